//! The pure-Rust RRS model loop (`system_tests::model_loop::rrs`) records bit for bit what
//! `shipsim run systems/rrs.toml` records through the FMUs (`target/fmu` or `SHIPSIM_FMU_DIR`;
//! fails, never skips, when they have not been built): 300 s with RRS on and off, and with the
//! main parameters overridden; and the `rrs-model-loop` binary writes the same CSV file as
//! `shipsim run`, byte for byte. Tolerance: none (every value compared by its bits).

use models::controllers::rrs::RollMode;
use shipsim::run::{prepare, run, run_into, MemoryRecorder, Output, RunOptions};
use system_tests::model_loop::rrs::{self, RrsParams, COLUMNS};
use system_tests::study::Env;

/// `systems/rrs.toml` with `--set` overrides, run by the master to `stop` s.
fn shipsim_run(sets: &[&str], stop: f64) -> shipsim::system::System {
    let env = Env::new("model_loop").unwrap();
    let mut system = env.system("rrs.toml").unwrap();
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    system.apply_overrides(&sets).unwrap();
    system.stop_time = Some(stop);
    system
}

/// The master's recorded columns of `systems/rrs.toml` with `sets`, to `stop` s.
fn shipsim_columns(sets: &[&str], stop: f64) -> MemoryRecorder {
    let (plan, fmus) = prepare(&shipsim_run(sets, stop)).unwrap();
    let mut memory = MemoryRecorder::new();
    run_into(&plan, &fmus, Some(&mut memory), &RunOptions::default()).unwrap();
    memory
}

/// Asserts that the model loop with `params` records bit for bit what the master records
/// with `sets`, over `stop` s.
fn assert_bit_identical(params: &RrsParams, sets: &[&str], stop: f64) {
    let expected = shipsim_columns(sets, stop);
    let names: Vec<&str> = expected.columns.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, COLUMNS, "the recorded columns of systems/rrs.toml");
    let mut row = 0;
    let summary = rrs::run(stop, params, |t, v| {
        assert!(row < expected.time.len(), "more rows than shipsim's");
        assert_eq!(
            t.to_bits(),
            expected.time[row].to_bits(),
            "time of row {row}"
        );
        for (j, x) in v.recorded().iter().enumerate() {
            let e = expected.data[j][row];
            assert!(
                x.to_bits() == e.to_bits(),
                "{sets:?}: {} at t = {t}: model loop {x:e}, shipsim {e:e}",
                COLUMNS[j]
            );
        }
        row += 1;
    })
    .unwrap();
    assert_eq!(row, expected.time.len(), "rows");
    assert_eq!(summary.macro_steps, (stop / rrs::STEP_SIZE).round() as u64);
    assert_eq!(summary.stop_time, stop);
}

#[test]
fn rrs_on_is_bit_identical_to_shipsim_over_300_s() {
    assert_bit_identical(&RrsParams::default(), &[], 300.0);
}

#[test]
fn rrs_off_is_bit_identical_to_shipsim_over_300_s() {
    let off = RrsParams {
        roll_mode: RollMode::Off,
        ..RrsParams::default()
    };
    assert_bit_identical(&off, &["autopilot.roll_mode=0"], 300.0);
}

/// Every parameter of [`RrsParams`] changed, and an odd number of base steps (the slow
/// instances' last step is shortened to t_n, and every instance publishes at t_n).
#[test]
fn overridden_parameters_and_a_short_last_step_are_bit_identical() {
    let params = RrsParams {
        waves_seed: 11,
        wave_direction: 2.2,
        significant_wave_height: 4.5,
        wave_period: 9.1,
        wave_roll_gain: 0.05,
        wind_seed: 12,
        sensors_seed: 13,
        roll_mode: RollMode::Forced,
        adaptation_enabled: false,
    };
    let sets = [
        "waves.seed=11",
        "waves.wave_direction=2.2",
        "waves.significant_wave_height=4.5",
        "waves.wave_period=9.1",
        "waves.roll_gain=0.05",
        "wind.seed=12",
        "sensors.seed=13",
        "autopilot.roll_mode=2",
        "autopilot.adaptation_enabled=false",
    ];
    assert_bit_identical(&params, &sets, 100.05);
}

/// `rrs-model-loop --csv` writes the file `shipsim run -o` writes, and its JSON line.
#[test]
fn the_binary_writes_shipsims_csv_byte_for_byte() {
    let d = tempfile::tempdir().unwrap();
    let (ours, theirs) = (d.path().join("loop.csv"), d.path().join("shipsim.csv"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rrs-model-loop"))
        .args(["--stop-time", "1200", "--roll-mode", "0", "--csv"])
        .arg(&ours)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = String::from_utf8(out.stdout).unwrap();
    assert!(
        line.starts_with("{\"stop_time\":1200,\"macro_steps\":24000,\"wall_s\":")
            && line.ends_with("}\n"),
        "{line}"
    );
    let (plan, fmus) = prepare(&shipsim_run(&["autopilot.roll_mode=0"], 1200.0)).unwrap();
    run(
        &plan,
        &fmus,
        Output::File(theirs.clone()),
        &RunOptions::default(),
    )
    .unwrap();
    let (a, b) = (
        std::fs::read(&ours).unwrap(),
        std::fs::read(&theirs).unwrap(),
    );
    assert_eq!(a.len(), b.len(), "file sizes");
    assert!(a == b, "the CSV files differ");
    // The full run records values below 1e-6, written with an exponent by both.
    assert!(a.windows(2).any(|w| w == b"e-"), "no exponent-form field");
}
