//! Runs of variables that several FMUs declare alike, written once. Use one in place of an
//! entry of a variable table: `pose!(out());` splices its entries in at that position, so the
//! value references of the entries before and after it are those of the full table (a fragment
//! never renumbers anything). The argument is the access path, from the model, of a value that
//! has the fragment's fields.

/// Heading (continuous and wrapped) and the north/east position of a hull, in that order, from
/// a value with fields `heading`, `heading_wrapped`, `x` and `y` (e.g. `pose!(out());` reads
/// `m.out().heading`, ...).
#[macro_export]
macro_rules! pose {
    (@fragment [$model:ty] [$($done:tt)*] ($($path:tt)*) $($rest:tt)*) => {
        $crate::__variables!(@[$model] [$($done)*]
            heading!($($path)*);
            output real "x" ["m"] (|m| m.$($path)*.x), "North position";
            output real "y" ["m"] (|m| m.$($path)*.y), "East position";
            $($rest)*
        )
    };
}

/// Heading psi, continuous and wrapped, from a value with fields `heading` and
/// `heading_wrapped`.
#[macro_export]
macro_rules! heading {
    (@fragment [$model:ty] [$($done:tt)*] ($($path:tt)*) $($rest:tt)*) => {
        $crate::__variables!(@[$model] [$($done)*]
            output real "heading" ["rad"] (|m| m.$($path)*.heading),
                "Heading psi from north, clockwise, continuous (not wrapped)";
            output real "heading_wrapped" ["rad"] (|m| m.$($path)*.heading_wrapped),
                "Heading wrapped to (-pi, pi]";
            $($rest)*
        )
    };
}

/// The design frame shared by the loop-shaped DDG-51 controllers of [Taylor2000, ch. 5] (HeadingAutopilot,
/// TrackController): Nomoto plant K' and T', steering-gear pole, Tustin sample step, rudder
/// command limit and the ship length and speed of the time base t' = tU/L, in that order, from
/// a value with the fields of `models::controllers::loop_shaped::LoopShapingCommon` (e.g.
/// `loop_shaping_common!(design.common);` reads and writes `m.design.common.nomoto_k`, ...).
#[macro_export]
macro_rules! loop_shaping_common {
    (@fragment [$model:ty] [$($done:tt)*] ($($path:tt)*) $($rest:tt)*) => {
        $crate::__variables!(@[$model] [$($done)*]
            tunable real "nomoto_k" ($($path)*.nomoto_k).min(0.0),
                "Nomoto K' of the design plant in t' = tU/L (eq. 5.26: 2.04)";
            tunable real "nomoto_t" ($($path)*.nomoto_t).min(0.0),
                "Nomoto T' in ship lengths (eq. 5.25: 1.9287)";
            tunable real "gear_pole" ($($path)*.gear_pole).min(0.0),
                "Steering-gear pole a of a/(s+a) in t' (eq. 5.28: 6)";
            tunable real "sample_step" ($($path)*.sample_step).min(0.0),
                "Largest internal Tustin step in ship lengths (t'); each communication step is split into equal samples not longer than this";
            tunable real "command_limit" ["rad"] ($($path)*.limit).min(0.0),
                "Rudder command limit (L2192-2199: 30 deg)";
            fixed real "ship_length" ["m"] ($($path)*.length).min(0.0),
                "Ship length L of the time base (DDG-51: 466 ft)";
            fixed real "ship_speed" ["m/s"] ($($path)*.speed).min(0.0),
                "Ship speed U of the time base (22 kn)";
            $($rest)*
        )
    };
}

/// The prime-system time base and the four measured path-model states of the estimators of
/// [Parsons1980, sec. 4-5] (PathEstimator, PathWlsEstimator): `ship_length`, `ship_speed` (parameters)
/// and the inputs `heading`, `yaw_rate`, `drift_angle`, `cross_track` from the fields
/// `ship_length`, `ship_speed` and `measured[0..4]` of the model.
#[macro_export]
macro_rules! path_measurements {
    (@fragment [$model:ty] [$($done:tt)*] () $($rest:tt)*) => {
        $crate::__variables!(@[$model] [$($done)*]
            fixed real "ship_length" ["m"] (ship_length).min(0.0),
                "Ship length L of the prime system (290 m)";
            fixed real "ship_speed" ["m/s"] (ship_speed).min(0.0),
                "Ship speed U of the prime system (12 kn)";
            input real "heading" ["rad"] (measured[0]),
                "Measured heading psi relative to the track direction";
            input real "yaw_rate" ["rad/s"] (measured[1]), "Measured yaw rate r";
            input real "drift_angle" ["rad"] (measured[2]),
                "Measured drift angle beta (Doppler sonar, v = -U beta)";
            input real "cross_track" ["m"] (measured[3]), "Measured lateral offset eta";
            $($rest)*
        )
    };
}
