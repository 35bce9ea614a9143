//! The declarative FMU definition: [`fmu!`](crate::fmu) (header, variable table, C API) and the
//! variable-table language of [`variables!`](macro@crate::variables).
//!
//! A variable is one entry, usually two lines:
//!
//! ```text
//! KIND TYPE[(MIN, MAX)] "name" ["unit"] (ACCESS) .modifier(..)*,
//!     "description";
//! ```
//!
//! * `KIND` gives causality and variability: `fixed` / `tunable` (parameters), `input`, `output`,
//!   `calculated` (calculated parameter), `local`. Real inputs, outputs and locals are
//!   continuous, Integer and Boolean ones discrete.
//! * `TYPE` is `real`, `int` or `bool`. An `int` carries its inclusive range, `int(0, i32::MAX)`,
//!   unless it is an enumeration (below), whose range is that of its codes.
//! * `ACCESS` is one of
//!   - a field path, `(params.angle_max)`, `(params.white_sigma[1])`, `(params.m[0][1])` or
//!     `(params.channels[2].sigma)`: the getter reads it and,
//!     for parameters and inputs, the setter writes it;
//!   - a field path with a cast, `(params.seed as u64)`: the field's type differs from the FMI type;
//!   - an enumeration, `(params.order => { 1: ServoOrder::First, 2: ServoOrder::Second })`: each
//!     code is written once with its variant (any pattern that is also an expression, such as a
//!     unit variant, `true` or `false`); the getter must cover every variant, the setter ignores a
//!     code that is not listed (the range check in `fmi2SetInteger` refuses it first);
//!   - a getter closure `(|m| m.gear.angle())`, for outputs;
//!   - a getter and a setter closure `(|m| .., |m, v| ..)`, where the field path does not fit.
//! * Modifiers are the const builders of [`Variable`](crate::Variable): `.range(lo, hi)`,
//!   `.min(lo)`, `.max(hi)` (Real bounds, declared in the XML and enforced on set) and
//!   `.depends_on(&["input", ..])` (an output's direct dependencies) and `.gated_by("param")`
//!   (an output scaled by a parameter, 0 by default or not: written in the XML's
//!   `<VendorAnnotations>` for the tool "shipsim", so that `shipsim check` warns when the output
//!   is connected while the parameter is 0).
//! * `fragment!(args);` in place of an entry splices in a run of entries that several FMUs
//!   share (see [`crate::fragments`]).
//!
//! Value references are positions in the table. **Rule: a released FMU's variables are never
//! reordered, removed or renumbered; new variables are only ever appended at the end of the
//! table**, so that users' OSP files, SSP files and scripts keep working.

/// Declares an FMU: its [`FmuDescription`](crate::FmuDescription) (identifier, description,
/// default experiment, optional direct feedthrough, documentation page and variable table) and
/// its FMI 2.0 C API ([`export_fmu!`](crate::export_fmu)).
///
/// ```text
/// fmi2_export::fmu! {
///     SteeringGearFmu => "SteeringGear",
///     description: "Steering machine ...",
///     experiment: (0.0, 30.0, 0.01),        // start, stop, step size [s]
///     direct_feedthrough: false,            // optional, default true
///     documentation: "documentation.html",  // next to the crate's lib.rs
///     variables: {
///         tunable real "angle_max" ["rad"] (params.angle_max).range(0.0, PI),
///             "Rudder-angle limit";
///         input real "rudder_command" ["rad"] (command), "Set-point rudder angle";
///         output real "rudder_angle" ["rad"] (|m| m.gear.angle()), "Actual rudder angle";
///     }
/// }
/// ```
#[macro_export]
macro_rules! fmu {
    ($model:ty => $($rest:tt)*) => {
        $crate::fmu_description!($model => $($rest)*);
        $crate::export_fmu!($model);
    };
}

/// The [`FmuDescription`](crate::FmuDescription) part of [`fmu!`](crate::fmu), without the C
/// symbols (for tests that put several model types in one binary). Takes the documentation page
/// either as a file next to the invoking source (`documentation: "documentation.html"`) or as
/// text (`documentation_html: "<p>..</p>"`).
#[macro_export]
macro_rules! fmu_description {
    (
        $model:ty => $id:literal,
        description: $desc:expr,
        experiment: ($t0:expr, $t1:expr, $h:expr),
        $(direct_feedthrough: $df:expr,)?
        documentation: $doc:literal,
        variables: { $($vars:tt)* } $(,)?
    ) => {
        $crate::fmu_description!(@impl $model, $id, $desc, ($t0, $t1, $h), [$($df)?],
            include_str!($doc), { $($vars)* });
    };
    (
        $model:ty => $id:literal,
        description: $desc:expr,
        experiment: ($t0:expr, $t1:expr, $h:expr),
        $(direct_feedthrough: $df:expr,)?
        documentation_html: $html:expr,
        variables: { $($vars:tt)* } $(,)?
    ) => {
        $crate::fmu_description!(@impl $model, $id, $desc, ($t0, $t1, $h), [$($df)?], $html,
            { $($vars)* });
    };
    (@impl $model:ty, $id:literal, $desc:expr, ($t0:expr, $t1:expr, $h:expr), [$($df:expr)?],
        $html:expr, { $($vars:tt)* }) => {
        impl $crate::FmuDescription for $model {
            const MODEL_IDENTIFIER: &'static str = $id;
            const DESCRIPTION: &'static str = $desc;
            const DEFAULT_EXPERIMENT: $crate::DefaultExperiment = $crate::DefaultExperiment {
                start_time: $t0,
                stop_time: $t1,
                step_size: $h,
            };
            $(const DIRECT_FEEDTHROUGH: bool = $df;)?

            fn variables() -> &'static [$crate::Variable<Self>] {
                static VARIABLES: &[$crate::Variable<$model>] = $crate::variables!($model; $($vars)*);
                VARIABLES
            }

            fn documentation_html() -> &'static str {
                $html
            }

            fn guid_cell() -> &'static ::std::sync::OnceLock<String> {
                static GUID: ::std::sync::OnceLock<String> = ::std::sync::OnceLock::new();
                &GUID
            }
        }
    };
}

/// A variable table for the model type `$model`, as a `&'static [Variable<$model>]` expression
/// (see the [module documentation](crate::table) for the language).
#[macro_export]
macro_rules! variables {
    ($model:ty; $($entries:tt)*) => {
        $crate::__variables!(@[$model] [] $($entries)*)
    };
}

/// The table muncher: `@[$model] [done entries] rest`.
#[doc(hidden)]
#[macro_export]
macro_rules! __variables {
    (@[$model:ty] [$($done:tt)*]) => {
        &[$($done)*]
    };
    // A shared fragment: it expands to its entries followed by the rest, through this muncher.
    (@[$model:ty] [$($done:tt)*] $fragment:ident ! ($($args:tt)*); $($rest:tt)*) => {
        $crate::$fragment! { @fragment [$model] [$($done)*] ($($args)*) $($rest)* }
    };
    (@[$model:ty] [$($done:tt)*]
        $kind:ident $type:ident $(($lo:expr, $hi:expr))? $name:literal $([$unit:literal])?
        ($($access:tt)*) $(.$modifier:ident($($arg:tt)*))*, $desc:expr; $($rest:tt)*
    ) => {
        $crate::__variables!(@[$model] [$($done)*
            $crate::Variable::<$model> {
                name: $name,
                causality: $crate::__causality!($kind),
                variability: $crate::__variability!($kind $type),
                description: $desc,
                access: $crate::__access!($kind $type [$($unit)?] [$($lo, $hi)?] ($($access)*)),
                dependencies: None,
                gate: None,
            } $(.$modifier($($arg)*))*,
        ] $($rest)*)
    };
}

#[doc(hidden)]
#[macro_export]
macro_rules! __causality {
    (fixed) => {
        $crate::Causality::Parameter
    };
    (tunable) => {
        $crate::Causality::Parameter
    };
    (calculated) => {
        $crate::Causality::CalculatedParameter
    };
    (input) => {
        $crate::Causality::Input
    };
    (output) => {
        $crate::Causality::Output
    };
    (local) => {
        $crate::Causality::Local
    };
}

#[doc(hidden)]
#[macro_export]
macro_rules! __variability {
    (fixed $t:ident) => {
        $crate::Variability::Fixed
    };
    (tunable $t:ident) => {
        $crate::Variability::Tunable
    };
    (calculated $t:ident) => {
        $crate::Variability::Fixed
    };
    ($kind:ident real) => {
        $crate::Variability::Continuous
    };
    ($kind:ident $t:ident) => {
        $crate::Variability::Discrete
    };
}

/// `Access` of one entry: `KIND TYPE [unit?] [lo, hi?] (ACCESS)`.
#[doc(hidden)]
#[macro_export]
macro_rules! __access {
    (fixed $($r:tt)*) => { $crate::__access!(@set $($r)*) };
    (tunable $($r:tt)*) => { $crate::__access!(@set $($r)*) };
    (input $($r:tt)*) => { $crate::__access!(@set $($r)*) };
    (output $($r:tt)*) => { $crate::__access!(@get $($r)*) };
    (calculated $($r:tt)*) => { $crate::__access!(@get $($r)*) };
    (local $($r:tt)*) => { $crate::__access!(@get $($r)*) };

    (@set real [$($unit:literal)?] [] $access:tt) => {
        $crate::Access::Real {
            get: $crate::__get!(f64 $access),
            set: Some($crate::__set!(f64 $access)),
            unit: $crate::__option!($($unit)?),
            min: None,
            max: None,
        }
    };
    (@get real [$($unit:literal)?] [] $access:tt) => {
        $crate::Access::Real {
            get: $crate::__get!(f64 $access),
            set: None,
            unit: $crate::__option!($($unit)?),
            min: None,
            max: None,
        }
    };
    // An enumeration: the range is that of its codes.
    (@$mode:ident int [] [] ($($f:ident $([$i:expr])*).+ => { $($code:literal : $($variant:ident)::+),+ $(,)? })) => {
        $crate::Access::Integer {
            get: $crate::__get!(i32 ($($f $([$i])*).+ => { $($code : $($variant)::+),+ })),
            set: $crate::__access!(@setter $mode i32 ($($f $([$i])*).+ => { $($code : $($variant)::+),+ })),
            min: Some($crate::table::min_code(&[$($code),+])),
            max: Some($crate::table::max_code(&[$($code),+])),
        }
    };
    (@$mode:ident int [] [$lo:expr, $hi:expr] $access:tt) => {
        $crate::Access::Integer {
            get: $crate::__get!(i32 $access),
            set: $crate::__access!(@setter $mode i32 $access),
            min: Some($lo),
            max: Some($hi),
        }
    };
    (@$mode:ident bool [] [] $access:tt) => {
        $crate::Access::Boolean {
            get: $crate::__get!(bool $access),
            set: $crate::__access!(@setter $mode bool $access),
        }
    };
    (@setter set $t:ident $access:tt) => { Some($crate::__set!($t $access)) };
    (@setter get $t:ident $access:tt) => { None };
}

/// The getter of an access form, as a closure coerced to `fn(&M) -> $t`.
#[doc(hidden)]
#[macro_export]
macro_rules! __get {
    ($t:ident (|$m:pat_param| $get:expr, |$m2:pat_param, $v:pat_param| $set:expr)) => { |$m| $get };
    ($t:ident (|$m:pat_param| $get:expr)) => { |$m| $get };
    ($t:ident ($($f:ident $([$i:expr])*).+ as $field:ty)) => { |m| m.$($f $([$i])*).+ as $t };
    ($t:ident ($($f:ident $([$i:expr])*).+ => { $($code:literal : $($variant:ident)::+),+ })) => {
        |m| match m.$($f $([$i])*).+ { $($($variant)::+ => $code,)+ }
    };
    ($t:ident ($($f:ident $([$i:expr])*).+)) => { |m| m.$($f $([$i])*).+ };
}

/// The setter of an access form, as a closure coerced to `fn(&mut M, $t)`.
#[doc(hidden)]
#[macro_export]
macro_rules! __set {
    ($t:ident (|$m:pat_param| $get:expr, |$m2:pat_param, $v:pat_param| $set:expr)) => { |$m2, $v| $set };
    ($t:ident (|$m:pat_param| $get:expr)) => {
        compile_error!("a parameter or input needs a setter: write (field.path) or (|m| get, |m, v| set)")
    };
    ($t:ident ($($f:ident $([$i:expr])*).+ as $field:ty)) => { |m, v| m.$($f $([$i])*).+ = v as $field };
    ($t:ident ($($f:ident $([$i:expr])*).+ => { $($code:literal : $($variant:ident)::+),+ })) => {
        |m, v| {
            if let Some(x) = match v { $($code => Some($($variant)::+),)+ _ => None } {
                m.$($f $([$i])*).+ = x;
            }
        }
    };
    ($t:ident ($($f:ident $([$i:expr])*).+)) => { |m, v| m.$($f $([$i])*).+ = v };
}

#[doc(hidden)]
#[macro_export]
macro_rules! __option {
    () => {
        None
    };
    ($x:expr) => {
        Some($x)
    };
}

/// The smallest code of an enumeration (its declared `min`).
pub const fn min_code(codes: &[i32]) -> i32 {
    let mut m = codes[0];
    let mut k = 1;
    while k < codes.len() {
        if codes[k] < m {
            m = codes[k];
        }
        k += 1;
    }
    m
}

/// The largest code of an enumeration (its declared `max`).
pub const fn max_code(codes: &[i32]) -> i32 {
    let mut m = codes[0];
    let mut k = 1;
    while k < codes.len() {
        if codes[k] > m {
            m = codes[k];
        }
        k += 1;
    }
    m
}
