//! Fuzzing that stays (issue 19): random FMI call sequences, mutated serialized states and
//! extreme in-range parameters on every FMU, and malformed system, OSP and model-description
//! files through the CLI. Each FMU case runs in a child process watched by the parent, so a
//! crash or hang is recorded, not fatal. The oracle and how to run it: docs/fuzzing.md.
//!
//! - [`rng`]: the seeded generator; a unit is a function of (seed, kind, FMU, index).
//! - [`ffi`]: loading an FMU binary and its variables (FFI confined to the fuzzer).
//! - [`calls`], [`gen`], [`mutate`]: FMI calls as data, random calls, state mutations.
//! - [`units`]: what one unit does (child side); [`proto`]: the child's records.
//! - [`runner`], [`watch`]: the parent, its per-call limits; [`files`]: malformed files.
//! - [`plan`]: the fixed suite of `cargo xtask test` and the rounds of `cargo xtask fuzz`.
//! - [`report`]: counts, failures and their repro lines.

pub mod calls;
pub mod ffi;
pub mod files;
pub mod gen;
pub mod mutate;
pub mod plan;
pub mod proto;
pub mod report;
pub mod rng;
pub mod runner;
pub mod units;
pub mod watch;

use std::os::unix::process::CommandExt;
use std::process::Command;

/// Address space a child may use: a state whose mutated length asks for terabytes fails an
/// allocation (a crash the oracle records) instead of taking the machine's memory.
pub const CHILD_ADDRESS_SPACE: u64 = 4 << 30;

/// Applies the limits of every process the fuzzer starts: [`CHILD_ADDRESS_SPACE`] and no core
/// files.
pub fn child_limits(cmd: &mut Command) {
    // SAFETY: setrlimit is async-signal-safe, as pre_exec requires.
    unsafe {
        cmd.pre_exec(|| {
            let set = |res, v: u64| {
                let lim = libc::rlimit {
                    rlim_cur: v,
                    rlim_max: v,
                };
                libc::setrlimit(res, &lim);
            };
            set(libc::RLIMIT_AS, CHILD_ADDRESS_SPACE);
            set(libc::RLIMIT_CORE, 0);
            Ok(())
        });
    }
}

/// `fuzz child <kind> <dir> <seed> <from> <to>`: runs units `from..to` of one FMU, reporting
/// records on stdout. Returns the exit status.
pub fn child_main(args: &[String]) -> i32 {
    // A panic of the fuzzer itself is not the FMU's: say so and use a status of its own.
    std::panic::set_hook(Box::new(|info| {
        proto::Record::Setup(format!("internal error of the fuzzer: {info}")).send();
        std::process::exit(70);
    }));
    let [kind, dir, seed, from, to] = args else {
        proto::Record::Setup("usage: fuzz child <kind> <dir> <seed> <from> <to>".into()).send();
        return 2;
    };
    let (Some(kind), Ok(seed), Ok(from), Ok(to)) = (
        units::Kind::parse(kind),
        seed.parse::<u64>(),
        from.parse::<u64>(),
        to.parse::<u64>(),
    ) else {
        proto::Record::Setup(format!("bad child arguments {args:?}")).send();
        return 2;
    };
    let loaded = ffi::Unpacked::at(std::path::Path::new(dir)).and_then(|u| ffi::Loaded::load(&u));
    let fmu = match loaded {
        Ok(f) => f,
        Err(e) => {
            proto::Record::Setup(format!("cannot load the FMU: {e}")).send();
            return 3;
        }
    };
    for unit in from..to {
        proto::Record::Unit(unit).send();
        units::run(kind, &fmu, seed, unit);
        proto::Record::Done(unit).send();
    }
    0
}
