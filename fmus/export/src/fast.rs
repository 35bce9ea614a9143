//! The step loop's path through the variable table: the Real accessors flattened by value
//! reference, built once per instance from [`FmuDescription::variables`].
//!
//! A co-simulation master calls `fmi2SetReal` on the connected inputs and `fmi2GetReal` on the
//! observed outputs at every communication point (FMI 2.0, sec. 4.2.4), so those two calls are
//! most of what the export layer costs a run. The variable table answers every question about a
//! variable (its type, causality, variability, range) by a `match` per value; for the values a
//! step loop moves the answers are fixed, so they are taken once here:
//!
//! * [`FastAccess::get_real`]: the getter of every Real variable (`None` for any other value
//!   reference);
//! * [`FastAccess::set_real`]: the setter and the accepted interval of every Real *input*. An
//!   input may be set in every state in which `fmi2SetReal` is legal at all (Instantiated,
//!   Initialization Mode, StepComplete, FMI 2.0, sec. 4.2.4), is never restored (only tunable
//!   parameters are, after `parameters_changed`), and takes a value that is finite and within its
//!   declared `[min, max]`. One comparison with `lo <= x <= hi` decides that: the interval is
//!   the declared range clipped to the finite numbers, so NaN and the infinities fall outside.
//!
//! A value the fast path does not accept (a parameter, a non-Real or unknown value reference, a
//! value out of range) takes the table path in [`crate::api`], which decides it and names the
//! reason; the fast path never refuses anything itself, so both paths accept exactly the same
//! calls with the same effect.

use crate::variables::{Access, Causality, Variable};
use crate::FmuDescription;

/// A Real input's setter and the interval `[lo, hi]` of values it accepts (finite, within the
/// range). Every other value reference has the empty interval `[+inf, -inf]`, which no value
/// passes, so the fast path needs no second test to hand it to the table path.
pub struct RealInput<M> {
    pub set: fn(&mut M, f64),
    pub lo: f64,
    pub hi: f64,
}

impl<M> RealInput<M> {
    /// Whether the fast path writes `x` (NaN fails both comparisons).
    #[inline(always)]
    pub fn accepts(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }
}

/// A Real variable's getter.
pub type RealGetter<M> = fn(&M) -> f64;

/// The Real accessors of a model type, indexed by value reference (see the module
/// documentation).
pub struct FastAccess<M> {
    pub get_real: Box<[Option<RealGetter<M>>]>,
    pub set_real: Box<[RealInput<M>]>,
}

impl<M: FmuDescription> FastAccess<M> {
    /// The accessors of `M::variables()`.
    pub fn new() -> Self {
        let vars = M::variables();
        FastAccess {
            get_real: vars.iter().map(real_getter).collect(),
            set_real: vars.iter().map(real_input).collect(),
        }
    }
}

fn real_getter<M>(v: &Variable<M>) -> Option<RealGetter<M>> {
    match v.access {
        Access::Real { get, .. } => Some(get),
        _ => None,
    }
}

fn real_input<M>(v: &Variable<M>) -> RealInput<M> {
    match v.access {
        Access::Real {
            set: Some(set),
            min,
            max,
            ..
        } if v.causality == Causality::Input => RealInput {
            set,
            lo: min.map_or(f64::MIN, |lo| lo.max(f64::MIN)),
            hi: max.map_or(f64::MAX, |hi| hi.min(f64::MAX)),
        },
        _ => RealInput {
            set: |_, _| {},
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
        },
    }
}
