"""The fixture FMUs of tests/fixtures/fmus (small C FMUs of our own, built with gcc here) against
FMPy and libcosim, and the interop defects of issue 18 on them.

What the fixtures stand for (the third-party FMUs the issue was found with):
* BouncingBall: state events handled inside fmi2DoStep.
* Feedthrough: every variable type, Enumeration (with a declared type) and String included.
* Terminator: an early end by fmi2Discard with fmi2Terminated (fmi2GetBooleanStatus).
* ResourceReader: a file under resources/ read at instantiation through fmuResourceLocation.
* SharedGuidA, SharedGuidB: two different models with one GUID.
* RadianSource, RadSink: an angle in `radian` declared with rad = 0 (PythonFMU's declaration)
  and in `rad` with rad = 1 (ours), `dimensionless` against `kg.m2/s2`, and an Integer declared
  continuous (which FMI 2.0 forbids).

shipsim against FMPy, each fixture alone: `shipsim run` of a one-instance system and
`fmpy.simulate_fmu` with output_interval = step size (FMPy then calls fmi2DoStep once per
output interval), every recorded output compared bit for bit (tolerance 0). The step size is
1/16 s: a dyadic step makes the time grids identical bit for bit. FMPy passes t_k = t0 + k*h and
shipsim libcosim's nanosecond grid (t0_ns + k*h_ns)/1e9 (master/src/run/time_grid.rs); with
h = 0.01 these differ in the last bit at some k (3*0.01 = 0.030000000000000002 but 30000000/1e9
= 0.03), which models that use t would carry into their outputs; with h = 1/16 both are exact.

shipsim against libcosim, coupled with our own FMUs: systems exported with `shipsim export-osp`
and run by libcosim (libcosim_runner.py), compared bit for bit as in test_systems_libcosim.py.

Environment: SHIPSIM_BIN (the master), SHIPSIM_FMU_DIR (our built FMUs).
"""
import csv
import json
import pathlib
import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

import fixtures
from test_master_interop import libcosim_rows, our_fmu, read_csv, shipsim

H = 0.0625


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """Every fixture built once: {name: path of the .fmu}."""
    return fixtures.build_all(tmp_path_factory.mktemp("fixture_fmus"))


def copy_fmus(built, names, dest):
    """Copies the named fixtures, and our FMUs (from SHIPSIM_FMU_DIR) for other names, into dest."""
    for n in names:
        shutil.copy(built[n] if n in built else our_fmu(n), dest / f"{n}.fmu")


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string: JSON's escapes are TOML's
    return repr(v)


def one_instance_toml(name, stop, params):
    values = ", ".join(f"{k} = {toml_value(v)}" for k, v in params.items())
    return textwrap.dedent(f"""
        [simulation]
        stop_time = {stop!r}
        step_size = {H!r}
        [[instances]]
        name = "m"
        fmu = "{name}.fmu"
        parameters = {{ {values} }}
    """)


def test_fixtures_pass_fmpy_validation_but_the_invalid_one(built):
    """FMPy's validation (schema, causality/variability/initial, units, ModelStructure) finds
    nothing in the fixtures, except the one variability error RadianSource has on purpose."""
    assert fixtures.names() == ["BouncingBall", "Feedthrough", "RadSink", "RadianSource", "ResourceReader",
                                "SharedGuidA", "SharedGuidB", "Terminator"]
    for name, fmu in built.items():
        problems = validate_fmu(str(fmu))
        if name == "RadianSource":
            assert len(problems) == 1 and '"count"' in problems[0] and "continuous" in problems[0], problems
        else:
            assert problems == [], f"{name}: {problems}"


# (fixture, stop time, start values): start values of every type that the fixture has.
CASES = [
    ("BouncingBall", 3.0, {}),
    ("BouncingBall", 2.0, {"e": 0.8, "h0": 2.0, "g": 3.71}),
    ("Feedthrough", 2.0, {"real_tunable_parameter": 0.5, "real_continuous_input": 1.5, "real_discrete_input": -2.25,
                          "integer_input": 3, "enumeration_input": 2, "boolean_input": True,
                          "string_parameter": "hello, world"}),
    ("Terminator", 1.0, {"rate": 3.0}),
    ("ResourceReader", 1.0, {}),
    ("SharedGuidA", 1.0, {"k": -0.75}),
    ("SharedGuidB", 1.0, {}),
    ("RadianSource", 2.0, {"omega": 3.0, "amplitude": 0.2}),
    ("RadSink", 1.0, {"angle_in": 0.25, "energy_in": 2.0}),
]


@pytest.mark.parametrize("name,stop,params", CASES, ids=[f"{c[0]}-{i}" for i, c in enumerate(CASES)])
def test_each_fixture_alone_equals_fmpy_bit_for_bit(built, tmp_path, name, stop, params):
    copy_fmus(built, [name], tmp_path)
    (tmp_path / "one.toml").write_text(one_instance_toml(name, stop, params))
    shipsim("run", tmp_path / "one.toml", "-o", tmp_path / "one.csv")
    header, rows = read_csv(tmp_path / "one.csv")
    ours = np.array(rows)
    outputs = [h.split(".", 1)[1] for h in header[1:]]
    # FMPy's validation refuses RadianSource (Integer declared continuous), which it would run.
    theirs = simulate_fmu(str(tmp_path / f"{name}.fmu"), start_time=0.0, stop_time=stop, step_size=H,
                          output_interval=H, start_values=params, output=outputs,
                          validate=name != "RadianSource")
    assert len(theirs) == len(ours), f"{name}: FMPy {len(theirs)} rows, shipsim {len(ours)}"
    times = theirs["time"].astype(np.float64)
    if name == "Terminator":
        # The early end, a documented difference of stamp: both record the values of the last
        # successful time, t = 0.5 s, last. FMPy stamps that row with the last successful time,
        # repeating the time of the row before it; shipsim stamps it with the end of the refused
        # macro step, t_(k+1) = 0.5625 s, where the master stopped (the other instances of a
        # system have reached it; the time column stays strictly increasing; the summary names
        # both times). Both stamps are asserted; the values are compared below.
        assert times[-2:].tolist() == [0.5, 0.5] and len(ours) == 10
        assert ours[-1, 0] == 0.5 + H and ours[-2, 0] == 0.5
        times = np.append(times[:-1], 0.5 + H)
    ours_t = ours[:, 0]
    assert times.tobytes() == ours_t.tobytes(), f"{name}: time grids differ"
    for j, out in enumerate(outputs, start=1):
        a = ours[:, j]
        b = theirs[out].astype(np.float64)
        diff = np.flatnonzero(a.view(np.uint64) != b.view(np.uint64))
        assert diff.size == 0, f"{name}.{out}: first difference at row {diff[0]}: shipsim {a[diff[0]]!r}, FMPy {b[diff[0]]!r}"
    # Not trivially constant: some output of every fixture changes over the run.
    assert any(len(set(ours[:, j])) > 1 for j in range(1, ours.shape[1])), f"{name}: no output changes"


def test_bouncing_ball_events_are_located_inside_the_step(built, tmp_path):
    """The impacts happen between communication points and are handled there: from h0 = 1 m with
    g = 9.81 m/s2 the first impact is at t = sqrt(2/g) = 0.4515 s and the next apex is e^2 h0 =
    0.49 m high; the sampled heights reach it to within g/2 (1/32 s)^2 = 4.8 mm (the grid's
    distance to the apex time) and never pass it (tolerance 1e-12 m)."""
    copy_fmus(built, ["BouncingBall"], tmp_path)
    (tmp_path / "ball.toml").write_text(one_instance_toml("BouncingBall", 3.0, {}))
    shipsim("run", tmp_path / "ball.toml", "-o", tmp_path / "ball.csv")
    header, rows = read_csv(tmp_path / "ball.csv")
    t, h, bounces = (np.array([r[header.index(c)] for r in rows]) for c in ("time", "m.h", "m.bounces"))
    assert h.min() >= 0.0
    first = np.flatnonzero(bounces > 0)[0]
    assert t[first - 1] < np.sqrt(2 / 9.81) <= t[first]
    second = np.flatnonzero(bounces > 1)[0]
    apex = h[first:second].max()
    assert 0.49 - 9.81 / 2 * (1 / 32) ** 2 <= apex <= 0.49 + 1e-12, apex
    assert bounces[-1] >= 4


def test_a_named_string_variable_is_recorded_quoted(built, tmp_path):
    """A String variable named in the outputs is a CSV column (issue 18): Feedthrough's
    string_parameter, set to text with a comma, a quote and non-ASCII, is in every row, quoted as
    RFC 4180 says, and reads back exactly with Python's csv module; `m.*` still records numbers
    only (so existing CSVs keep their columns). In memory (Python) it is refused by name."""
    copy_fmus(built, ["Feedthrough"], tmp_path)
    text = 'héllo, "world"'
    toml = one_instance_toml("Feedthrough", 0.25, {"string_parameter": text}) + textwrap.dedent("""
        [output]
        variables = ["m.string_parameter", "m.*"]
    """)
    (tmp_path / "s.toml").write_text(toml)
    shipsim("run", tmp_path / "s.toml", "-o", tmp_path / "s.csv")
    raw = (tmp_path / "s.csv").read_text(encoding="utf-8").splitlines()
    assert raw[1].split(",", 1)[1].startswith('"héllo, ""world""",'), raw[1]
    with open(tmp_path / "s.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    assert header[:2] == ["time", "m.string_parameter"] and "m.integer_output" in header
    assert header.count("m.string_parameter") == 1  # not again from m.*
    assert len(rows) == 1 + 5  # t = 0, 0.0625, ..., 0.25
    assert all(r[1] == text and len(r) == len(header) for r in rows[1:])
    import shipsim as sp
    system = sp.System.load(tmp_path / "s.toml")
    with pytest.raises(sp.ShipsimError, match="'m.string_parameter' is a String variable"):
        system.run(0.25, variables=["m.string_parameter"])


def test_resource_file_is_read_at_instantiation(built, tmp_path):
    """ResourceReader's gain and offset come only from resources/parameters.txt (2.5, 0.25; the
    model description has no start values for them); y = offset + gain*t."""
    copy_fmus(built, ["ResourceReader"], tmp_path)
    (tmp_path / "res.toml").write_text(one_instance_toml("ResourceReader", 1.0, {}))
    shipsim("run", tmp_path / "res.toml", "-o", tmp_path / "res.csv")
    header, rows = read_csv(tmp_path / "res.csv")
    assert header == ["time", "m.gain", "m.offset", "m.y"]
    for t, gain, offset, y in rows:
        assert (gain, offset) == (2.5, 0.25)
        assert y == 0.25 + 2.5 * t


# ---------------------------------------------------------------------------------------------
# Interop defects of issue 18

def test_export_osp_with_enumeration_value_runs_in_libcosim(built, tmp_path):
    """libcosim ignores Enumeration variables (its FMU import drops them), so an initial value
    for one made the whole exported file fail: "No such variable: m:enumeration_input". The
    export leaves it out with a warning; libcosim runs the file, with results equal to shipsim's
    run of the same file (bit for bit; the Real outputs, which libcosim_runner reads)."""
    copy_fmus(built, ["Feedthrough", "SteeringGear"], tmp_path)
    (tmp_path / "ft.toml").write_text(textwrap.dedent("""
        connections = ["ft.real_continuous_output -> gear.rudder_command", "gear.rudder_angle -> ft.real_discrete_input"]
        [simulation]
        stop_time = 2.0
        step_size = 0.01
        [[instances]]
        name = "ft"
        fmu = "Feedthrough.fmu"
        parameters = { enumeration_input = 3, integer_input = 4, boolean_input = true, real_tunable_parameter = 0.1, string_parameter = "osp" }
        [[instances]]
        name = "gear"
        fmu = "SteeringGear.fmu"
    """))
    osp = tmp_path / "OspSystemStructure.xml"
    r = shipsim("export-osp", tmp_path / "ft.toml", "-o", osp)
    assert "libcosim ignores Enumeration variables" in r.stderr and "ft.enumeration_input" in r.stderr, r.stderr
    text = osp.read_text()
    assert "enumeration_input" not in text
    assert '<InitialValue variable="integer_input"><Integer value="4"/></InitialValue>' in text
    assert '<InitialValue variable="string_parameter"><String value="osp"/></InitialValue>' in text
    out = tmp_path / "osp.csv"
    shipsim("run", osp, "-o", out)
    real_cols = ["ft.real_continuous_output", "ft.real_discrete_output", "gear.rudder_angle", "gear.rudder_rate"]
    only = keep_columns(out, ["time", *real_cols], tmp_path / "osp_real.csv")
    header, rows = read_csv(only)
    assert abs(rows[-1][header.index("gear.rudder_angle")]) > 0.1
    assert_same_as_libcosim(osp, only)


def assert_same_as_libcosim(osp_file, our_csv):
    """test_master_interop.assert_same_as_libcosim (tolerance 0: every recorded value at every
    step bit-identical), for systems with RadianSource: libcosim's FMI Library prints its verdict
    on that FMU's Integer declared continuous to stdout, before the runner's JSON. That line is
    checked and set aside."""
    header, ours = read_csv(our_csv)
    runner = pathlib.Path(__file__).with_name("libcosim_runner.py")
    r = subprocess.run([sys.executable, str(runner), str(osp_file), str(len(ours) - 1), *header[1:]],
                       capture_output=True, text=True)
    assert r.returncode == 0, f"libcosim run of {osp_file} failed ({r.returncode}):\n{r.stderr}"
    *logged, result = r.stdout.splitlines()
    for line in logged:
        assert "[FMI Library: FMI2XML] Only Real variables can have variability='continuous'" in line, line
    theirs = json.loads(result)
    assert len(theirs) == len(ours) - 1
    for k, (a, b) in enumerate(zip(ours[1:], theirs), start=1):
        for name, x, y in zip(header[1:], a[1:], b):
            assert x.hex() == y.hex(), f"row {k} (t = {a[0]}), {name}: shipsim {x!r} vs libcosim {y!r}"


def keep_columns(csv_path, columns, dest):
    with open(csv_path) as f:
        rows = list(csv.reader(f))
    idx = [rows[0].index(c) for c in columns]
    with open(dest, "w", newline="") as f:
        csv.writer(f).writerows([[r[i] for i in idx] for r in rows])
    return dest




def test_units_of_a_third_party_osp_file_warn_and_strict_units_errs(built, tmp_path):
    """An OSP file that libcosim runs ("dimensionless" into "kg.m2/s2", "radian" with rad = 0
    into "rad" with rad = 1) runs here too, with warnings, and gives libcosim's results bit for
    bit; --strict-units makes the dimension mismatch an error. The rad-only difference stays a
    warning even then (an angle declared with and without the rad exponent)."""
    copy_fmus(built, ["RadianSource", "RadSink"], tmp_path)
    osp = tmp_path / "OspSystemStructure.xml"
    shutil.copy(fixtures.FIXTURES / "systems" / "units_OspSystemStructure.xml", osp)
    r = shipsim("check", osp)
    assert "OK (2 instances, 2 connections" in r.stdout
    warnings = [w for w in r.stderr.splitlines() if "incompatible units" in w]
    assert len(warnings) == 2, r.stderr
    assert any("radian" in w and "only in the rad exponent" in w for w in warnings), warnings
    assert any("dimensionless" in w and "kg.m2/s2" in w and "--strict-units" in w for w in warnings), warnings
    r = shipsim("check", osp, "--strict-units", check=False)
    assert r.returncode == 1, r.stderr
    # One error, the dimension mismatch (the angle's rad-only difference is no error).
    errors = [line for line in r.stderr.splitlines() if "incompatible units" in line]
    assert len(errors) == 1 and errors[0].startswith("error: "), r.stderr
    assert "'src.work' is in dimensionless but 'sink.energy_in' is in kg.m2/s2" in errors[0]
    r = shipsim("run", osp, "--strict-units", "-o", tmp_path / "strict.csv", check=False)
    assert r.returncode == 1 and not (tmp_path / "strict.csv").exists()
    out = tmp_path / "units.csv"
    shipsim("run", osp, "-o", out)
    only = keep_columns(out, ["time", "src.angle", "src.work", "sink.angle_out", "sink.energy_out",
                              "sink.angle_integral"], tmp_path / "units_real.csv")
    header, rows = read_csv(only)
    assert rows[-1][header.index("sink.energy_out")] > 0.0
    assert_same_as_libcosim(osp, only)


def test_units_in_our_own_toml_stay_an_error(built, tmp_path):
    """In the native TOML, where `convert = true` exists, a dimension mismatch is an error that
    suggests it; with convert = true the system is accepted."""
    copy_fmus(built, ["RadianSource", "RadSink"], tmp_path)
    system = (fixtures.FIXTURES / "systems" / "units.toml").read_text()
    (tmp_path / "units.toml").write_text(system)
    r = shipsim("check", tmp_path / "units.toml", check=False)
    assert r.returncode == 1
    assert "incompatible units: 'src.work' is in dimensionless but 'sink.energy_in' is in kg.m2/s2" in r.stderr
    assert "set convert = true" in r.stderr
    converted = '{ from = "src.work", to = "sink.energy_in", convert = true }'
    (tmp_path / "units.toml").write_text(system.replace('"src.work -> sink.energy_in"', converted))
    r = shipsim("check", tmp_path / "units.toml")
    assert "only in the rad exponent" in r.stderr and "OK (2 instances, 2 connections" in r.stdout


def test_shared_guid_warns_in_check_and_export(built, tmp_path):
    """Two different FMU files with one GUID: check and export-osp warn (libcosim would run one
    model for both); the same FMU twice, or two copies of it, do not."""
    copy_fmus(built, ["SharedGuidA", "SharedGuidB"], tmp_path)
    shutil.copy(built["SharedGuidA"], tmp_path / "SharedGuidA_copy.fmu")

    def system(a, b):
        return textwrap.dedent(f"""
            [simulation]
            stop_time = 1.0
            step_size = 0.0625
            [[instances]]
            name = "a"
            fmu = "{a}"
            [[instances]]
            name = "b"
            fmu = "{b}"
        """)

    (tmp_path / "two.toml").write_text(system("SharedGuidA.fmu", "SharedGuidB.fmu"))
    for args in (["check", tmp_path / "two.toml"],
                 ["export-osp", tmp_path / "two.toml", "-o", tmp_path / "osp" / "OspSystemStructure.xml"]):
        r = shipsim(*args)
        lines = [w for w in r.stderr.splitlines() if "share the GUID" in w]
        assert len(lines) == 1, r.stderr
        assert "SharedGuidA" in lines[0] and "SharedGuidB" in lines[0] and "{shipsim-fixture-shared-guid}" in lines[0]
    for a, b in [("SharedGuidA.fmu", "SharedGuidA.fmu"), ("SharedGuidA.fmu", "SharedGuidA_copy.fmu")]:
        (tmp_path / "same.toml").write_text(system(a, b))
        r = shipsim("check", tmp_path / "same.toml")
        assert "GUID" not in r.stderr, r.stderr


def test_why_shared_guids_warn_libcosim_runs_one_model_for_both(built, tmp_path):
    """The reason for the warning, reproduced with the libcosim of the test environment: in the
    exported file of SharedGuidA and SharedGuidB, libcosim gives instance b the results of
    SharedGuidA (y = t) instead of its own (y = -t^2), which shipsim gives."""
    copy_fmus(built, ["SharedGuidA", "SharedGuidB"], tmp_path)
    (tmp_path / "two.toml").write_text(one_instance_toml("SharedGuidA", 1.0, {}) + textwrap.dedent("""
        [[instances]]
        name = "b"
        fmu = "SharedGuidB.fmu"
        [output]
        variables = ["m.y", "b.y"]
    """))
    shipsim("run", tmp_path / "two.toml", "-o", tmp_path / "two.csv")
    shipsim("export-osp", tmp_path / "two.toml", "-o", tmp_path / "OspSystemStructure.xml")
    header, rows = read_csv(tmp_path / "two.csv")
    assert header == ["time", "m.y", "b.y"]
    for t, a, b in rows:
        assert (a, b) == (t, -t * t)
    theirs = libcosim_rows(tmp_path / "OspSystemStructure.xml", header, len(rows) - 1)
    assert [b for _, b in theirs] == [t for t, _, _ in rows[1:]]


def test_integer_declared_continuous_warns_and_runs(built, tmp_path):
    copy_fmus(built, ["RadianSource"], tmp_path)
    (tmp_path / "src.toml").write_text(one_instance_toml("RadianSource", 1.0, {}))
    r = shipsim("check", tmp_path / "src.toml")
    lines = [w for w in r.stderr.splitlines() if "continuous" in w]
    assert len(lines) == 1 and "'count' (Integer)" in lines[0] and "sec. 2.2.7" in lines[0], r.stderr
    r = shipsim("run", tmp_path / "src.toml", "-o", tmp_path / "src.csv")
    assert "'count' (Integer)" in r.stderr
    header, rows = read_csv(tmp_path / "src.csv")
    assert [r[header.index("m.count")] for r in rows] == list(range(17))


def test_fixtures_coupled_with_our_steering_gear_equal_libcosim(built, tmp_path):
    """A fixture chain through one of our FMUs: RadianSource's angle (radian, rad = 0) commands
    a SteeringGear (rad), whose rudder angle drives RadSink; BouncingBall's height is recorded
    beside them. shipsim's run of the TOML equals libcosim's run of the exported file bit for
    bit (the unit warnings do not change the numbers)."""
    copy_fmus(built, ["RadianSource", "RadSink", "BouncingBall", "SteeringGear"], tmp_path)
    (tmp_path / "chain.toml").write_text(textwrap.dedent("""
        connections = ["src.angle -> gear.rudder_command", "gear.rudder_angle -> sink.angle_in"]
        [simulation]
        stop_time = 4.0
        step_size = 0.01
        [[instances]]
        name = "src"
        fmu = "RadianSource.fmu"
        parameters = { amplitude = 0.3, omega = 1.5 }
        [[instances]]
        name = "gear"
        fmu = "SteeringGear.fmu"
        [[instances]]
        name = "sink"
        fmu = "RadSink.fmu"
        [[instances]]
        name = "ball"
        fmu = "BouncingBall.fmu"
        step_multiple = 2
        [output]
        variables = ["src.angle", "gear.rudder_angle", "sink.angle_out", "sink.angle_integral", "ball.h", "ball.v"]
    """))
    out = tmp_path / "chain.csv"
    r = shipsim("run", tmp_path / "chain.toml", "-o", out)
    assert "only in the rad exponent" in r.stderr
    shipsim("export-osp", tmp_path / "chain.toml", "-o", tmp_path / "OspSystemStructure.xml")
    header, rows = read_csv(out)
    # The gear follows the sine within its rate limit: not trivially zero.
    assert max(abs(r[header.index("gear.rudder_angle")]) for r in rows) > 0.1
    assert_same_as_libcosim(tmp_path / "OspSystemStructure.xml", out)
