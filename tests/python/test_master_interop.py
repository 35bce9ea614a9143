"""The shipsim master against FMUs it did not build, and against libcosim.

* FMUs generated at test time with PythonFMU (`pythonfmu build`), and the FMUs shipped in the
  PyPI package crane-fmu, run in shipsim (which hosts their Python runtime itself).
* A chained system of them, written as native TOML, exported with `shipsim export-osp`, gives the
  same CSV in shipsim as in libcosim (libcosimpy) on that OspSystemStructure.xml, to 1e-12
  (Jacobi stepping).
* Our own FMUs (SteeringGear) coupled: same check.

Environment: SHIPSIM_BIN (the master binary), SHIPSIM_FMU_DIR (our built FMUs).
"""
import csv
import importlib.metadata
import json
import os
import pathlib
import shutil
import subprocess
import sys
import textwrap

import pytest
from conftest import ROOT


def shipsim_bin() -> str:
    exe = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
    if not pathlib.Path(exe).exists():
        raise RuntimeError(f"{exe} is missing: run `cargo build --release -p shipsim` (or `cargo xtask test`)")
    return exe


def shipsim(*args, env_extra=None, check=True):
    env = dict(os.environ)
    # The Python whose libpython shipsim loads for PythonFMU FMUs: the one running the tests,
    # which has pythonfmu and crane-fmu installed.
    env.setdefault("SHIPSIM_PYTHON", sys.executable)
    env.update(env_extra or {})
    r = subprocess.run([shipsim_bin(), *map(str, args)], capture_output=True, text=True, env=env)
    if check and r.returncode != 0:
        raise AssertionError(f"shipsim {' '.join(map(str, args))} failed ({r.returncode}):\n{r.stderr}")
    return r


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]


def libcosim_rows(osp_file, header, n_steps):
    """Runs an OspSystemStructure.xml in libcosim (in a child process, see libcosim_runner.py);
    returns rows t_1..t_n of the header's columns."""
    runner = pathlib.Path(__file__).with_name("libcosim_runner.py")
    r = subprocess.run([sys.executable, str(runner), str(osp_file), str(n_steps), *header[1:]],
                       capture_output=True, text=True)
    assert r.returncode == 0, f"libcosim run of {osp_file} failed ({r.returncode}):\n{r.stderr}"
    return json.loads(r.stdout)


def assert_same_as_libcosim(osp_file, our_csv, tol=0.0):
    header, ours = read_csv(our_csv)
    theirs = libcosim_rows(osp_file, header, len(ours) - 1)
    worst = 0.0
    for k, (a, b) in enumerate(zip(ours[1:], theirs), start=1):
        for name, x, y in zip(header[1:], a[1:], b):
            d = abs(x - y)
            worst = max(worst, d)
            assert d <= tol * max(1.0, abs(y)), f"row {k} (t = {a[0]}), {name}: shipsim {x!r} vs libcosim {y!r}"
    return worst


SRC = """
import math
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real

class Src(Fmi2Slave):
    author = "shipsim tests"
    description = "y = amp*sin(omega*t) - 0.5*fb"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.amp = 1.0
        self.omega = 2.0
        self.fb = 0.0
        self.y = 0.0
        self.register_variable(Real("amp", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("omega", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("fb", causality=Fmi2Causality.input))
        self.register_variable(Real("y", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self.y = self.amp * math.sin(self.omega * (current_time + step_size)) - 0.5 * self.fb
        return True
"""

INTEGRATOR = """
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real

class Integrator(Fmi2Slave):
    author = "shipsim tests"
    description = "x' = u (explicit Euler per communication step), y = k*x"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.k = 1.0
        self.u = 0.0
        self.x = 0.0
        self.y = 0.0
        self.register_variable(Real("k", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Real("x", causality=Fmi2Causality.output))
        self.register_variable(Real("y", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self.x += step_size * self.u
        self.y = self.k * self.x
        return True
"""


@pytest.fixture(scope="module")
def python_fmus(tmp_path_factory):
    """Src.fmu and Integrator.fmu built with PythonFMU at test time."""
    d = tmp_path_factory.mktemp("pythonfmu")
    for name, code in [("Src", SRC), ("Integrator", INTEGRATOR)]:
        script = d / f"{name}.py"
        script.write_text(textwrap.dedent(code))
        subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(script), "-d", str(d)], check=True,
                       capture_output=True)
        assert (d / f"{name}.fmu").exists()
    return d


def crane_fmu(name):
    for f in importlib.metadata.files("crane-fmu"):
        if f.name == f"{name}.fmu":
            return pathlib.Path(f.locate())
    raise RuntimeError(f"{name}.fmu not found in the crane-fmu package")


def test_pythonfmu_chain_equals_libcosim(python_fmus, tmp_path):
    for f in ["Src.fmu", "Integrator.fmu"]:
        shutil.copy(python_fmus / f, tmp_path / f)
    (tmp_path / "chain.toml").write_text(textwrap.dedent("""
        connections = ["src.y -> int1.u", "int1.y -> int2.u", "int2.x -> src.fb"]
        [simulation]
        stop_time = 2.0
        step_size = 0.01
        [[instances]]
        name = "src"
        fmu = "Src.fmu"
        parameters = { amp = 1.5, omega = 3.0 }
        [[instances]]
        name = "int1"
        fmu = "Integrator.fmu"
        parameters = { k = 2.0 }
        [[instances]]
        name = "int2"
        fmu = "Integrator.fmu"
        [output]
        variables = ["src.y", "int1.x", "int1.y", "int2.x", "int2.y"]
    """))
    out_toml = tmp_path / "toml.csv"
    r = shipsim("run", tmp_path / "chain.toml", "-o", out_toml)
    assert "200 macro steps, 600 FMU steps" in r.stderr
    shipsim("export-osp", tmp_path / "chain.toml", "-o", tmp_path / "OspSystemStructure.xml")
    out_osp = tmp_path / "osp.csv"
    shipsim("run", tmp_path / "OspSystemStructure.xml", "-o", out_osp)
    h1, rows_toml = read_csv(out_toml)
    h2, rows_osp = read_csv(out_osp)
    # The OSP run records every output; same values on the shared columns.
    idx = [h2.index(h) for h in h1]
    assert [[r[i] for i in idx] for r in rows_osp] == rows_toml
    header, rows = read_csv(out_toml)
    assert len(rows) == 201
    assert rows[-1][0] == 2.0
    # Not trivially zero: the chain carries the signal through both integrators.
    assert abs(rows[-1][header.index("int2.x")]) > 1e-3
    assert_same_as_libcosim(tmp_path / "OspSystemStructure.xml", out_toml)


def test_crane_fmu_forced_oscillator_equals_libcosim(tmp_path):
    """crane-fmu's oscillator and driving force; a gain/offset connection becomes an OSP
    LinearTransformation function in the exported file."""
    for name in ["HarmonicOscillator6D", "DrivingForce"]:
        shutil.copy(crane_fmu(name), tmp_path / f"{name}.fmu")
    (tmp_path / "osc.toml").write_text(textwrap.dedent("""
        connections = [
            { from = "drv.f[2]", to = "osc.f[2]", gain = 2.0, offset = 0.1 },
            "osc.v[2] -> drv.v_osc[2]",
            "drv.f[0] -> osc.f[0]",
        ]
        [simulation]
        stop_time = 1.0
        step_size = 0.01
        [[instances]]
        name = "drv"
        fmu = "DrivingForce.fmu"
        parameters = { "ampl[2]" = 2.0, "freq[0]" = 0.5 }
        [[instances]]
        name = "osc"
        fmu = "HarmonicOscillator6D.fmu"
        parameters = { "c[2]" = 0.3 }
        [output]
        variables = ["drv.*", "osc.x[0]", "osc.x[2]", "osc.v[2]"]
    """))
    out = tmp_path / "osc.csv"
    shipsim("run", tmp_path / "osc.toml", "-o", out)
    shipsim("export-osp", tmp_path / "osc.toml", "-o", tmp_path / "OspSystemStructure.xml")
    assert '<LinearTransformation name="lt0" factor="2.0" offset="0.1"/>' in (tmp_path / "OspSystemStructure.xml").read_text()
    header, rows = read_csv(out)
    assert abs(rows[-1][header.index("osc.x[2]")]) > 1e-3
    assert_same_as_libcosim(tmp_path / "OspSystemStructure.xml", out)


def test_python_runtime_found_on_path_and_clear_error_without(python_fmus, tmp_path):
    shutil.copy(python_fmus / "Src.fmu", tmp_path / "Src.fmu")
    (tmp_path / "one.toml").write_text(
        '[simulation]\nstop_time = 0.1\nstep_size = 0.05\n[[instances]]\nname = "s"\nfmu = "Src.fmu"\n')
    # python3 on PATH (the test venv's bin first), no SHIPSIM_PYTHON / VIRTUAL_ENV.
    env = {k: v for k, v in os.environ.items() if k not in ("SHIPSIM_PYTHON", "VIRTUAL_ENV", "PYTHONHOME",
                                                              "PYTHONPATH")}
    bindir = tmp_path / "bin"
    bindir.mkdir()
    (bindir / "python3").symlink_to(sys.executable)
    env["PATH"] = f"{bindir}:{env.get('PATH', '')}"
    r = subprocess.run([shipsim_bin(), "run", str(tmp_path / "one.toml"), "-o", str(tmp_path / "o.csv")],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    header, rows = read_csv(tmp_path / "o.csv")
    assert header == ["time", "s.y"] and len(rows) == 3
    # No usable Python: a clear error naming the FMU, no crash.
    r = shipsim("run", tmp_path / "one.toml", env_extra={"SHIPSIM_PYTHON": "/nonexistent/python3"}, check=False)
    assert r.returncode == 1, r.stderr
    assert "Src.fmu" in r.stderr and "needsExecutionTool" in r.stderr and "no suitable Python found" in r.stderr


def test_inspect_third_party_fmu():
    r = shipsim("inspect", crane_fmu("DrivingForce"))
    assert "generated by   PythonFMU" in r.stdout
    assert "needsExecutionTool                       true" in r.stdout
    assert "v_osc[2]" in r.stdout


def our_fmu(model_identifier):
    d = pathlib.Path(os.environ.get("SHIPSIM_FMU_DIR", ROOT / "target" / "fmu"))
    p = d / f"{model_identifier}.fmu"
    if not p.exists():
        raise RuntimeError(f"{p} is missing: run `cargo xtask build-fmus` first")
    return p


def test_our_fmus_coupled_equal_libcosim(tmp_path):
    shutil.copy(our_fmu("SteeringGear"), tmp_path / "SteeringGear.fmu")
    # A fast first-order gear drives a slower second-order one (multi-rate 1:2); both tunable
    # and fixed parameters and an input start value are set through the system file.
    (tmp_path / "gears.toml").write_text(textwrap.dedent("""
        connections = ["fast.rudder_angle -> slow.rudder_command"]
        [simulation]
        stop_time = 10.0
        step_size = 0.01
        [[instances]]
        name = "fast"
        fmu = "SteeringGear.fmu"
        parameters = { rudder_command = 0.35, time_constant = 0.5 }
        [[instances]]
        name = "slow"
        fmu = "SteeringGear.fmu"
        step_multiple = 2
        parameters = { servo_order = 2, omega0 = 3.0, zeta0 = 0.7 }
        [output]
        variables = ["fast.rudder_angle", "fast.rudder_rate", "slow.rudder_angle", "slow.rudder_rate"]
    """))
    out = tmp_path / "gears.csv"
    shipsim("run", tmp_path / "gears.toml", "-o", out)
    shipsim("export-osp", tmp_path / "gears.toml", "-o", tmp_path / "OspSystemStructure.xml")
    header, rows = read_csv(out)
    # The command passes both gears: angle limit 22 deg = 0.384 rad is not reached by 0.35.
    assert abs(rows[-1][header.index("fast.rudder_angle")] - 0.35) < 1e-3
    assert abs(rows[-1][header.index("slow.rudder_angle")] - 0.35) < 1e-2
    assert_same_as_libcosim(tmp_path / "OspSystemStructure.xml", out)
