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
    /// The getters of the Real outputs, with their value references, for the finiteness check
    /// after `fmi2ExitInitializationMode` and `fmi2DoStep`.
    pub outputs: Box<[(u32, RealGetter<M>)]>,
}

impl<M: FmuDescription> FastAccess<M> {
    /// The accessors of `M::variables()`.
    pub fn new() -> Self {
        let vars = M::variables();
        let output = |(vr, v): (usize, &Variable<M>)| match v.access {
            Access::Real { get, .. } if v.causality == Causality::Output => Some((vr as u32, get)),
            _ => None,
        };
        FastAccess {
            get_real: vars.iter().map(real_getter).collect(),
            set_real: vars.iter().map(real_input).collect(),
            outputs: vars.iter().enumerate().filter_map(output).collect(),
        }
    }

    /// The value reference of the first Real output of `m` that is not a finite number (`None`:
    /// all are finite). The common path is one subtraction and one addition per output and one
    /// test at the end: `x - x` is 0 for a finite `x` and NaN for NaN and the infinities.
    #[inline]
    pub fn non_finite_output(&self, m: &M) -> Option<u32> {
        let mut sum = 0.0;
        for (_, get) in self.outputs.iter() {
            let x = get(m);
            sum += x - x;
        }
        if sum == 0.0 {
            None
        } else {
            self.first_non_finite(m)
        }
    }

    #[cold]
    #[inline(never)]
    fn first_non_finite(&self, m: &M) -> Option<u32> {
        let bad = self.outputs.iter().find(|(_, get)| !get(m).is_finite());
        bad.map(|(vr, _)| *vr)
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

#[cfg(test)]
mod tests {
    //! The fast path accepts exactly the values the table path accepts, with the same effect,
    //! and leaves every refusal, with its message, to the table path.
    use crate::testing::{functions, Harness};
    use crate::FmuModel;
    use fmi2::*;
    use serde::{Deserialize, Serialize};

    #[derive(Clone, Debug, Default, Serialize, Deserialize)]
    struct Ranged {
        a: f64,
        b: f64,
        c: f64,
        k: f64,
        n: i32,
        sum: f64,
    }

    crate::fmu_description! {
        Ranged => "Ranged",
        description: "ranged inputs",
        experiment: (0.0, 1.0, 0.5),
        documentation_html: "",
        variables: {
            input real "a" (a).range(-1.0, 1.0), "a in [-1, 1]";
            input real "b" (b).min(0.0), "b >= 0";
            input real "c" (c), "any finite c";
            tunable real "k" (k).range(0.0, 10.0), "a tunable parameter";
            fixed int(0, 5) "n" (n), "an Integer";
            output real "sum" (sum), "a + b + c + k, kept by calculate_outputs";
        }
    }

    impl FmuModel for Ranged {
        fn initialize(&mut self, _t: f64) -> Result<(), String> {
            self.calculate_outputs();
            Ok(())
        }
        fn calculate_outputs(&mut self) {
            self.sum = self.a + self.b + self.c + self.k;
        }
        fn do_step(&mut self, _t: f64, _h: f64) -> Result<(), String> {
            self.calculate_outputs();
            Ok(())
        }
    }

    fn set(fmu: &Harness<Ranged>, vrs: &[u32], xs: &[f64]) -> fmi2Status {
        let (f, c) = (fmu.functions(), fmu.component());
        unsafe { (f.fmi2SetReal)(c, vrs.as_ptr(), vrs.len(), xs.as_ptr()) }
    }

    fn get(fmu: &Harness<Ranged>, vrs: &[u32]) -> (fmi2Status, Vec<u64>) {
        let (f, c) = (fmu.functions(), fmu.component());
        let mut out = vec![f64::NAN; vrs.len()];
        let s = unsafe { (f.fmi2GetReal)(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (s, out.iter().map(|x| x.to_bits()).collect())
    }

    fn bits(xs: &[f64]) -> Vec<u64> {
        xs.iter().map(|x| x.to_bits()).collect()
    }

    #[test]
    fn real_inputs_take_the_fast_path_and_every_refusal_the_table_path() {
        let mut fmu = Harness::<Ranged>::instantiate(functions::<Ranged>(), "ranged");
        fmu.initialize(0.0);
        let [a, b, c, k, n, sum] = ["a", "b", "c", "k", "n", "sum"].map(|name| fmu.vr(name));
        // Bounds are inclusive, -0.0 >= 0 keeps its sign, any finite value passes where no
        // range is declared; a parameter in the same batch goes through the table.
        let accepted = [1.0, -0.0, -f64::MAX, 10.0];
        assert_eq!(set(&fmu, &[a, b, c, k], &accepted), fmi2OK);
        assert_eq!(get(&fmu, &[a, b, c, k]), (fmi2OK, bits(&accepted)));
        // The outputs follow the inputs before the next step (the fast path marks them stale).
        assert_eq!(set(&fmu, &[c], &[2.0]), fmi2OK);
        assert_eq!(get(&fmu, &[sum]), (fmi2OK, bits(&[13.0])));
        // Refusals name the variable and the reason and leave every value as it was.
        for (vr, x, reason) in [
            (
                a,
                1.0 + f64::EPSILON,
                "\"a\" = 1.0000000000000002 refused: outside [-1, 1]",
            ),
            (a, -1.5, "\"a\" = -1.5 refused: outside [-1, 1]"),
            (a, f64::NAN, "\"a\" = NaN refused: not a finite number"),
            (b, -0.5, "\"b\" = -0.5 refused: outside [0, inf]"),
            (b, f64::INFINITY, "\"b\" = inf refused: not a finite number"),
            (
                c,
                f64::NEG_INFINITY,
                "\"c\" = -inf refused: not a finite number",
            ),
            (k, 10.5, "\"k\" = 10.5 refused: outside [0, 10]"),
        ] {
            assert_eq!(set(&fmu, &[vr], &[x]), fmi2Error);
            assert!(fmu.log().last().contains(reason), "{}", fmu.log().last());
        }
        assert_eq!(
            get(&fmu, &[a, b, c, k]),
            (fmi2OK, bits(&[1.0, -0.0, 2.0, 10.0]))
        );
        // A batch stops at a value reference of the wrong type or of no variable, after
        // writing the values before it; getters refuse the same references.
        assert_eq!(set(&fmu, &[c, n, b], &[3.0, 1.0, 4.0]), fmi2Error);
        assert!(fmu
            .log()
            .last()
            .contains("is Integer \"n\", not a Real variable"));
        assert_eq!(get(&fmu, &[c, b]), (fmi2OK, bits(&[3.0, -0.0])));
        assert_eq!(set(&fmu, &[99], &[0.0]), fmi2Error);
        assert!(fmu
            .log()
            .last()
            .contains("no variable with value reference 99"));
        assert_eq!(set(&fmu, &[sum], &[0.0]), fmi2Error);
        assert!(fmu
            .log()
            .last()
            .contains("\"sum\" has causality Output and cannot be set"));
        assert_eq!(get(&fmu, &[sum, n]).0, fmi2Error);
        assert!(fmu
            .log()
            .last()
            .contains("is Integer \"n\", not a Real variable"));
        assert_eq!(get(&fmu, &[99]).0, fmi2Error);
        assert!(fmu
            .log()
            .last()
            .contains("no variable with value reference 99"));
        // fmi2DoStep refuses an infinite communication point and an infinite step size.
        assert_eq!(fmu.try_step(f64::INFINITY, 0.5), fmi2Error);
        assert!(fmu.log().last().contains("currentCommunicationPoint = inf"));
        assert_eq!(fmu.try_step(0.0, f64::INFINITY), fmi2Error);
        assert!(fmu
            .log()
            .last()
            .contains("communicationStepSize = inf must be > 0"));
        fmu.step(0.0, 0.5);
        assert_eq!(get(&fmu, &[sum]), (fmi2OK, bits(&[14.0])));
    }
}
