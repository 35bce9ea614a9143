//! The `[[io]]` channels of a paced or I/O run, opened against a session: outputs
//! ([`outputs`]: NMEA 0183 over UDP or TCP, plain UDP) read variables at communication points
//! and send datagrams; inputs ([`inputs`]: NMEA 0183 commands, plain UDP) receive on their own
//! threads into bounded queues, and their values are applied at macro-step boundaries.

pub mod inputs;
pub mod outputs;

use crate::error::{Error, Result};
use crate::run::Session;
use crate::units::{self, RadRule, Unit};
use std::net::{SocketAddr, ToSocketAddrs};

/// An address `host:port` of a channel.
pub fn address(text: Option<&str>, what: &str, channel: usize) -> Result<SocketAddr> {
    let t = text.ok_or_else(|| Error::Other(format!("[[io]] #{channel}: {what} is required")))?;
    t.to_socket_addrs()
        .ok()
        .and_then(|mut a| a.next())
        .ok_or_else(|| {
            Error::Other(format!(
                "[[io]] #{channel}: {what} = \"{t}\" is not host:port"
            ))
        })
}

/// A linear map `gain*x + offset` between a variable's unit and a wire unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linear {
    pub gain: f64,
    pub offset: f64,
}

impl Linear {
    pub fn apply(&self, x: f64) -> f64 {
        self.gain * x + self.offset
    }
}

/// The variable's declared unit (its FMU's definition or the built-in one), or None when it
/// declares none.
fn variable_unit(session: &Session, name: &str) -> Result<Option<Unit>> {
    let (i, sv) = session.variable(name)?;
    let md = &session.fmus()[i].model_description;
    let Some(u) = md.real_unit(sv) else {
        return Ok(None);
    };
    units::declared(md, u)
        .map(|(u, _)| Some(u))
        .map_err(|e| Error::Other(format!("'{name}': {}", e.0)))
}

/// The map from `variable`'s unit to `wire` (or back with `to_wire` false). A variable that
/// declares no unit is taken to be in SI units (rad for an angle). "" is a code or flag: as is.
pub fn conversion(session: &Session, variable: &str, wire: &str, to_wire: bool) -> Result<Linear> {
    if wire.is_empty() {
        return Ok(Linear {
            gain: 1.0,
            offset: 0.0,
        });
    }
    let w = Unit::parse(wire).map_err(|e| Error::Other(e.0))?;
    let v = variable_unit(session, variable)?.unwrap_or(Unit {
        factor: 1.0,
        offset: 0.0,
        ..w
    });
    let rule = RadRule::Omittable {
        from: to_wire,
        to: !to_wire,
    };
    let c = match to_wire {
        true => v.conversion_to(&w, rule),
        false => w.conversion_to(&v, rule),
    };
    let c = c.ok_or_else(|| {
        Error::Other(format!(
            "'{variable}': its unit ({}) does not convert to {wire}",
            v.dimension()
        ))
    })?;
    let (gain, offset) = c.gain_offset();
    Ok(Linear { gain, offset })
}

/// The current value of a variable as a number.
pub fn value(session: &mut Session, name: &str) -> Result<f64> {
    use crate::system::TypedValue;
    Ok(match session.get(name)? {
        TypedValue::Real(x) => x,
        TypedValue::Integer(i) => f64::from(i),
        TypedValue::Boolean(b) => f64::from(u8::from(b)),
        TypedValue::String(_) => f64::NAN,
    })
}
