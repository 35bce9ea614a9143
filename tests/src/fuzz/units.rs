//! The units a child process runs: a random call sequence, a mutated serialized state, or one
//! extreme in-range parameter value followed by one step. Every unit makes its own instance and
//! frees it, so any unit can run alone (a crash or hang ends the child; the parent starts a new
//! one at the next unit).

use super::calls::{Bytes, Call, Ctx, Phase, StateRef};
use super::ffi::{Loaded, Model, Var};
use super::gen;
use super::mutate;
use super::proto::Record;
use super::rng::{unit_rng, Rng};
use fmi2::{fmi2OK, fmi2Warning};
use shipsim::model_description::VarType;

/// Calls in one random sequence.
pub const CALLS_PER_UNIT: usize = 40;

/// What a unit of each kind does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    Calls,
    State,
    Param,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Calls => "calls",
            Kind::State => "state",
            Kind::Param => "param",
        }
    }
    pub fn parse(s: &str) -> Option<Kind> {
        [Kind::Calls, Kind::State, Kind::Param]
            .into_iter()
            .find(|k| k.name() == s)
    }
}

/// Runs unit `unit` of `kind` on `fmu`.
pub fn run(kind: Kind, fmu: &Loaded, seed: u64, unit: u64) {
    let mut rng = unit_rng(seed, kind.name(), &fmu.model.name, unit);
    let mut ctx = Ctx::new(fmu);
    match kind {
        Kind::Calls => {
            for _ in 0..CALLS_PER_UNIT {
                let call = gen::next(&mut rng, &ctx);
                ctx.run(&call);
                if ctx.nonfinite {
                    break;
                }
            }
        }
        Kind::State => mutated_state(&mut ctx, &mut rng),
        Kind::Param => {
            let cases = param_cases(&fmu.model);
            let case = match cases.get(unit as usize) {
                Some(c) => c.clone(),
                None => random_params(&mut rng, &fmu.model),
            };
            if !case.is_empty() {
                parameters(&mut ctx, &case);
            }
        }
    }
    ctx.close();
}

/// Instantiate, setup at t = 0 and initialize; false when the FMU refused.
fn start(ctx: &mut Ctx) -> bool {
    ctx.run(&gen::instantiate(&mut Rng::new(0), true)) == fmi2OK
        && ctx.run(&Call::Setup {
            tolerance: None,
            start: 0.0,
            stop: None,
        }) == fmi2OK
        && ctx.run(&Call::Enter) == fmi2OK
        && ctx.run(&Call::Exit) == fmi2OK
}

fn ok(st: i32) -> bool {
    st == fmi2OK || st == fmi2Warning
}

/// A few steps, a serialized state, 1-4 mutations of its body, fmi2DeSerializeFMUstate,
/// fmi2SetFMUstate and two steps from the state's time.
fn mutated_state(ctx: &mut Ctx, rng: &mut Rng) {
    if !start(ctx) {
        return;
    }
    let h = ctx.fmu.model.default_step;
    for _ in 0..1 + rng.below(10) {
        let t = ctx.time;
        if !ok(ctx.run(&Call::DoStep {
            t,
            h,
            no_prior: false,
        })) {
            return;
        }
    }
    if !ok(ctx.run(&Call::GetState(None)))
        || !ok(ctx.run(&Call::Serialize {
            state: StateRef::Live(0),
            short: 0,
        }))
    {
        return;
    }
    let m = mutate::draw(rng, ctx.bytes.len());
    let before = ctx.states.len();
    if !ok(ctx.run(&Call::Deserialize(Bytes::Mutated(m)))) || ctx.states.len() == before {
        return;
    }
    if !ok(ctx.run(&Call::SetState(StateRef::Live(before)))) {
        return;
    }
    // The state's own time, from fmi2GetRealStatus(fmi2LastSuccessfulTime).
    ctx.time = last_successful_time(ctx).unwrap_or(ctx.time);
    for _ in 0..2 {
        let t = ctx.time;
        if ctx.phase != Phase::Step
            || !ok(ctx.run(&Call::DoStep {
                t,
                h,
                no_prior: false,
            }))
        {
            return;
        }
    }
}

fn last_successful_time(ctx: &mut Ctx) -> Option<f64> {
    let mut t = 0.0;
    Record::Begin("getRealStatus(kind=2) (the state's time)".into()).send();
    // SAFETY: the component is live; `t` is a valid out pointer.
    let st =
        unsafe { (ctx.fmu.api.fmi2GetRealStatus)(ctx.comp, fmi2::fmi2LastSuccessfulTime, &mut t) };
    Record::End(st).send();
    ctx.calls += 1;
    (st == fmi2OK && t.is_finite()).then_some(t)
}

/// Parameter values, then initialization and one step of 1 s.
fn parameters(ctx: &mut Ctx, case: &[(Var, f64)]) {
    if ctx.run(&gen::instantiate(&mut Rng::new(0), true)) != fmi2OK {
        return;
    }
    for (var, value) in case {
        let vrs = super::calls::Vrs::List(vec![var.vr]);
        let set = match var.ty {
            VarType::Real => Call::SetReal(vrs, vec![*value]),
            VarType::Boolean => Call::SetBoolean(vrs, vec![*value as i32]),
            _ => Call::SetInteger(vrs, vec![*value as i32]),
        };
        if !ok(ctx.run(&set)) {
            return;
        }
    }
    for call in [
        Call::Setup {
            tolerance: None,
            start: 0.0,
            stop: None,
        },
        Call::Enter,
        Call::Exit,
        Call::DoStep {
            t: 0.0,
            h: 1.0,
            no_prior: false,
        },
    ] {
        if !ok(ctx.run(&call)) || ctx.nonfinite {
            return;
        }
    }
}

/// Extreme values inside a declared range: its ends, tiny positive and negative values, zero,
/// and large magnitudes.
pub fn extremes(var: &Var) -> Vec<f64> {
    let (lo, hi) = (var.min, var.max);
    let candidates: Vec<f64> = match var.ty {
        VarType::Real => vec![
            lo,
            hi,
            5e-324,
            1e-300,
            1e-100,
            1e-12,
            1e-6,
            0.0,
            -1e-300,
            -1e-6,
            1e6,
            -1e6,
            1e300,
            -1e300,
            f64::MAX,
            -f64::MAX,
        ],
        VarType::Boolean => vec![0.0, 1.0],
        _ => vec![
            lo,
            hi,
            0.0,
            1.0,
            -1.0,
            1e6,
            f64::from(i32::MAX),
            f64::from(i32::MIN),
        ],
    };
    let mut out: Vec<f64> = Vec::new();
    for x in candidates {
        if x.is_finite() && x >= lo && x <= hi && !out.iter().any(|y| y.to_bits() == x.to_bits()) {
            out.push(x);
        }
    }
    out
}

/// The fixed parameter cases of a model, in table order: every (parameter, extreme value); then
/// every mode-like Integer parameter (declared maximum at most 1000) at its maximum with every
/// Real parameter at 1e-300 (SteeringGear's `max_substep` only sub-steps with `servo_order` = 2).
pub fn param_cases(model: &Model) -> Vec<Vec<(Var, f64)>> {
    let mut cases: Vec<Vec<(Var, f64)>> = model
        .parameters()
        .flat_map(|v| extremes(v).into_iter().map(move |x| vec![(v.clone(), x)]))
        .collect();
    let modes = model.parameters().filter(|v| {
        v.ty != VarType::Real
            && v.ty != VarType::Boolean
            && v.max <= 1000.0
            && Some(v.max) != v.start
    });
    for m in modes {
        for r in model.parameters().filter(|v| v.ty == VarType::Real) {
            if r.min <= 1e-300 && r.max >= 1e-300 {
                cases.push(vec![(m.clone(), m.max), (r.clone(), 1e-300)]);
            }
        }
    }
    cases
}

/// One to three random parameters at random in-range values (the long run, past the fixed
/// cases): half the time an extreme value, else any in range.
fn random_params(rng: &mut Rng, model: &Model) -> Vec<(Var, f64)> {
    let params: Vec<&Var> = model.parameters().collect();
    if params.is_empty() {
        return Vec::new();
    }
    (0..1 + rng.below(3))
        .map(|_| {
            let v = (*rng.pick(&params)).clone();
            let x = match v.ty {
                VarType::Real => {
                    let e = extremes(&v);
                    if rng.chance(0.5) && !e.is_empty() {
                        *rng.pick(&e)
                    } else {
                        gen::in_range(rng, v.min, v.max)
                    }
                }
                VarType::Boolean => rng.below(2) as f64,
                _ => f64::from(gen::integer(rng, Some(&v))),
            };
            (v, x)
        })
        .collect()
}
