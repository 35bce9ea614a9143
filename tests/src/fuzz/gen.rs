//! Random calls and arguments. Three in four calls are ones the state machine allows in the
//! phase the instance is in (with random arguments, legal or not); one in four is any call.

use super::calls::{Bytes, Call, Ctx, InstantiateArgs, Phase, StateRef, Vrs};
use super::ffi::{Model, Var};
use super::mutate;
use super::rng::Rng;
use shipsim::model_description::VarType;

/// Doubles that break arithmetic: non-finite, signed zero, denormal, tiny, huge.
pub const SPECIAL_F64: [f64; 18] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    5e-324,
    -5e-324,
    f64::MIN_POSITIVE,
    1e-300,
    -1e-300,
    1e-12,
    1e300,
    -1e300,
    f64::MAX,
    f64::MIN,
    1e6,
    -1e6,
    -1.0,
];

const SPECIAL_I32: [i32; 9] = [0, 1, -1, 2, 255, 65536, i32::MAX, i32::MIN, 1_000_000];

/// A Real value for `var` (or for no variable in particular).
pub fn real(rng: &mut Rng, var: Option<&Var>) -> f64 {
    let (lo, hi) = var.map_or((f64::NEG_INFINITY, f64::INFINITY), |v| (v.min, v.max));
    match rng.weighted(&[35, 10, 30, 10, 5, 10]) {
        0 => in_range(rng, lo, hi),
        1 => var.and_then(|v| v.start).unwrap_or(0.0),
        2 => *rng.pick(&SPECIAL_F64),
        3 => {
            if rng.chance(0.5) {
                lo
            } else {
                hi
            }
        }
        4 => f64::from_bits(rng.next_u64()),
        _ => (rng.unit() - 0.5) * 10f64.powi(rng.below(12) as i32 - 3),
    }
}

/// Uniform in [lo, hi] when both are finite and close; log-uniform magnitudes otherwise.
pub fn in_range(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    if lo.is_finite() && hi.is_finite() && hi - lo < 1e6 {
        return lo + rng.unit() * (hi - lo);
    }
    let mag = 10f64.powf(rng.unit() * 12.0 - 6.0);
    let x = if rng.chance(0.5) { mag } else { -mag };
    x.clamp(lo.max(-f64::MAX), hi.min(f64::MAX))
}

pub fn integer(rng: &mut Rng, var: Option<&Var>) -> i32 {
    let (lo, hi) = var.map_or((-10.0, 10.0), |v| (v.min, v.max));
    match rng.weighted(&[50, 15, 25, 10]) {
        0 => {
            let (lo, hi) = (lo.max(-1000.0) as i64, hi.min(1000.0) as i64);
            if hi >= lo {
                (lo + rng.below((hi - lo + 1) as usize) as i64) as i32
            } else {
                0
            }
        }
        1 => var.and_then(|v| v.start).unwrap_or(0.0) as i32,
        2 => *rng.pick(&SPECIAL_I32),
        _ => {
            if rng.chance(0.5) {
                lo as i32
            } else {
                hi as i32
            }
        }
    }
}

fn boolean(rng: &mut Rng) -> i32 {
    *rng.pick(&[0, 1, 0, 1, 0, 1, 2, -1, 255])
}

/// Value references of type `ty`, mostly of variables `settable` accepts.
fn vrs(rng: &mut Rng, model: &Model, ty: VarType, settable: &dyn Fn(&Var) -> bool) -> Vrs {
    let all = model.of(ty);
    let pool: Vec<&Var> = if rng.chance(0.8) {
        all.iter().filter(|v| settable(v)).collect()
    } else {
        all.iter().collect()
    };
    let random_vr = |rng: &mut Rng| -> u32 {
        let small = rng.below(64) as u32;
        *rng.pick(&[u32::MAX, 9999, 1 << 31, small])
    };
    match rng.weighted(&[75, 8, 7, 3, 4, 3]) {
        0 if !pool.is_empty() => {
            let n = 1 + rng.below(3);
            Vrs::List((0..n).map(|_| rng.pick(&pool).vr).collect())
        }
        1 => {
            let other = [
                VarType::Real,
                VarType::Integer,
                VarType::Boolean,
                VarType::String,
            ];
            let o = model.of(*rng.pick(&other));
            Vrs::List(if o.is_empty() {
                vec![0]
            } else {
                vec![rng.pick(o).vr]
            })
        }
        3 => Vrs::List(Vec::new()),
        4 => Vrs::NullVr(1 + rng.below(4)),
        5 if !pool.is_empty() => Vrs::NullValues(vec![rng.pick(&pool).vr]),
        _ => Vrs::List(vec![random_vr(rng)]),
    }
}

fn var_of(model: &Model, ty: VarType, vr: u32) -> Option<&Var> {
    model.of(ty).iter().find(|v| v.vr == vr)
}

/// Which variables the phase lets one set (FMI 2.0 sec. 4.2.4, the table of the state machine).
fn settable(phase: Phase) -> impl Fn(&Var) -> bool {
    move |v: &Var| match phase {
        Phase::Instantiated => v.settable_instantiated,
        Phase::Init => v.is_parameter() || v.causality == fmi2::Causality::Input,
        _ => {
            v.causality == fmi2::Causality::Input
                || (v.is_parameter() && v.variability == fmi2::Variability::Tunable)
        }
    }
}

fn get_call(rng: &mut Rng, model: &Model) -> Call {
    let any = |_: &Var| true;
    match rng.weighted(&[6, 2, 2, 1]) {
        0 => Call::GetReal(vrs(rng, model, VarType::Real, &any)),
        1 => Call::GetInteger(vrs(rng, model, VarType::Integer, &any)),
        2 => Call::GetBoolean(vrs(rng, model, VarType::Boolean, &any)),
        _ => Call::GetString(vrs(rng, model, VarType::String, &any)),
    }
}

/// One value per value reference, drawn for its variable when the list names one.
fn values<T>(
    rng: &mut Rng,
    model: &Model,
    ty: VarType,
    v: &Vrs,
    draw: fn(&mut Rng, Option<&Var>) -> T,
) -> Vec<T> {
    (0..v.len())
        .map(|i| {
            let var = match v {
                Vrs::List(l) => var_of(model, ty, l[i]),
                _ => None,
            };
            draw(rng, var)
        })
        .collect()
}

fn set_call(rng: &mut Rng, model: &Model, phase: Phase) -> Call {
    let ok = settable(phase);
    match rng.weighted(&[7, 2, 2, 1]) {
        0 => {
            let v = vrs(rng, model, VarType::Real, &ok);
            let x = values(rng, model, VarType::Real, &v, real);
            Call::SetReal(v, x)
        }
        1 => {
            let v = vrs(rng, model, VarType::Integer, &ok);
            let x = values(rng, model, VarType::Integer, &v, integer);
            Call::SetInteger(v, x)
        }
        2 => {
            let v = vrs(rng, model, VarType::Boolean, &ok);
            let x = (0..v.len()).map(|_| boolean(rng)).collect();
            Call::SetBoolean(v, x)
        }
        _ => {
            let v = vrs(rng, model, VarType::String, &ok);
            let x = (0..v.len())
                .map(|_| match rng.below(4) {
                    0 => None,
                    1 => Some(String::new()),
                    2 => Some("x".repeat(1 + rng.below(5000))),
                    _ => Some("fuzz %s %n".to_string()),
                })
                .collect();
            Call::SetString(v, x)
        }
    }
}

/// A communication step size: mostly ordinary, sometimes large, huge or invalid.
pub fn step_size(rng: &mut Rng, model: &Model) -> f64 {
    match rng.weighted(&[55, 15, 12, 10, 8]) {
        0 => model.default_step * *rng.pick(&[0.5, 1.0, 1.0, 2.0, 10.0]),
        1 => *rng.pick(&[1e-3, 0.01, 0.05, 0.1, 0.5, 1.0, 2.0]),
        2 => *rng.pick(&[5.0, 10.0, 60.0, 100.0, 600.0]),
        3 => *rng.pick(&[1e3, 1e4, 1e6, 1e9, 1e12, 1e300, f64::MAX]),
        _ => *rng.pick(&[
            0.0,
            -0.0,
            -1.0,
            f64::NAN,
            f64::INFINITY,
            5e-324,
            1e-300,
            1e-12,
        ]),
    }
}

fn do_step(rng: &mut Rng, ctx: &Ctx) -> Call {
    let t = match rng.weighted(&[88, 4, 4, 4]) {
        0 => ctx.time,
        1 => ctx.time + 0.5,
        2 => 0.0,
        _ => *rng.pick(&[f64::NAN, f64::INFINITY, -1.0, 1e300]),
    };
    Call::DoStep {
        t,
        h: step_size(rng, &ctx.fmu.model),
        no_prior: rng.chance(0.5),
    }
}

fn state_ref(rng: &mut Rng) -> StateRef {
    match rng.weighted(&[85, 8, 7]) {
        0 => StateRef::Live(rng.below(4)),
        1 => StateRef::Null,
        _ => StateRef::Freed(rng.below(4)),
    }
}

fn state_call(rng: &mut Rng, ctx: &Ctx) -> Call {
    match rng.weighted(&[20, 20, 8, 6, 14, 16, 4]) {
        0 => Call::GetState(if rng.chance(0.2) {
            Some(rng.below(4))
        } else {
            None
        }),
        1 => Call::SetState(state_ref(rng)),
        2 => Call::FreeState(state_ref(rng)),
        3 => Call::StateSize {
            state: state_ref(rng),
            null_size: rng.chance(0.2),
        },
        4 => Call::Serialize {
            state: state_ref(rng),
            short: *rng.pick(&[0, 0, 0, 1, 8, 1 << 20]),
        },
        5 => Call::Deserialize(match rng.weighted(&[30, 55, 8, 7]) {
            0 => Bytes::Valid,
            1 => Bytes::Mutated(mutate::draw(rng, ctx.bytes.len())),
            2 => Bytes::Zeros(*rng.pick(&[0, 1, 11, 12, 100, 1 << 20])),
            _ => Bytes::Null(*rng.pick(&[0, 1, 100])),
        }),
        _ => Call::Status {
            which: rng.below(5) as u8,
            kind: *rng.pick(&[0, 1, 2, 3, -1, 99]),
            null_value: rng.chance(0.1),
        },
    }
}

pub fn instantiate(rng: &mut Rng, legal: bool) -> Call {
    let wrong = |rng: &mut Rng, p: f64| !legal && rng.chance(p);
    Call::Instantiate(InstantiateArgs {
        name: if wrong(rng, 0.15) {
            None
        } else {
            Some("fuzz".into())
        },
        fmu_type: if wrong(rng, 0.15) {
            *rng.pick(&[0, 7, -1])
        } else {
            1
        },
        guid: if wrong(rng, 0.2) {
            1 + rng.below(2) as u8
        } else {
            0
        },
        resources: if wrong(rng, 0.2) {
            1 + rng.below(2) as u8
        } else {
            0
        },
        callbacks: if wrong(rng, 0.15) {
            1 + rng.below(2) as u8
        } else {
            0
        },
        logging: rng.chance(0.3),
    })
}

fn setup(rng: &mut Rng) -> Call {
    let start = match rng.weighted(&[80, 20]) {
        0 => 0.0,
        _ => *rng.pick(&[1.0, -1.0, f64::NAN, 1e300, f64::INFINITY, 5e-324]),
    };
    Call::Setup {
        tolerance: rng
            .chance(0.3)
            .then(|| *rng.pick(&[1e-6, 0.0, -1.0, f64::NAN])),
        start,
        stop: rng.chance(0.4).then(|| {
            *rng.pick(&[
                start + 10.0,
                start + 1e6,
                start - 1.0,
                f64::NAN,
                f64::INFINITY,
            ])
        }),
    }
}

/// Any call at all, whatever the phase.
fn any_call(rng: &mut Rng, ctx: &Ctx) -> Call {
    let model = &ctx.fmu.model;
    match rng.below(17) {
        0 => instantiate(rng, false),
        1 => setup(rng),
        2 => Call::Enter,
        3 => Call::Exit,
        4 => Call::Terminate,
        5 => Call::Reset,
        6 => get_call(rng, model),
        7 => set_call(rng, model, ctx.phase),
        8 => do_step(rng, ctx),
        9 | 10 => state_call(rng, ctx),
        11 => Call::CancelStep,
        12 => Call::SetDebugLogging {
            on: rng.chance(0.5),
            categories: rng.chance(0.8).then(|| {
                vec![rng
                    .pick(&["logStatusError", "logCalls", "nope", "", "logEvents"])
                    .to_string()]
            }),
            n: rng.below(4),
        },
        13 => {
            let o: Vec<u32> = model.real_outputs.iter().take(2).copied().collect();
            let i: Vec<u32> = model.real.iter().take(2).map(|v| v.vr).collect();
            Call::DirectionalDerivative {
                dv: i.iter().map(|_| real(rng, None)).collect(),
                unknown: o,
                known: i,
            }
        }
        14 => {
            let v = vrs(rng, model, VarType::Real, &|_| true);
            let n = v.len();
            Call::SetInputDerivatives(
                v,
                (0..n).map(|_| *rng.pick(&[1, 0, 2, -1])).collect(),
                (0..n).map(|_| real(rng, None)).collect(),
            )
        }
        15 => {
            let v = vrs(rng, model, VarType::Real, &|_| true);
            let n = v.len();
            Call::GetOutputDerivatives(v, (0..n).map(|_| *rng.pick(&[1, 0, 2, -1])).collect())
        }
        _ => Call::NullComponent(rng.below(6) as u8),
    }
}

/// The next call of a random sequence.
pub fn next(rng: &mut Rng, ctx: &Ctx) -> Call {
    let model = &ctx.fmu.model;
    if ctx.phase != Phase::NoInstance && rng.chance(0.25) {
        return any_call(rng, ctx);
    }
    match ctx.phase {
        Phase::NoInstance => {
            let legal = rng.chance(0.85);
            instantiate(rng, legal)
        }
        Phase::Instantiated => match rng.weighted(&[25, 35, 5, 25, 5, 5]) {
            0 => setup(rng),
            1 => set_call(rng, model, ctx.phase),
            2 => get_call(rng, model),
            3 => Call::Enter,
            4 => state_call(rng, ctx),
            _ => Call::FreeInstance,
        },
        Phase::Init => match rng.weighted(&[35, 20, 40, 5]) {
            0 => set_call(rng, model, ctx.phase),
            1 => get_call(rng, model),
            2 => Call::Exit,
            _ => state_call(rng, ctx),
        },
        Phase::Step => match rng.weighted(&[40, 20, 12, 18, 3, 3, 2, 2]) {
            0 => do_step(rng, ctx),
            1 => set_call(rng, model, ctx.phase),
            2 => get_call(rng, model),
            3 => state_call(rng, ctx),
            4 => Call::Terminate,
            5 => Call::Reset,
            6 => Call::FreeInstance,
            _ => Call::CancelStep,
        },
        Phase::Terminated | Phase::Error => match rng.weighted(&[30, 20, 30, 20]) {
            0 => get_call(rng, model),
            1 => state_call(rng, ctx),
            2 => Call::Reset,
            _ => Call::FreeInstance,
        },
        Phase::Fatal => Call::FreeInstance,
    }
}
