//! The manoeuvrability criteria of IMO Resolution MSC.137(76), *Standards for Ship
//! Manoeuvrability* (2002), Annex, sec. 5.3, applied to the metrics of this module.
//!
//! The Standards (sec. 5.3) consider the manoeuvrability satisfactory when:
//! 1. **Turning ability** (5.3.1): the advance does not exceed 4.5 L and the tactical diameter
//!    does not exceed 5 L in the turning circle manoeuvre (35° rudder or the largest permitted
//!    at the test speed, to both sides; Annex 4.2.2).
//! 2. **Initial turning ability** (5.3.2): with 10° rudder, the ship has not travelled more than
//!    2.5 L by the time the heading has changed by 10° from the original heading.
//! 3. **Yaw checking and course keeping** (5.3.3), with L/V in s (L in m, V the test speed in
//!    m/s, Annex 4.2.1):
//!    * first overshoot of the 10°/10° zig-zag at most 10° if L/V < 10 s, 20° if L/V ≥ 30 s,
//!      (5 + L/(2V))° in between;
//!    * second overshoot of the 10°/10° zig-zag at most 25° if L/V < 10 s, 40° if L/V ≥ 30 s,
//!      (17.5 + 0.75 L/V)° in between;
//!    * first overshoot of the 20°/20° zig-zag at most 25°.
//!
//! (Text read at imorules.com, MSC.137(76) Annex 4.2 and 5.3; the form of MSC/Circ.1053,
//! Appendix 6, reports the initial turning as "distance to turn 10 deg with 10 deg rudder".
//! Both overshoot limits are continuous at L/V = 10 s and 30 s.) "Should not exceed" is read as
//! ≤: a metric equal to its limit passes; a NaN metric fails.
//!
//! Units as in the metrics: lengths in m, angles in rad (the limits are converted from the
//! degrees of the Standards). The criteria apply to the test each is defined on; which manoeuvre
//! produced the metrics (35° turn, 10°/10° or 20°/20° zig-zag) is the caller's to ensure, as is
//! running it to both sides (each side is one check).

use serde::{Deserialize, Serialize};

use super::{TurningCircleMetrics, ZigZagMetrics};
use crate::hull::DEG;

/// Largest advance, in ship lengths (5.3.1).
pub const ADVANCE_LIMIT_LENGTHS: f64 = 4.5;
/// Largest tactical diameter, in ship lengths (5.3.1).
pub const TACTICAL_DIAMETER_LIMIT_LENGTHS: f64 = 5.0;
/// Largest track to a 10° heading change with 10° rudder, in ship lengths (5.3.2).
pub const INITIAL_TURNING_LIMIT_LENGTHS: f64 = 2.5;
/// Largest first overshoot of the 20°/20° zig-zag [deg] (5.3.3.3).
pub const FIRST_OVERSHOOT_LIMIT_20_20_DEG: f64 = 25.0;

/// An input of a check that is not a finite positive number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CriteriaError {
    /// Which input ("ship length", "test speed").
    pub name: &'static str,
    pub value: f64,
}

impl std::fmt::Display for CriteriaError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "IMO MSC.137(76) criteria: {} = {} (must be finite and > 0)",
            self.name, self.value
        )
    }
}

impl std::error::Error for CriteriaError {}

fn positive(name: &'static str, value: f64) -> Result<f64, CriteriaError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(CriteriaError { name, value })
    }
}

/// Turning ability (5.3.1) of one turning circle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TurningCheck {
    /// 4.5 L [m].
    pub advance_limit: f64,
    /// 5 L [m].
    pub tactical_diameter_limit: f64,
    pub advance_pass: bool,
    pub tactical_diameter_pass: bool,
    /// Both met.
    pub pass: bool,
}

/// Turning ability (5.3.1): advance ≤ 4.5 L and tactical diameter ≤ 5 L, for ship length
/// `length` [m]. `m` should come from the 35° (or largest permitted rudder) turning circle.
pub fn check_turning(m: &TurningCircleMetrics, length: f64) -> Result<TurningCheck, CriteriaError> {
    let l = positive("ship length", length)?;
    let advance_limit = ADVANCE_LIMIT_LENGTHS * l;
    let tactical_diameter_limit = TACTICAL_DIAMETER_LIMIT_LENGTHS * l;
    let advance_pass = m.advance <= advance_limit;
    let tactical_diameter_pass = m.tactical_diameter <= tactical_diameter_limit;
    Ok(TurningCheck {
        advance_limit,
        tactical_diameter_limit,
        advance_pass,
        tactical_diameter_pass,
        pass: advance_pass && tactical_diameter_pass,
    })
}

/// Initial turning ability (5.3.2).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct InitialTurningCheck {
    /// 2.5 L [m].
    pub track_limit: f64,
    pub pass: bool,
}

/// Initial turning ability (5.3.2): the track `track` [m] run with 10° rudder until the heading
/// has changed by 10° is at most 2.5 L. The track is
/// [`ZigZagMetrics::track_to_second_execute`] of a 10°/10° zig-zag, or
/// [`TurningCircleMetrics::track_to_10deg`] of a turning circle with 10° rudder (not of the 35°
/// one).
pub fn check_initial_turning(
    track: f64,
    length: f64,
) -> Result<InitialTurningCheck, CriteriaError> {
    let track_limit = INITIAL_TURNING_LIMIT_LENGTHS * positive("ship length", length)?;
    Ok(InitialTurningCheck {
        track_limit,
        pass: track <= track_limit,
    })
}

/// IMO 10°/10° first-overshoot limit [rad] for L/V [s] (5.3.3.1): 10° below 10 s, 20° from
/// 30 s, (5 + L/(2V))° in between.
pub fn first_overshoot_limit_10_10(l_over_u: f64) -> f64 {
    by_l_over_u(l_over_u, 10.0, 20.0, (5.0, 0.5))
}

/// IMO 10°/10° second-overshoot limit [rad] for L/V [s] (5.3.3.2): 25° below 10 s, 40° from
/// 30 s, (17.5 + 0.75 L/V)° in between.
pub fn second_overshoot_limit_10_10(l_over_u: f64) -> f64 {
    by_l_over_u(l_over_u, 25.0, 40.0, (17.5, 0.75))
}

/// The shape of both 10°/10° limits [rad]: `below_10` degrees for L/V < 10 s, `from_30`
/// degrees for L/V ≥ 30 s, (a + b·L/V) degrees in between.
fn by_l_over_u(l_over_u: f64, below_10: f64, from_30: f64, (a, b): (f64, f64)) -> f64 {
    let deg = if l_over_u < 10.0 {
        below_10
    } else if l_over_u >= 30.0 {
        from_30
    } else {
        a + b * l_over_u
    };
    deg * DEG
}

/// Yaw checking (5.3.3.1-2) of one 10°/10° zig-zag.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ZigZag1010Check {
    /// L/V [s].
    pub l_over_u: f64,
    /// First and second overshoot limits [rad].
    pub first_overshoot_limit: f64,
    pub second_overshoot_limit: f64,
    pub first_overshoot_pass: bool,
    pub second_overshoot_pass: bool,
    /// Both met.
    pub pass: bool,
}

/// Yaw checking (5.3.3.1-2) of a 10°/10° zig-zag for ship length `length` [m] and test speed
/// `speed` [m/s] (the approach speed).
pub fn check_zigzag_10_10(
    m: &ZigZagMetrics,
    length: f64,
    speed: f64,
) -> Result<ZigZag1010Check, CriteriaError> {
    let l_over_u = positive("ship length", length)? / positive("test speed", speed)?;
    let first_overshoot_limit = first_overshoot_limit_10_10(l_over_u);
    let second_overshoot_limit = second_overshoot_limit_10_10(l_over_u);
    let first_overshoot_pass = m.first_overshoot <= first_overshoot_limit;
    let second_overshoot_pass = m.second_overshoot <= second_overshoot_limit;
    Ok(ZigZag1010Check {
        l_over_u,
        first_overshoot_limit,
        second_overshoot_limit,
        first_overshoot_pass,
        second_overshoot_pass,
        pass: first_overshoot_pass && second_overshoot_pass,
    })
}

/// Yaw checking (5.3.3.3) of one 20°/20° zig-zag.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ZigZag2020Check {
    /// 25° [rad].
    pub first_overshoot_limit: f64,
    pub pass: bool,
}

/// Yaw checking (5.3.3.3) of a 20°/20° zig-zag: first overshoot at most 25°.
pub fn check_zigzag_20_20(m: &ZigZagMetrics) -> ZigZag2020Check {
    let first_overshoot_limit = FIRST_OVERSHOOT_LIMIT_20_20_DEG * DEG;
    ZigZag2020Check {
        first_overshoot_limit,
        pass: m.first_overshoot <= first_overshoot_limit,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Degrees written out in rad (π/180 multiples computed by hand, 17 digits).
    const DEG_10: f64 = 0.174_532_925_199_432_95;
    const DEG_15: f64 = 0.261_799_387_799_149_4;
    const DEG_20: f64 = 0.349_065_850_398_865_9;
    const DEG_25: f64 = 0.436_332_312_998_582_4;
    const DEG_32_5: f64 = 0.567_232_006_898_157_1;
    const DEG_40: f64 = 0.698_131_700_797_731_8;
    /// Agreement of the limits with the hand values [rad]: round-off of deg·(π/180).
    const TOL: f64 = 1e-15;

    fn zigzag(first: f64, second: f64) -> ZigZagMetrics {
        ZigZagMetrics {
            first_overshoot: first,
            second_overshoot: second,
            ..Default::default()
        }
    }

    /// 10°/10° limits at L/V = 5 s (below 10 s: 10° and 25°), 20 s (5 + 20/2 = 15°,
    /// 17.5 + 0.75·20 = 32.5°) and 40 s (30 s or more: 20° and 40°), for L = 100 m and
    /// V = 20, 5 and 2.5 m/s.
    #[test]
    fn zigzag_10_10_limits_by_hand() {
        for (speed, l_over_u, first, second) in [
            (20.0, 5.0, DEG_10, DEG_25),
            (5.0, 20.0, DEG_15, DEG_32_5),
            (2.5, 40.0, DEG_20, DEG_40),
        ] {
            let c = check_zigzag_10_10(&zigzag(0.0, 0.0), 100.0, speed).unwrap();
            assert_eq!(c.l_over_u, l_over_u);
            assert!((c.first_overshoot_limit - first).abs() < TOL, "{c:?}");
            assert!((c.second_overshoot_limit - second).abs() < TOL, "{c:?}");
            assert!(c.pass);
            assert!((first_overshoot_limit_10_10(l_over_u) - first).abs() < TOL);
            assert!((second_overshoot_limit_10_10(l_over_u) - second).abs() < TOL);
            assert!((super::super::imo_10_10_first_overshoot_limit(l_over_u) - first).abs() < TOL);
            // 0.1° over a limit fails that limit only; at the limit passes ("not exceed").
            let over = 0.1 * DEG_10 / 10.0;
            let c1 = check_zigzag_10_10(&zigzag(first + over, 0.0), 100.0, speed).unwrap();
            assert!(!c1.first_overshoot_pass && c1.second_overshoot_pass && !c1.pass);
            let c2 = check_zigzag_10_10(&zigzag(0.0, second + over), 100.0, speed).unwrap();
            assert!(c2.first_overshoot_pass && !c2.second_overshoot_pass && !c2.pass);
            let at = zigzag(c.first_overshoot_limit, c.second_overshoot_limit);
            assert!(check_zigzag_10_10(&at, 100.0, speed).unwrap().pass);
        }
        // The formulas meet the constant parts at 10 s (10°, 25°) and 30 s (20°, 40°).
        assert!((first_overshoot_limit_10_10(10.0) - DEG_10).abs() < TOL);
        assert!((second_overshoot_limit_10_10(10.0) - DEG_25).abs() < TOL);
        assert!((first_overshoot_limit_10_10(29.999_999_9) - DEG_20).abs() < 1e-8);
        assert!((second_overshoot_limit_10_10(29.999_999_9) - DEG_40).abs() < 1e-8);
    }

    /// 20°/20°: 25°; turning: 4.5 L = 450 m and 5 L = 500 m for L = 100 m; initial turning:
    /// 2.5 L = 250 m.
    #[test]
    fn turning_and_20_20_limits_by_hand() {
        let c = check_zigzag_20_20(&zigzag(DEG_25 - 1e-6, 99.0));
        assert!((c.first_overshoot_limit - DEG_25).abs() < TOL && c.pass);
        assert!(!check_zigzag_20_20(&zigzag(DEG_25 + 1e-6, 0.0)).pass);

        let turn = |advance, tactical_diameter| TurningCircleMetrics {
            advance,
            tactical_diameter,
            ..Default::default()
        };
        let c = check_turning(&turn(449.9, 499.9), 100.0).unwrap();
        assert_eq!((c.advance_limit, c.tactical_diameter_limit), (450.0, 500.0));
        assert!(c.advance_pass && c.tactical_diameter_pass && c.pass);
        assert!(check_turning(&turn(450.0, 500.0), 100.0).unwrap().pass);
        let c = check_turning(&turn(450.1, 499.9), 100.0).unwrap();
        assert!(!c.advance_pass && c.tactical_diameter_pass && !c.pass);
        let c = check_turning(&turn(449.9, 500.1), 100.0).unwrap();
        assert!(c.advance_pass && !c.tactical_diameter_pass && !c.pass);

        let c = check_initial_turning(250.0, 100.0).unwrap();
        assert_eq!(c.track_limit, 250.0);
        assert!(c.pass);
        assert!(!check_initial_turning(250.1, 100.0).unwrap().pass);
    }

    /// A NaN metric (e.g. the track of a run that never turned 10°) fails; a bad length or
    /// speed is an error naming it.
    #[test]
    fn nan_metrics_fail_and_bad_inputs_are_named() {
        assert!(!check_initial_turning(f64::NAN, 100.0).unwrap().pass);
        assert!(!check_zigzag_20_20(&zigzag(f64::NAN, 0.0)).pass);
        assert!(
            !check_zigzag_10_10(&zigzag(0.0, f64::NAN), 100.0, 5.0)
                .unwrap()
                .pass
        );
        let nan_turn = TurningCircleMetrics {
            advance: f64::NAN,
            ..Default::default()
        };
        assert!(!check_turning(&nan_turn, 100.0).unwrap().pass);

        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = check_turning(&TurningCircleMetrics::default(), bad).unwrap_err();
            assert_eq!(e.name, "ship length");
            assert_eq!(e.value.to_bits(), bad.to_bits());
            assert!(e.to_string().contains("ship length = "), "{e}");
            assert_eq!(
                check_initial_turning(1.0, bad).unwrap_err().name,
                "ship length"
            );
            let e = check_zigzag_10_10(&zigzag(0.0, 0.0), 100.0, bad).unwrap_err();
            assert_eq!(e.name, "test speed");
        }
    }
}
