//! Hull (ship) models of the sources.
//!
//! Each ship is a plain `Clone + Debug + Serialize + Deserialize` struct holding its parameters
//! and state, built by a validating constructor (`Result<_, ParamError>`) or a named preset, and
//! advanced by `step(&mut self, inputs, h)`, which advances exactly `h` seconds with a fixed
//! internal step (RK4, see [`crate::integrate`]) or an exact ZOH discretisation for the linear
//! models. Interfaces are SI with angles in rad; prime-system (nondimensional) quantities are
//! extra outputs. Earth frame: x north, y east, heading ψ from north positive clockwise
//! (to starboard). The heading state is continuous (not wrapped); `heading_wrapped` gives
//! (−π, π].
//!
//! | type | source |
//! | --- | --- |
//! | [`container_ship::ContainerShip`], [`container_ship::LinearContainerShip`] | Son & Nomoto (1982) as implemented in the MSS toolbox (`container.m`, `Lcontainer.m`) |
//! | [`mariner::Mariner`] | Chislett & Strøm-Tejsen (1965) as implemented in the MSS toolbox (`mariner.m`) |
//! | [`nomoto::NomotoShip`] | [Taylor2000, sec. 4.1 and 5.2.1], Esso Osaka data [Taylor2000, Tables 2.2-2.3] |
//! | [`supply_vessel::SupplyVessel`] | [Fossen1999, sec. 2.1-2.5 and 6] |
//! | [`tokyo_maru::TokyoMaru`] | [Parsons1980, sec. 2.1-2.3, Tables 1-2] |
//! | [`rrs_ship::RrsShip`] | [Klugt1987, sec. 2.2.2, 2.4 and 2.5, Tables 2.1-2.5] |

pub mod container_ship;
pub mod mariner;
pub mod nomoto;
pub mod rrs_ship;
pub mod supply_vessel;
pub mod tokyo_maru;

/// One degree in radians.
pub const DEG: f64 = std::f64::consts::PI / 180.0;
/// One knot in m/s (1852 m / 3600 s).
pub const KNOT: f64 = 1852.0 / 3600.0;

/// Wraps an angle to (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    let mut w = a % two_pi;
    if w > std::f64::consts::PI {
        w -= two_pi;
    } else if w <= -std::f64::consts::PI {
        w += two_pi;
    }
    w
}

/// Checks the named values of an initial state: each is finite, and each name listed in
/// `angles_within_half_pi` (a roll angle) lies in (−π/2, π/2), where a hull's small-angle or
/// restoring model still means something (capsized is outside every model here).
pub fn check_initial_state(
    values: &[(&str, f64)],
    angles_within_half_pi: &[&str],
) -> Result<(), crate::error::ParamError> {
    for &(name, v) in values {
        crate::error::check_finite(name, v)?;
        if angles_within_half_pi.contains(&name) {
            crate::error::require(
                v.abs() < std::f64::consts::FRAC_PI_2,
                name,
                v,
                "must lie in (-pi/2, pi/2)",
            )?;
        }
    }
    Ok(())
}

/// The value of a parameter that the named preset `preset` sets to `ours`: `ours`, when the
/// parameter is still at its `default` or already equals `ours`; a parameter set to anything
/// else conflicts with the preset and is refused (whatever the order of the sets), as the
/// heading autopilot's `preset` does.
pub fn preset_value(
    preset: i32,
    name: &str,
    value: f64,
    default: f64,
    ours: f64,
) -> Result<f64, String> {
    if value == default || value == ours {
        Ok(ours)
    } else {
        Err(format!(
            "preset = {preset} sets {name} = {ours}, but {name} was set to {value}: set preset = 0 \
             to give the parameters one by one"
        ))
    }
}

/// First-order rudder servo of the MSS ships (MSS `container.m`, also used by `mariner.m` and
/// `Lcontainer.m`): the command is saturated to ±`max`, the rate
/// is `(δ_c,sat − δ)/1 s` clipped to ±`rate_max`. There is no separate limit on the state.
#[inline]
pub(crate) fn mss_rudder_rate(command: f64, delta: f64, max: f64, rate_max: f64) -> f64 {
    let dc = command.clamp(-max, max);
    (dc - delta).clamp(-rate_max, rate_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn initial_state_checks() {
        assert!(check_initial_state(&[("x", 1e6), ("roll", 1.5)], &["roll"]).is_ok());
        let e = check_initial_state(&[("x", f64::NAN)], &[]).unwrap_err();
        assert!(e.to_string().contains("x = NaN"), "{e}");
        let e = check_initial_state(&[("roll", 1.6)], &["roll"]).unwrap_err();
        assert!(e.to_string().contains("roll = 1.6"), "{e}");
        assert!(check_initial_state(&[("heading", 100.0)], &["roll"]).is_ok());
    }

    #[test]
    fn preset_values_and_conflicts() {
        assert_eq!(preset_value(2, "a", 1.0, 1.0, 3.0), Ok(3.0));
        assert_eq!(preset_value(2, "a", 3.0, 1.0, 3.0), Ok(3.0));
        let e = preset_value(2, "a", 2.0, 1.0, 3.0).unwrap_err();
        assert!(
            e.contains("preset = 2 sets a = 3, but a was set to 2"),
            "{e}"
        );
        assert!(preset_value(2, "a", f64::NAN, 1.0, 3.0).is_err());
    }

    #[test]
    fn wrap() {
        assert!((wrap_pi(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap_pi(-0.5) + 0.5).abs() < 1e-15);
        assert!((wrap_pi(7.0) - (7.0 - 2.0 * std::f64::consts::PI)).abs() < 1e-12);
    }
}

/// Snapshot semantics the FMU layer relies on: a clone, and a bincode round trip, continue
/// exactly like the original (bit-identical states after further steps).
#[cfg(test)]
mod snapshot_tests {
    use super::*;

    fn roundtrip<T: serde::Serialize + serde::de::DeserializeOwned>(x: &T) -> T {
        bincode::deserialize(&bincode::serialize(x).unwrap()).unwrap()
    }

    #[test]
    fn clone_and_serialize_continue_identically() {
        use container_ship::*;
        let inp = ContainerShipInputs {
            rudder_command: 0.1,
            shaft_command_rpm: 80.0,
            ..Default::default()
        };
        let mut a = ContainerShip::at_equilibrium(70.0).unwrap();
        a.step(&inp, 10.0);
        let mut b = a.clone();
        let mut c = roundtrip(&a);
        for s in [&mut a, &mut b, &mut c] {
            s.step(&inp, 10.0);
        }
        assert_eq!(a, b);
        assert_eq!(a, c);

        let inp = mariner::MarinerInputs {
            rudder_command: 0.2,
        };
        let mut a = mariner::Mariner::mss_default();
        a.step(&inp, 5.0);
        let mut c = roundtrip(&a);
        a.step(&inp, 5.0);
        c.step(&inp, 5.0);
        assert_eq!(a, c);

        let inp = rrs_ship::RrsShipInputs {
            rudder: 0.1,
            speed: 11.0,
            wave_elevation: 0.5,
            ..Default::default()
        };
        let mut a = rrs_ship::RrsShip::simulation_22kn();
        a.step(&inp, 5.0);
        let mut c = roundtrip(&a);
        a.step(&inp, 5.0);
        c.step(&inp, 5.0);
        assert_eq!(a, c);

        let inp = tokyo_maru::TokyoMaruInputs {
            rudder: 0.1,
            ..Default::default()
        };
        let mut a = tokyo_maru::TokyoMaru::design_depth();
        a.step(&inp, 5.0);
        let mut c = roundtrip(&a);
        a.step(&inp, 5.0);
        c.step(&inp, 5.0);
        assert_eq!(a.state(), c.state());
        assert_eq!(a.outputs(), c.outputs());

        let inp = nomoto::NomotoInputs {
            rudder: 0.1,
            ..Default::default()
        };
        let mut a = nomoto::NomotoShip::esso_osaka();
        a.step(&inp, 5.0);
        let mut c = roundtrip(&a);
        a.step(&inp, 5.0);
        c.step(&inp, 5.0);
        assert_eq!(a, c);

        let inp = supply_vessel::SupplyVesselInputs {
            tau: [1e4, 1e4, 1e5],
            ..Default::default()
        };
        let mut a = supply_vessel::SupplyVessel::northern_clipper();
        a.step(&inp, 5.0);
        let mut c = roundtrip(&a);
        a.step(&inp, 5.0);
        c.step(&inp, 5.0);
        assert_eq!(a, c);
    }
}
