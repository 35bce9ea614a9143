//! Units (`shipsim::units`) and values with units wherever a value is written: `--set`, system
//! files and events. Expected values are the textbook definitions (1 kn = 1852/3600 m/s,
//! 1 rpm = 2 pi/60 rad/s, 1 deg = pi/180 rad), computed here independently of the module.

mod common;

use common::{fmu_dir, our_fmu};
use shipsim::model_description::ModelDescription;
use shipsim::system::TypedValue;
use shipsim::units::{Quantity, RadRule, Unit};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::path::Path;
use std::process::Command;

const FMI: RadRule = RadRule::Omittable {
    from: true,
    to: true,
};

/// `x unit_from` in `unit_to`, both built-in.
fn conv(x: f64, from: &str, to: &str) -> f64 {
    let (f, t) = (Unit::parse(from).unwrap(), Unit::parse(to).unwrap());
    f.conversion_to(&t, RadRule::Strict)
        .unwrap_or_else(|| panic!("{from} -> {to} refused"))
        .apply(x)
}

/// |a - b| <= rel * |b|.
fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

#[test]
fn degrees_convert_as_rusts_to_radians() {
    // FMI 2.0: value_SI = factor * value with factor = PI/180 as one double, which is what
    // f64::to_radians computes (x * (PI / 180)): equal bit for bit.
    for d in [
        0.0, 1.0, 7.0, 10.0, 22.0, 30.0, 45.0, 90.0, -90.0, 180.0, 359.5,
    ] {
        assert_eq!(
            conv(d, "deg", "rad").to_bits(),
            f64::to_radians(d).to_bits(),
            "{d} deg"
        );
    }
    assert_eq!(conv(90.0, "deg", "rad"), FRAC_PI_2);
    assert_eq!(conv(180.0, "deg", "rad"), PI);
    // and back: PI rad is 180 deg within one rounding.
    assert!(close(conv(PI, "rad", "deg"), 180.0, 2.3e-16));
}

#[test]
fn speeds_and_rates() {
    // 15 kn = 15 * 1852 / 3600 m/s = 27780/3600 (one correctly rounded division); the module's
    // 15 * (1852/3600) has two roundings: within 1 ulp (relative 2.3e-16).
    assert!(close(conv(15.0, "kn", "m/s"), 27780.0 / 3600.0, 2.3e-16));
    assert!(close(
        conv(15.0, "knot", "m/s"),
        7.716_666_666_666_667,
        2.3e-16
    ));
    // 80 rpm = 80 * 2 pi / 60 rad/s = 8.37758040957278 (pi * 8/3); within 2 ulp.
    assert!(close(conv(80.0, "rpm", "rad/s"), 8.0 * PI / 3.0, 4.5e-16));
    // 10 deg/s = pi/18 rad/s.
    assert!(close(conv(10.0, "deg/s", "rad/s"), PI / 18.0, 2.3e-16));
    // 36 km/h = 10 m/s; 100 km/h = 100000/1852 kn.
    assert!(close(conv(36.0, "km/h", "m/s"), 10.0, 2.3e-16));
    assert!(close(
        conv(100.0, "km/h", "kn"),
        100_000.0 / 1852.0,
        4.5e-16
    ));
    // 1 NM = 1852 m, 1 ft = 0.3048 m, 2 h = 7200 s, 3 t = 3000 kg, 2 kN.m = 2000 N.m.
    assert_eq!(conv(1.0, "NM", "m"), 1852.0);
    assert_eq!(conv(1.0, "nm", "km"), 1.852);
    assert_eq!(conv(1.0, "ft", "m"), 0.3048);
    assert_eq!(conv(2.0, "h", "s"), 7200.0);
    assert_eq!(conv(3.0, "min", "s"), 180.0);
    assert_eq!(conv(3.0, "t", "kg"), 3000.0);
    assert_eq!(conv(2.0, "kN.m", "N.m"), 2000.0);
    assert_eq!(conv(2.0, "kN.m", "Nm"), 2000.0);
    assert_eq!(conv(1.5, "kN", "N"), 1500.0);
    assert_eq!(conv(50.0, "%", "1"), 0.5);
    assert_eq!(conv(4.0, "Hz", "1/s"), 4.0);
    // 20 degC = 293.15 K (offset 273.15), within one rounding.
    assert!(close(conv(20.0, "degC", "K"), 293.15, 2.3e-16));
}

#[test]
fn compounds_exponents_and_refusals() {
    let nm = Unit::parse("N.m").unwrap();
    assert_eq!(nm.exponents, [1, 2, -2, 0, 0, 0, 0, 0]);
    for same in ["kg.m2/s2", "kg*m^2/s^2", "kg.m.m/s/s", "J"] {
        assert_eq!(Unit::parse(same).unwrap().exponents, nm.exponents, "{same}");
    }
    assert_eq!(
        Unit::parse("m/s2").unwrap().exponents,
        [0, 1, -2, 0, 0, 0, 0, 0]
    );
    // Incompatible units do not convert.
    let (kg, rad) = (Unit::parse("kg").unwrap(), Unit::parse("rad").unwrap());
    assert!(kg.conversion_to(&rad, FMI).is_none());
    assert!(Unit::parse("N").unwrap().conversion_to(&nm, FMI).is_none());
    assert!(Unit::parse("kn")
        .unwrap()
        .conversion_to(&Unit::parse("m").unwrap(), FMI)
        .is_none());
    // Unknown names are refused with a suggestion.
    let e = Unit::parse("knts").unwrap_err().to_string();
    assert!(
        e.contains("unknown unit 'knts'") && e.contains("'knots'"),
        "{e}"
    );
    assert!(Unit::parse("m/").is_err() && Unit::parse("").is_err());
}

#[test]
fn rad_may_be_omitted_where_the_rule_says() {
    // PythonFMU's `radian`: BaseUnit with rad = 0 (FMI 2.0 lets rad be omitted).
    let radian0 = Unit {
        exponents: [0; 8],
        factor: 1.0,
        offset: 0.0,
    };
    let deg = Unit::parse("deg").unwrap();
    let omit_to = RadRule::Omittable {
        from: false,
        to: true,
    };
    assert_eq!(
        deg.conversion_to(&radian0, omit_to).unwrap().apply(90.0),
        FRAC_PI_2
    );
    // SSP compares every exponent: refused.
    assert!(deg.conversion_to(&radian0, RadRule::Strict).is_none());
    // rad/s to an FMU's 1/s (rad omitted), but not the built-in Hz (cycles) to rad/s.
    let per_s = Unit::parse("1/s").unwrap();
    let rad_s = Unit::parse("rad/s").unwrap();
    assert!(rad_s.conversion_to(&per_s, omit_to).is_some());
    assert!(Unit::parse("Hz")
        .unwrap()
        .conversion_to(&rad_s, omit_to)
        .is_none());
    // Everything else must still match: rad/s to a rad-less m/s is refused.
    let m_s = Unit::parse("m/s").unwrap();
    assert!(rad_s.conversion_to(&m_s, FMI).is_none());
    // Gain and offset for a connection: km -> m is 1000, 0; degC -> K is 1, 273.15.
    let km_m = Unit::parse("km").unwrap();
    let m = Unit::parse("m").unwrap();
    assert_eq!(
        km_m.conversion_to(&m, FMI).unwrap().gain_offset(),
        (1000.0, 0.0)
    );
    let c = Unit::parse("degC")
        .unwrap()
        .conversion_to(&Unit::parse("K").unwrap(), FMI);
    assert_eq!(c.unwrap().gain_offset(), (1.0, 273.15));
}

#[test]
fn numbers_and_pi_expressions() {
    let q = |s: &str| Quantity::parse(s).unwrap();
    // A plain number is parsed as Rust parses it: the same bits.
    for s in [
        "0.1",
        "1.5707963267948966",
        "-3",
        "2.35e-4",
        "1e300",
        "5e-324",
    ] {
        assert_eq!(
            q(s).value.to_bits(),
            s.parse::<f64>().unwrap().to_bits(),
            "{s}"
        );
        assert_eq!(q(s).unit, None);
    }
    assert_eq!(q("pi/2").value, FRAC_PI_2);
    assert_eq!(q("2*pi").value, TAU);
    assert_eq!(q("-pi").value, -PI);
    assert_eq!(q("π").value, PI);
    assert_eq!(q("pi / 2 rad").value, FRAC_PI_2);
    assert_eq!(q("pi/2 rad").unit.as_deref(), Some("rad"));
    assert_eq!(q("90deg").value, 90.0);
    assert_eq!(q("90deg").unit.as_deref(), Some("deg"));
    assert_eq!(q("15 kn").unit.as_deref(), Some("kn"));
    assert_eq!(q("10 deg/s").unit.as_deref(), Some("deg/s"));
    assert_eq!(q("-1.5e3 kN.m").value, -1500.0);
    assert!(Quantity::parse("deg").is_err() && Quantity::parse("").is_err());
}

/// A model description with the cases FMUs not written here have: a `radian` with rad = 0
/// (PythonFMU), a unit without BaseUnit, a variable without unit, a declared type with a
/// range, and a constant.
const XML: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="M" guid="{units}">
  <CoSimulation modelIdentifier="M"/>
  <UnitDefinitions>
    <Unit name="radian"><BaseUnit/></Unit>
    <Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit>
    <Unit name="rpm"><BaseUnit s="-1" factor="0.016666666666666666"/></Unit>
    <Unit name="deg"/>
    <Unit name="dimensionless"/>
  </UnitDefinitions>
  <TypeDefinitions><SimpleType name="Speed"><Real unit="m/s" min="0" max="20"/></SimpleType></TypeDefinitions>
  <ModelVariables>
    <ScalarVariable name="angle" valueReference="0" causality="parameter" variability="tunable"><Real unit="radian" start="0"/></ScalarVariable>
    <ScalarVariable name="speed" valueReference="1" causality="input"><Real declaredType="Speed" start="0"/></ScalarVariable>
    <ScalarVariable name="shaft" valueReference="2" causality="parameter" variability="fixed"><Real unit="rpm" start="80"/></ScalarVariable>
    <ScalarVariable name="heading_deg" valueReference="3" causality="parameter" variability="fixed"><Real unit="deg" start="0"/></ScalarVariable>
    <ScalarVariable name="gain" valueReference="4" causality="parameter" variability="fixed"><Real start="1"/></ScalarVariable>
    <ScalarVariable name="ratio" valueReference="5" causality="parameter" variability="fixed"><Real unit="dimensionless" start="1"/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>"#;

/// Validates a one-instance TOML system (parameters `params`, plus `extra` text) against XML.
fn validate(params: &str, extra: &str) -> Result<Vec<(String, TypedValue)>, String> {
    let text = format!(
        "[simulation]\nstop_time = 1.0\nstep_size = 0.1\n\n[[instances]]\nname = \"m\"\nfmu = \"M.fmu\"\nparameters = {{ {params} }}\n{extra}"
    );
    let sys = shipsim::format::toml::parse(Path::new("sys.toml"), &text).unwrap();
    let md = ModelDescription::parse(XML).unwrap();
    let plan = sys.validate(&[&md]).map_err(|e| e.to_string())?;
    let mut out: Vec<(String, TypedValue)> = plan.instances[0]
        .start_values
        .iter()
        .map(|s| (s.variable.clone(), s.value.clone()))
        .collect();
    out.extend(
        plan.events
            .iter()
            .map(|e| (e.name.clone(), e.value.clone())),
    );
    Ok(out)
}

fn real(params: &str) -> f64 {
    match validate(params, "").unwrap()[0].1 {
        TypedValue::Real(x) => x,
        ref v => panic!("{v:?}"),
    }
}

#[test]
fn values_convert_to_the_declared_unit_in_validation() {
    // deg onto PythonFMU's rad-less `radian`: the FMI rad rule.
    assert_eq!(real(r#"angle = "90 deg""#), FRAC_PI_2);
    assert_eq!(real(r#"angle = "pi/2""#), FRAC_PI_2);
    // The declared type's unit (m/s): 15 kn.
    assert!(close(real(r#"speed = "15 kn""#), 27780.0 / 3600.0, 2.3e-16));
    // The same name as the declared unit: the number as written, whatever the FMU's rpm is.
    assert_eq!(real(r#"shaft = "80 rpm""#), 80.0);
    // An FMU unit without BaseUnit that is a built-in name (deg): converted by the table.
    assert!(close(
        real(r#"heading_deg = "0.5 rad""#),
        90.0 / PI,
        2.3e-16
    ));
    // Plain numbers keep their bits.
    assert_eq!(real("gain = 0.1").to_bits(), 0.1f64.to_bits());
    assert_eq!(real(r#"gain = "0.1""#).to_bits(), 0.1f64.to_bits());
    // Events convert too.
    let ev = "[[events]]\ntime = 0.5\nset = \"m.angle\"\nvalue = \"-45 deg\"\n";
    let v = validate("", ev).unwrap();
    assert_eq!(
        v[0],
        ("m.angle".into(), TypedValue::Real(-f64::to_radians(45.0)))
    );
}

#[test]
fn wrong_units_are_errors_naming_line_instance_variable_value_and_units() {
    let e = validate(r#"speed = "15 kg""#, "").unwrap_err();
    for part in [
        "sys.toml:8",
        "instance 'm'",
        "'speed'",
        "15 kg",
        "'kg'",
        "'m/s'",
    ] {
        assert!(e.contains(part), "{part} not in: {e}");
    }
    let e = validate(r#"gain = "2 m""#, "").unwrap_err();
    assert!(
        e.contains("'gain'") && e.contains("declares no unit"),
        "{e}"
    );
    let e = validate(r#"ratio = "2 m""#, "").unwrap_err();
    assert!(e.contains("'dimensionless' without a BaseUnit"), "{e}");
    // The built-in Hz is not an angular velocity, even onto a rad-less FMU unit... it is a
    // rate: onto `radian` (no s) it is refused for the seconds.
    let e = validate(r#"angle = "1 Hz""#, "").unwrap_err();
    assert!(
        e.contains("'Hz' (s-1)") && e.contains("'radian' (1)"),
        "{e}"
    );
    let ev = "[[events]]\ntime = 0.5\nset = \"m.speed\"\nvalue = \"10 deg\"\n";
    let e = validate("", ev).unwrap_err();
    assert!(
        e.contains("sys.toml:9") && e.contains("event at t = 0.5"),
        "{e}"
    );
    assert!(e.contains("'deg' (rad)") && e.contains("'m/s'"), "{e}");
    // The FMU's rpm omits rad (s-1, factor 1/60) where the table's rpm is 2 pi/60 rad/s:
    // rad/s onto it would be off by 2 pi, so it is refused; Hz (s-1) converts exactly.
    let e = validate(r#"shaft = "8 rad/s""#, "").unwrap_err();
    assert!(
        e.contains("ambiguous") && e.contains("write the value in rpm"),
        "{e}"
    );
    assert!(close(real(r#"shaft = "2 Hz""#), 120.0, 2.3e-16));
    // The declared type's range applies to converted values: 50 kn = 25.7 m/s > 20.
    let e = validate(r#"speed = "50 kn""#, "").unwrap_err();
    assert!(e.contains("outside the declared range [0, 20]"), "{e}");
}

/// rrs.toml with its FMUs taken from $SHIPSIM_FMU_DIR, written into `dir`.
fn rrs_system(dir: &Path) -> std::path::PathBuf {
    our_fmu("RrsShip");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("systems/rrs.toml")).unwrap();
    let fmus = format!("{}/", fmu_dir().display());
    let p = dir.join("rrs.toml");
    std::fs::write(&p, text.replace("../target/fmu/", &fmus)).unwrap();
    p
}

fn run(system: &Path, csv: &Path, sets: &[&str]) -> std::process::Output {
    let csv = csv.to_str().unwrap();
    let mut args = vec!["-q", "-o", csv];
    for s in sets {
        args.extend(["--set", s]);
    }
    shipsim("run", system, &args)
}

#[test]
fn set_with_degrees_gives_the_same_csv_as_the_radians() {
    let dir = tempfile::tempdir().unwrap();
    let sys = rrs_system(dir.path());
    let csvs: Vec<_> = [
        "waves.wave_direction=1.5707963267948966",
        "waves.wave_direction=90deg",
        "waves.wave_direction=90 deg",
        "waves.wave_direction=pi/2",
        "waves.wave_direction=pi/2 rad",
    ]
    .iter()
    .enumerate()
    .map(|(i, set)| {
        let csv = dir.path().join(format!("{i}.csv"));
        let out = run(&sys, &csv, &[set]);
        assert!(
            out.status.success(),
            "{set}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::read(csv).unwrap()
    })
    .collect();
    assert!(csvs[0].len() > 1_000_000, "the full 1200 s run");
    for (i, c) in csvs.iter().enumerate().skip(1) {
        assert!(c == &csvs[0], "CSV {i} differs from the radians");
    }
    // And a different direction gives a different CSV (the comparison can fail).
    let csv = dir.path().join("other.csv");
    assert!(run(&sys, &csv, &["waves.wave_direction=60 deg"])
        .status
        .success());
    assert!(std::fs::read(csv).unwrap() != csvs[0]);
}

/// A system of Waves and a SteeringGear with `speed`, `direction`, `rate` and the event value
/// spliced in.
fn small_system(
    dir: &Path,
    name: &str,
    speed: &str,
    direction: &str,
    rate: &str,
    event: &str,
) -> std::path::PathBuf {
    let f = fmu_dir();
    let text = format!(
        r#"[simulation]
stop_time = 20.0
step_size = 0.1

[[instances]]
name = "waves"
fmu = "{waves}"
parameters = {{ seed = 1, spectrum = 1, significant_wave_height = 3.0, wave_period = 7.7, wave_direction = {direction}, roll_gain = 0.03, yaw_gain = 0.002, ship_speed = {speed}, heading = 0.0 }}

[[instances]]
name = "gear"
fmu = "{gear}"
parameters = {{ rate_max = {rate}, rudder_command = 0.0 }}

[[events]]
time = 2.0
set = "gear.rudder_command"
value = {event}

[output]
file = "{name}.csv"
variables = ["waves.roll_moment", "waves.yaw_moment", "gear.rudder_angle"]
"#,
        waves = f.join("Waves.fmu").display(),
        gear = f.join("SteeringGear.fmu").display(),
    );
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_system_file_with_knots_and_an_event_in_degrees_runs() {
    our_fmu("Waves");
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let with_units = small_system(
        d,
        "units",
        r#""15 kn""#,
        r#""90 deg""#,
        r#""10 deg/s""#,
        r#""10 deg""#,
    );
    // The same in SI, the numbers computed here: 15*1852/3600, pi/2, pi/18.
    let si = small_system(
        d,
        "si",
        &format!("{:?}", 27780.0 / 3600.0),
        &format!("{FRAC_PI_2:?}"),
        &format!("{:?}", 10.0 * (PI / 180.0)),
        &format!("{:?}", 10.0 * (PI / 180.0)),
    );
    for s in [&with_units, &si] {
        let out = shipsim("run", s, &["-q"]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let (a, b) = (
        std::fs::read(d.join("units.csv")).unwrap(),
        std::fs::read(d.join("si.csv")).unwrap(),
    );
    assert!(a == b, "the CSVs differ");
    // The event moved the rudder: the last rudder angle is 10 deg (reached at 10 deg/s).
    let (h, rows) = common::read_csv(&d.join("units.csv"));
    let last = rows.last().unwrap()[common::col(&h, "gear.rudder_angle")];
    assert!(close(last, 10.0 * PI / 180.0, 1e-6), "{last}");

    // A wrong unit fails with file:line, instance, variable, value and both units.
    let bad = small_system(d, "bad", r#""15 kg""#, "0.0", "0.1", "0.0");
    let at = format!("{}:8:", bad.display());
    let parts = ["instance 'waves'", "'ship_speed'", "15 kg", "'kg'", "'m/s'"];
    refused(
        &shipsim("check", &bad, &[]),
        &[&[at.as_str()], &parts[..]].concat(),
    );
    let bad_event = small_system(d, "bad_event", "1.0", "0.0", "0.1", r#""10 m/s""#);
    let at = format!("{}:15:", bad_event.display());
    let parts = ["'gear.rudder_command'", "10 m/s", "'m/s'", "'rad'"];
    refused(
        &shipsim("run", &bad_event, &[]),
        &[&[at.as_str()], &parts[..]].concat(),
    );
    assert!(!d.join("bad_event.csv").exists());
}

/// `shipsim COMMAND SYSTEM ARGS...`.
fn shipsim(command: &str, system: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .arg(command)
        .arg(system)
        .args(args)
        .output()
        .unwrap()
}

/// The command failed with a message containing every part.
fn refused(out: &std::process::Output, parts: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "passed: {err}");
    for part in parts {
        assert!(err.contains(part), "{part} not in: {err}");
    }
}

/// A bare number above a full turn on a variable in radians is said to be taken in radians
/// (issue 36, item 11: `--set waves.wave_direction=90` silently meant 90 rad); with a unit, or
/// within a turn, nothing is said.
#[test]
fn a_bare_angle_above_a_turn_is_said_to_be_radians() {
    let d = tempfile::tempdir().unwrap();
    let sys = common::rrs_file(d.path());
    let check = |set: &str| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
            .args(["check", sys.to_str().unwrap(), "--set", set])
            .output()
            .unwrap();
        assert!(out.status.success(), "{out:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let err = check("waves.wave_direction=90");
    assert!(
        err.contains("warning: ")
            && err.contains("--set waves.wave_direction=90: 90 has no unit and is taken in the variable's, rad (90 rad = 5157 deg); for degrees write \"90 deg\" (instance 'waves', variable 'wave_direction')"),
        "{err}"
    );
    for quiet in [
        "waves.wave_direction=90deg",
        "waves.wave_direction=3",
        "waves.wave_direction=-6.2",
    ] {
        assert!(!check(quiet).contains("has no unit"), "{quiet}");
    }
}
