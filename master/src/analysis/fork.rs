//! One measurement: a fork from the operating point with a sinusoid on an input or a
//! connection, and the phasors of the recorded signals over whole periods.
//!
//! Fork j-indexing: row j of the fork is t_(k0+j) = T + j·h, the operating point being row 0.
//! The sinusoid d_j = A·sin(ω·j·h) is applied over [t_j, t_(j+1)): an input as an event at
//! every step (u_j = u0 + d_j), a connection as its offset (u_j = g·r_(j+lead) + c + d_j, where
//! r is the source as the connection reads it at step j: published at t_j, or under
//! Gauss-Seidel at t_(j+1) when the source steps before the destination, `lead` = 1).
//! After `settle` steps, the phasor of a sequence x over the N steps of P whole periods is
//! X = (2/N)·Σ x_j·e^(−iωjh) (the DC part cancels exactly over whole periods).

use super::{Base, DescribingPoint, Injection, LoopPoint, Options, OutputResponse, ResponsePoint};
use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::model_description::{ModelDescription, VarType};
use crate::run::Session;
use crate::system::{Algorithm, EventSpec, PlanEvent, System, TypedValue, Value, VarRef};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::TAU;
use std::sync::Arc;

/// The least number of steps in a correlation window (more periods where one is shorter).
const MIN_WINDOW: f64 = 200.0;
/// Harmonics 2..=HARMONICS make the distortion.
const HARMONICS: u32 = 5;

/// What a measurement injects and records, resolved against the system.
pub(crate) struct Plan {
    injection: Resolved,
    outputs: Vec<String>,
    periods: u32,
    settle: Option<f64>,
    h: f64,
}

enum Resolved {
    Input {
        name: String,
    },
    Connection {
        index: usize,
        source: String,
        gain: f64,
        offset: f64,
        lead: usize,
    },
}

/// The steps of one fork at a frequency.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Length {
    /// The snapped frequency [rad/s].
    pub omega: f64,
    pub settle: u64,
    /// The window: N steps of whole periods.
    pub window: u64,
}

impl Length {
    pub fn total(&self) -> u64 {
        self.settle + self.window
    }
}

/// `a.y -> b.u` in the plan's spelling.
fn normalized(connection: &str) -> Option<String> {
    let (a, b) = connection.split_once("->")?;
    Some(format!("{} -> {}", a.trim(), b.trim()))
}

impl Plan {
    pub fn new(
        system: &System,
        fmus: &[Arc<Fmu>],
        injection: &Injection,
        outputs: &[String],
        opts: &Options,
    ) -> Result<Plan> {
        let mds: Vec<&ModelDescription> = fmus.iter().map(|f| &f.model_description).collect();
        for name in outputs {
            variable(system, fmus, name)?;
        }
        let injection = match injection {
            Injection::Input(name) => {
                let (_, t) = variable(system, fmus, name)?;
                if t != Some(VarType::Real) {
                    return Err(Error::Other(format!(
                        "input '{name}': a sinusoid is injected into a Real variable"
                    )));
                }
                Resolved::Input { name: name.clone() }
            }
            Injection::Connection(c) => resolve_connection(system, &mds, c)?,
        };
        if !(opts.amplitude > 0.0 && opts.amplitude.is_finite()) {
            return Err(Error::Other(format!(
                "amplitude {}: it must be a positive number",
                opts.amplitude
            )));
        }
        if opts.periods == 0 {
            return Err(Error::Other("periods: at least 1".into()));
        }
        Ok(Plan {
            injection,
            outputs: outputs.to_vec(),
            periods: opts.periods,
            settle: opts.settle,
            h: system.step_size,
        })
    }

    /// The variables every fork records: the outputs, and the returned signal of a break.
    pub fn variables(&self) -> Vec<String> {
        let mut v = self.outputs.clone();
        if let Resolved::Connection { source, .. } = &self.injection {
            v.push(source.clone());
        }
        v
    }

    /// The fork at `omega`: P whole periods (more if one period is short) in N steps, ω
    /// snapped to 2πP/(Nh), after the settling time (default: 3 periods).
    pub fn length(&self, omega: f64) -> Length {
        let h = self.h;
        let per_period = TAU / (omega * h);
        let periods = f64::from(self.periods).max((MIN_WINDOW / per_period).ceil());
        let window = (periods * per_period).round().max(1.0);
        let omega = TAU * periods / (window * h);
        let settle = match self.settle {
            Some(s) => (s / h).ceil().max(0.0),
            None => (3.0 * TAU / (omega * h)).ceil(),
        };
        Length {
            omega,
            settle: settle as u64,
            window: window as u64,
        }
    }
}

/// The variable `name` of `system`: its instance index and type.
fn variable(system: &System, fmus: &[Arc<Fmu>], name: &str) -> Result<(usize, Option<VarType>)> {
    let r = VarRef::parse(name)
        .ok_or_else(|| Error::Other(format!("'{name}' is not instance.variable")))?;
    let i = system
        .instances
        .iter()
        .position(|x| x.name == r.instance)
        .ok_or_else(|| {
            Error::Other(format!(
                "'{name}': no instance '{}' in {}{}",
                r.instance,
                system.source.display(),
                crate::error::did_you_mean(
                    &r.instance,
                    system.instances.iter().map(|x| x.name.as_str())
                )
            ))
        })?;
    let v = fmus[i].variable(&r.variable).ok_or_else(|| {
        let md = &fmus[i].model_description;
        Error::Other(format!(
            "'{name}': instance '{}' has no variable '{}'{}",
            r.instance,
            r.variable,
            crate::error::did_you_mean(
                &r.variable,
                md.model_variables.variables.iter().map(|v| v.name.as_str())
            )
        ))
    })?;
    Ok((i, v.var_type()))
}

/// The connection to break: a Real, single-term connection of the plan.
fn resolve_connection(
    system: &System,
    mds: &[&ModelDescription],
    connection: &str,
) -> Result<Resolved> {
    let plan = system.validate(mds)?;
    let wanted = normalized(connection).ok_or_else(|| {
        Error::Other(format!(
            "--break \"{connection}\": give a connection as \"instance.output -> instance.input\""
        ))
    })?;
    let Some(index) = plan.connections.iter().position(|c| c.name == wanted) else {
        let names: Vec<&str> = plan.connections.iter().map(|c| c.name.as_str()).collect();
        return Err(Error::Other(format!(
            "--break \"{connection}\": no such connection in {}{}",
            system.source.display(),
            crate::error::did_you_mean(&wanted, names.iter().copied())
        )));
    };
    let c = &plan.connections[index];
    let summed = plan
        .connections
        .iter()
        .filter(|x| x.to_instance == c.to_instance && x.to_vr == c.to_vr)
        .count()
        > 1;
    if c.var_type != VarType::Real || summed {
        return Err(Error::Other(format!(
            "--break \"{wanted}\": the loop is broken at a Real connection that alone drives its input"
        )));
    }
    let order = |i: usize| plan.order.iter().position(|&x| x == i);
    let lead = usize::from(
        plan.algorithm == Algorithm::GaussSeidel && order(c.from_instance) < order(c.to_instance),
    );
    Ok(Resolved::Connection {
        index,
        source: wanted.split(" -> ").next().unwrap_or_default().to_string(),
        gain: c.gain,
        offset: c.offset,
        lead,
    })
}

/// The phasor of harmonic `n` of x_j over j in `from..from + len` at ω·h = `wh`.
fn phasor(x: &[f64], from: usize, len: usize, wh: f64, n: u32) -> Complex64 {
    let w = wh * f64::from(n);
    let sum: Complex64 = (from..from + len)
        .map(|j| x[j] * Complex64::from_polar(1.0, -w * j as f64))
        .sum();
    sum * (2.0 / len as f64)
}

/// The fundamental and the harmonic distortion of a sequence.
fn fundamental(x: &[f64], from: usize, len: usize, wh: f64) -> (Complex64, f64) {
    let f = phasor(x, from, len, wh, 1);
    let harmonics: f64 = (2..=HARMONICS)
        .map(|n| phasor(x, from, len, wh, n).norm_sqr())
        .sum();
    (f, harmonics.sqrt() / f.norm())
}

/// A fork's result: the injected phasor, what was sent (a break), and per recorded variable
/// the fundamental and distortion.
struct Fork {
    omega: f64,
    d: Complex64,
    sent: Option<Complex64>,
    returned: Option<(Complex64, f64)>,
    outputs: Vec<(Complex64, f64)>,
}

/// The plan and the prepared system: runs forks.
pub(crate) struct Work<'a> {
    plan: &'a Plan,
    base: &'a Base,
    /// An injected input's value at the operating point, and the event that sets it.
    input: Option<(f64, PlanEvent)>,
}

impl<'a> Work<'a> {
    /// The work of `plan` on `base`, whose sinusoids reach `max_amplitude`.
    pub fn new(plan: &'a Plan, base: &'a Base, max_amplitude: f64) -> Result<Work<'a>> {
        let input = match &plan.injection {
            Resolved::Input { name } => {
                let mut s = base.session()?;
                let u0 = match s.get(name)? {
                    TypedValue::Real(x) => x,
                    v => return Err(Error::Other(format!("'{name}' is {v:?}, not a Real"))),
                };
                // The same checks as a set: settable during a run, and u0 ± A in range.
                let template = input_event(&mut s, name, u0)?;
                input_event(&mut s, name, u0 + max_amplitude)?;
                input_event(&mut s, name, u0 - max_amplitude)?;
                s.close()?;
                Some((u0, template))
            }
            Resolved::Connection { .. } => None,
        };
        Ok(Work { plan, base, input })
    }

    pub fn length(&self, omega: f64) -> Length {
        self.plan.length(omega)
    }

    /// One fork at `omega` with amplitude `amplitude`.
    fn fork(&self, omega: f64, amplitude: f64) -> Result<Fork> {
        let len = self.plan.length(omega);
        let mut s = self.base.session()?;
        let k0 = s.step_index();
        let wh = len.omega * self.base.h;
        let total = len.total();
        let d: Vec<f64> = (0..=total)
            .map(|j| amplitude * (wh * j as f64).sin())
            .collect();
        match (&self.plan.injection, &self.input) {
            (Resolved::Input { .. }, Some((u0, template))) => {
                s.add_events((0..total).map(|j| PlanEvent {
                    step: k0 + j,
                    value: TypedValue::Real(u0 + d[j as usize]),
                    ..template.clone()
                }));
                s.step(total)?;
            }
            (Resolved::Connection { index, offset, .. }, _) => {
                for dj in &d[..total as usize] {
                    s.set_connection_offset(*index, offset + dj)?;
                    s.step(1)?;
                }
            }
            _ => unreachable!("an input's value is read in Work::new"),
        }
        if s.step_index() < k0 + total {
            return Err(Error::Other(format!(
                "the fork at {} rad/s ended at t = {} s, before its window's end at t = {} s: {:?}",
                len.omega,
                s.time(),
                self.base.time + total as f64 * self.base.h,
                s.state()
            )));
        }
        let (from, n) = (len.settle as usize, len.window as usize);
        let rows = s.rows();
        let column = |name: &str| {
            rows.column(name)
                .ok_or_else(|| Error::Other(format!("'{name}' was not recorded")))
        };
        let outputs = self
            .plan
            .outputs
            .iter()
            .map(|o| Ok(fundamental(column(o)?, from, n, wh)))
            .collect::<Result<Vec<_>>>()?;
        let (sent, returned) = match &self.plan.injection {
            Resolved::Connection {
                source,
                gain,
                offset,
                lead,
                ..
            } => {
                let r = column(source)?;
                let r: Vec<f64> = (0..total as usize).map(|j| r[j + lead]).collect();
                let u: Vec<f64> = r
                    .iter()
                    .zip(&d)
                    .map(|(r, d)| gain * r + offset + d)
                    .collect();
                (
                    Some(phasor(&u, from, n, wh, 1)),
                    Some(fundamental(&r, from, n, wh)),
                )
            }
            Resolved::Input { .. } => (None, None),
        };
        let d = phasor(&d, from, n, wh, 1);
        s.close()?;
        Ok(Fork {
            omega: len.omega,
            d,
            sent,
            returned,
            outputs,
        })
    }

    /// The responses at the outputs for each frequency (and at twice the amplitude).
    pub fn responses(
        &self,
        freqs: &[f64],
        amplitude: f64,
        linearity: bool,
    ) -> Result<Vec<ResponsePoint>> {
        let forks = self.forks(freqs, amplitude, linearity)?;
        Ok(forks
            .into_iter()
            .map(|(a, b)| ResponsePoint {
                omega: a.omega,
                outputs: self.output_responses(&a, b.as_ref()),
            })
            .collect())
    }

    /// Forks at `freqs` (each also at twice the amplitude with `linearity`), in parallel.
    fn forks(
        &self,
        freqs: &[f64],
        amplitude: f64,
        linearity: bool,
    ) -> Result<Vec<(Fork, Option<Fork>)>> {
        let mut jobs: Vec<(usize, f64)> = freqs.iter().map(|w| (0, *w)).collect();
        if linearity {
            jobs.extend(freqs.iter().map(|w| (1, *w)));
        }
        let done: Vec<Fork> = jobs
            .par_iter()
            .map(|(twice, w)| self.fork(*w, amplitude * (1 + twice) as f64))
            .collect::<Result<_>>()?;
        let mut done = done.into_iter();
        let first: Vec<Fork> = done.by_ref().take(freqs.len()).collect();
        let second: Vec<Option<Fork>> = match linearity {
            true => done.map(Some).collect(),
            false => (0..freqs.len()).map(|_| None).collect(),
        };
        Ok(first.into_iter().zip(second).collect())
    }

    fn output_responses(&self, a: &Fork, b: Option<&Fork>) -> Vec<OutputResponse> {
        self.plan
            .outputs
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let ratio = a.outputs[i].0 / a.d;
                let change = b.map(|b| (b.outputs[i].0 / b.d) / ratio);
                OutputResponse {
                    name: name.clone(),
                    ratio,
                    distortion: a.outputs[i].1,
                    gain_change_db: change.map(|c| 20.0 * c.norm().log10()),
                    phase_change_deg: change.map(|c| c.arg().to_degrees()),
                }
            })
            .collect()
    }

    /// The loop L = −R/U at each frequency (and at twice the amplitude).
    pub fn loop_points(
        &self,
        freqs: &[f64],
        amplitude: f64,
        linearity: bool,
    ) -> Result<Vec<LoopPoint>> {
        let l = |f: &Fork| -> Complex64 {
            let (r, _) = f.returned.expect("a break");
            -r / f.sent.expect("a break")
        };
        Ok(self
            .forks(freqs, amplitude, linearity)?
            .into_iter()
            .map(|(a, b)| {
                let change = b.as_ref().map(|b| l(b) / l(&a));
                LoopPoint {
                    omega: a.omega,
                    l: l(&a),
                    distortion: a.returned.map_or(0.0, |r| r.1),
                    gain_change_db: change.map(|c| 20.0 * c.norm().log10()),
                    phase_change_deg: change.map(|c| c.arg().to_degrees()),
                }
            })
            .collect())
    }

    /// The describing function at `omega` over `amplitudes`.
    pub fn describing(&self, omega: f64, amplitudes: &[f64]) -> Result<Vec<DescribingPoint>> {
        amplitudes
            .par_iter()
            .map(|a| {
                let f = self.fork(omega, *a)?;
                Ok(DescribingPoint {
                    amplitude: *a,
                    omega: f.omega,
                    outputs: self.output_responses(&f, None),
                })
            })
            .collect()
    }
}

/// The event that sets input `name` to `value` now, checked as a set is (settable during a
/// run, within the declared range): the template of the injected events.
fn input_event(s: &mut Session, name: &str, value: f64) -> Result<PlanEvent> {
    let spec = EventSpec {
        time: s.time(),
        target: VarRef::parse(name).expect("checked"),
        value: Value::Real(value),
        line: None,
    };
    let mds: Vec<&ModelDescription> = s.fmus().iter().map(|f| &f.model_description).collect();
    let plan = s.plan();
    s.system()
        .resolve_event(&mds, &spec, plan.n_steps, plan.stop_time)
}
