"""The `shipsim` Python package (python/), installed into the venv by `cargo xtask test`.

- System.run equals `shipsim run` bit for bit (arrays at full precision: the CLI's CSV is
  parsed, and Rust writes the shortest text that reads back to the same double);
- a second Python thread progresses while a run holds no GIL;
- SIGINT stops a run in a subprocess cleanly (KeyboardInterrupt, temp folders removed);
- errors are the documented exception types, with the CLI's message;
- inspect reads units, causality and start values from the model description.
Campaigns (local and Dask) are in test_python_campaign.py."""
import csv
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
import zipfile
import xml.etree.ElementTree as ET

import numpy as np
import pandas as pd
import pytest

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
RRS = ROOT / "systems" / "rrs.toml"


def cli_columns(system, *args):
    """`shipsim run` into a CSV; the columns as float64 arrays (exact: shortest round-trip text)."""
    with tempfile.TemporaryDirectory() as d:
        out = pathlib.Path(d) / "out.csv"
        subprocess.run([BIN, "run", str(system), "-q", "-o", str(out), *args], check=True)
        with open(out, newline="") as f:
            rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    data = np.array([[float(x) for x in r] for r in body])
    return {h: data[:, j] for j, h in enumerate(header)}


@pytest.mark.parametrize(
    "system, sets, stop",
    [
        (RRS, {"waves.seed": 3, "waves.significant_wave_height": 3.7, "autopilot.roll_mode": 0}, 300.0),
        (ROOT / "systems" / "dp_observer.toml", {}, 120.0),
    ],
)
def test_run_equals_cli_bit_for_bit(system, sets, stop):
    s = shipsim.System.load(system)
    for k, v in sets.items():
        s.set(k, v)
    df = s.run(stop_time=stop)
    args = ["--stop-time", repr(stop)]
    for k, v in sets.items():
        args += ["--set", f"{k}={v!r}"]
    ref = cli_columns(system, *args)
    assert list(ref) == ["time", *df.columns]
    assert len(df) == len(ref["time"]) > 100
    assert np.array_equal(df.index.to_numpy(), ref["time"])
    for c in df.columns:
        got = df[c].to_numpy(dtype=np.float64)
        # bit for bit: the same doubles, NaN nowhere
        assert np.array_equal(got.view(np.uint64), ref[c].view(np.uint64)), c


def test_result_frame_units_and_selection():
    s = shipsim.System.load(RRS)
    df = s.run(stop_time=10, variables=["ship.roll", "gear.*"])
    assert df.index.name == "time"
    assert df.index[0] == 0.0 and df.index[-1] == 10.0 and len(df) == 201
    assert df.columns[0] == "ship.roll"
    assert "gear.rudder_angle" in df.columns and "gear.rudder_rate" in df.columns
    assert not any(c.startswith(("ship.", "waves.")) for c in df.columns[1:])
    assert df.attrs["units"]["ship.roll"] == "rad"
    assert df.attrs["units"]["gear.rudder_rate"] == "rad/s"
    assert df.attrs["summary"]["macro_steps"] == 200
    assert df["gear.command_saturated"].dtype == np.bool_
    # without pandas: a dict of numpy arrays with the same values
    cols = s.run(stop_time=10, variables=["ship.roll", "gear.*"], as_frame=False)
    assert isinstance(cols, dict) and set(cols) == {"time", *df.columns}
    assert np.array_equal(cols["ship.roll"], df["ship.roll"].to_numpy())
    assert cols.units["ship.roll"] == "rad"


def test_runs_are_independent_and_set_persists():
    s = shipsim.System.load(RRS)
    a = s.run(stop_time=60, variables=["ship.roll"])
    s.set("waves.seed", 99)
    b = s.run(stop_time=60, variables=["ship.roll"])
    c = s.run(stop_time=60, variables=["ship.roll"])
    assert not np.array_equal(a["ship.roll"], b["ship.roll"])
    assert np.array_equal(b["ship.roll"], c["ship.roll"])
    assert s.values["waves.seed"] == "99"


def test_gil_is_released_during_a_run():
    s = shipsim.System.load(RRS)
    ticks = []
    running = threading.Event()
    stop = threading.Event()

    def count():
        while not stop.is_set():
            if running.is_set():
                ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    running.set()
    begin = time.perf_counter()
    df = s.run(stop_time=12000, variables=["ship.roll"])
    end = time.perf_counter()
    stop.set()
    t.join()
    assert len(df) == 240001
    during = [x for x in ticks if begin < x < end]
    # The run takes hundreds of ms; a thread that never got the GIL would tick 0 times.
    assert end - begin > 0.1
    assert len(during) > 20, (len(during), end - begin)


def test_sigint_stops_a_run_cleanly(tmp_path):
    script = textwrap.dedent(
        f"""
        import os, sys, time
        import shipsim
        s = shipsim.System.load({str(RRS)!r})
        print("loaded", flush=True)
        begin = time.perf_counter()
        try:
            s.run(stop_time=1e7, variables=["ship.roll"])
            print("finished", flush=True)
        except KeyboardInterrupt:
            print(f"interrupted after {{time.perf_counter() - begin:.2f}} s", flush=True)
        del s
        import gc; gc.collect()
        left = [p for p in os.listdir(os.environ["TMPDIR"]) if p.startswith("shipsim")]
        print("left", left, flush=True)
        """
    )
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    env = dict(os.environ, TMPDIR=str(tmp))
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, env=env)
    assert p.stdout.readline().strip() == "loaded"
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=30)
    assert p.returncode == 0, err
    lines = out.splitlines()
    assert lines[0].startswith("interrupted after "), out
    # stopped within a fraction of a second of the signal, not at the end of 1e7 s
    assert float(lines[0].split()[2]) < 5.0
    assert lines[1] == "left []", out
    assert list(tmp.iterdir()) == []


def cli_error(*args):
    p = subprocess.run([BIN, *args], capture_output=True, text=True)
    assert p.returncode != 0
    return p.stderr


def test_errors_are_documented_types_with_the_cli_message(tmp_path):
    assert issubclass(shipsim.FmuError, shipsim.ShipsimError)
    assert issubclass(shipsim.ShipsimError, Exception)
    # a bad path
    missing = tmp_path / "missing.toml"
    with pytest.raises(shipsim.SystemFileError) as e:
        shipsim.System.load(missing)
    assert f"error: {e.value}" in cli_error("run", str(missing))
    assert e.value.file == str(missing) or str(e.value.file) == str(missing)
    # an unknown variable, with a suggestion
    s = shipsim.System.load(RRS)
    with pytest.raises(shipsim.VariableError, match="did you mean 'seed'"):
        s.set("waves.sed", 3)
    with pytest.raises(shipsim.VariableError, match="no instance 'wave'"):
        s.run(stop_time=1, variables=["wave.*"])
    # an FMU failure (an FMI call returns fmi2Error): a sub-step that would take 5e298
    # internal steps in one fmi2DoStep is refused by the steering gear
    s.set("gear.servo_order", 2).set("gear.max_substep", 1e-300)
    with pytest.raises(shipsim.SimulationError) as e:
        s.run(stop_time=10)
    assert e.value.status == "fmi2Error" and e.value.instance == "gear"
    assert e.value.function == "fmi2DoStep"
    assert f"error: {e.value}" in cli_error("run", str(RRS), "--stop-time", "10", "--no-output",
                                            "--set", "gear.servo_order=2", "--set", "gear.max_substep=1e-300")
    # an FMU archive that is not one
    bad = tmp_path / "bad.fmu"
    bad.write_bytes(b"not a zip")
    with pytest.raises(shipsim.FmuError) as e:
        shipsim.inspect(bad)
    assert str(bad) in str(e.value)


def test_inspect_reads_the_model_description(fmu_path):
    path = fmu_path("Waves")
    md = shipsim.inspect(path)
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    assert md.guid == root.get("guid") and md.model_name == root.get("modelName")
    xml_vars = root.find("ModelVariables").findall("ScalarVariable")
    assert [v.name for v in md.variables] == [v.get("name") for v in xml_vars]
    for v, x in zip(md.variables, xml_vars):
        assert v.value_reference == int(x.get("valueReference"))
        assert v.causality == x.get("causality", "local")
        typ = next(iter(x))
        assert v.type == typ.tag
        if typ.get("unit") is not None:
            assert v.unit == typ.get("unit")
        if typ.get("start") is not None:
            start = typ.get("start")
            expected = {"Real": float, "Integer": int, "Enumeration": int,
                        "Boolean": lambda s: s == "true", "String": str}[typ.tag](start)
            assert v.start == expected, v.name
    hs = md.variable("significant_wave_height")
    assert hs.causality == "parameter" and hs.unit == "m"
    with pytest.raises(shipsim.VariableError, match="did you mean"):
        md.variable("significant_wave_hight")
    frame = md.to_frame()
    assert frame.loc["significant_wave_height", "unit"] == "m"


def test_readme_python_snippet(tmp_path):
    """The README's Python example runs as written (with the reduced polar campaign and its
    output in a temporary folder, so that the test stays short and leaves nothing behind)."""
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Python: the `shipsim` package"):]
    start = section.index("```python\n") + len("```python\n")
    code = section[start:section.index("```", start)]
    assert 'c.run(jobs=2)' in code and "campaigns/rrs_polar.toml" in code
    code = code.replace("campaigns/rrs_polar.toml", "campaigns/rrs_polar_reduced.toml")
    code = code.replace("c.run(jobs=2)", f"c.run({str(tmp_path / 'out')!r}, jobs=2, progress=False)")
    assert "c.derived_table()" in code
    code = code.replace("c.derived_table()", f"c.derived_table({str(tmp_path / 'out')!r})")
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        scope = {}
        exec(compile(code, "README.md", "exec"), scope)
    finally:
        os.chdir(cwd)
    assert scope["df"].attrs["units"]["ship.roll"] == "rad"
    assert scope["md"].variable("significant_wave_height").unit == "m"
    assert len(scope["table"]) == 12


def test_osp_xml_system_equals_toml(tmp_path):
    """System.load reads OSP OspSystemStructure.xml too: a system exported by
    `shipsim export-osp` runs bit for bit like its TOML (same parameters, connections, step)."""
    toml = ROOT / "systems" / "autopilot_current.toml"
    xml = tmp_path / "OspSystemStructure.xml"
    subprocess.run([BIN, "export-osp", str(toml), "-o", str(xml)], check=True, capture_output=True)
    a, b = shipsim.System.load(toml), shipsim.System.load(xml)
    assert list(a.instances) == list(b.instances)
    every = [f"{name}.*" for name in a.instances]
    ra, rb = a.run(stop_time=120, variables=every), b.run(stop_time=120, variables=every)
    assert len(ra) > 100 and len(ra.columns) > 5
    pd.testing.assert_frame_equal(ra, rb, check_exact=True)


def test_set_accepts_values_with_units():
    """Values with units (docs/units.md) work from Python as in --set: "90 deg" is the same
    double as pi/2 rad, and a wrong unit is refused with both units named."""
    s = shipsim.System.load(RRS)
    a = s.set("waves.wave_direction", "90 deg").run(stop_time=30, variables=["ship.roll"])
    b = s.set("waves.wave_direction", 1.5707963267948966).run(stop_time=30, variables=["ship.roll"])
    assert np.array_equal(a["ship.roll"].to_numpy(), b["ship.roll"].to_numpy())
    s.set("waves.wave_direction", "15 kn")
    with pytest.raises(shipsim.SystemFileError, match="kn"):
        s.run(stop_time=1)


def test_strict_units_of_an_osp_file(tmp_path):
    """An OSP file's unit mismatches are warnings (ShipsimWarning), as libcosim runs such files;
    strict_units = True makes them errors, like --strict-units. The RRS export maps wave moments
    [N.m] onto rudder-equivalent disturbances [rad] (convert = true in the TOML)."""
    xml = tmp_path / "OspSystemStructure.xml"
    subprocess.run([BIN, "export-osp", str(RRS), "-o", str(xml)], check=True, capture_output=True)
    s = shipsim.System.load(xml)
    assert s.strict_units is False and shipsim.System.load(RRS).strict_units is True
    with pytest.warns(shipsim.ShipsimWarning, match="incompatible units"):
        df = s.run(stop_time=20, variables=["ship.roll"])
    ref = shipsim.System.load(RRS).run(stop_time=20, variables=["ship.roll"])
    pd.testing.assert_frame_equal(df, ref, check_exact=True)
    s.strict_units = True
    with pytest.raises(shipsim.SystemFileError, match="incompatible units"):
        s.run(stop_time=20)
