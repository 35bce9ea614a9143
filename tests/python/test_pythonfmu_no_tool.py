"""A PythonFMU built with `pythonfmu build --no-external-tool` (issue 18, interop defect
"PythonFMU without an external tool").

Such an FMU declares needsExecutionTool="false" but its binary is the same as the default
build's: it calls the CPython C API without linking libpython. FMPy runs it because FMPy's
process holds libpython already; shipsim loaded the Python runtime only for
needsExecutionTool="true" and failed with "undefined symbol: _Py_NoneStruct". shipsim now loads
the runtime of the Python named by SHIPSIM_PYTHON (else $VIRTUAL_ENV/bin/python3, else python3
on PATH; master/src/fmu.rs, `python::python_executable`) when the binary misses a CPython symbol.

The FMU is built here with the test's own Python, run in shipsim and in FMPy with the base step
1/16 s (dyadic: both tools pass the same communication points), every row equal bit for bit
(tolerance 0).

Environment: SHIPSIM_BIN (the master).
"""
import subprocess
import sys
import textwrap
import zipfile

import numpy as np
import pytest
from fmpy import simulate_fmu

from test_master_interop import read_csv, shipsim

H = 0.0625

WAVE = """
import math
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real

class Wave(Fmi2Slave):
    author = "shipsim tests"
    description = "y = amp*sin(omega*t) + u, z = integral of y (explicit Euler per step)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.amp = 1.5
        self.omega = 2.0
        self.u = 0.0
        self.y = 0.0
        self.z = 0.0
        self.register_variable(Real("amp", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("omega", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Real("y", causality=Fmi2Causality.output))
        self.register_variable(Real("z", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self.z += step_size * self.y
        self.y = self.amp * math.sin(self.omega * (current_time + step_size)) + self.u
        return True
"""


@pytest.fixture(scope="module")
def no_tool_fmu(tmp_path_factory):
    d = tmp_path_factory.mktemp("no_tool")
    (d / "Wave.py").write_text(textwrap.dedent(WAVE))
    subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(d / "Wave.py"), "-d", str(d),
                    "--no-external-tool"], check=True, capture_output=True)
    fmu = d / "Wave.fmu"
    with zipfile.ZipFile(fmu) as z:
        md = z.read("modelDescription.xml").decode()
    # What makes this variant different: it does not ask for an execution tool.
    assert 'needsExecutionTool="false"' in md
    return fmu


def system(fmu, stop):
    return textwrap.dedent(f"""
        [simulation]
        stop_time = {stop!r}
        step_size = {H!r}
        [[instances]]
        name = "w"
        fmu = "{fmu}"
        parameters = {{ amp = 0.75, omega = 3.0, u = 0.25 }}
    """)


def test_no_external_tool_pythonfmu_equals_fmpy_bit_for_bit(no_tool_fmu, tmp_path):
    (tmp_path / "w.toml").write_text(system(no_tool_fmu, 2.0))
    shipsim("run", tmp_path / "w.toml", "-o", tmp_path / "w.csv")
    header, rows = read_csv(tmp_path / "w.csv")
    assert header == ["time", "w.y", "w.z"]
    ours = np.array(rows)
    theirs = simulate_fmu(str(no_tool_fmu), start_time=0.0, stop_time=2.0, step_size=H, output_interval=H,
                          start_values={"amp": 0.75, "omega": 3.0, "u": 0.25}, output=["y", "z"])
    assert len(theirs) == len(ours) == 33
    assert theirs["time"].astype(np.float64).tobytes() == ours[:, 0].tobytes()
    for j, out in enumerate(["y", "z"], start=1):
        a, b = ours[:, j], theirs[out].astype(np.float64)
        diff = np.flatnonzero(a.view(np.uint64) != b.view(np.uint64))
        assert diff.size == 0, f"{out}: first difference at row {diff[0]}: shipsim {a[diff[0]]!r}, FMPy {b[diff[0]]!r}"
    # Not trivial: y follows the parameters (0.75 sin(3 t) + 0.25 at t = 2 s, to 1e-15).
    assert abs(ours[-1, 1] - (0.75 * np.sin(6.0) + 0.25)) < 1e-15


def test_no_external_tool_pythonfmu_without_a_python_names_the_cause(no_tool_fmu, tmp_path):
    (tmp_path / "w.toml").write_text(system(no_tool_fmu, 0.5))
    r = shipsim("run", tmp_path / "w.toml", env_extra={"SHIPSIM_PYTHON": str(tmp_path / "no-such-python")},
                check=False)
    assert r.returncode != 0
    assert "calls the Python C API" in r.stderr and "_Py" in r.stderr, r.stderr
    assert "no-such-python" in r.stderr, r.stderr


PICKY = """
import importlib, os
from pythonfmu import Fmi2Causality, Fmi2Slave, Real

class Picky(Fmi2Slave):
    author = "shipsim tests"
    description = "needs the module named by $PICKY_NEEDS (as an FMU needs numpy): y = 2"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        importlib.import_module(os.environ.get("PICKY_NEEDS", "math"))
        self.y = 2.0
        self.register_variable(Real("y", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        return True
"""


def test_a_run_that_fails_to_instantiate_keeps_the_last_csv_and_names_its_python(tmp_path):
    """Issue 36, item 1: the run that failed at fmi2Instantiate (its Python lacked a package)
    truncated the last good CSV to its header, and the error named neither the Python used
    nor SHIPSIM_PYTHON."""
    (tmp_path / "Picky.py").write_text(textwrap.dedent(PICKY))
    subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(tmp_path / "Picky.py"), "-d",
                    str(tmp_path), "--no-external-tool"], check=True, capture_output=True)
    (tmp_path / "p.toml").write_text(textwrap.dedent(f"""
        [simulation]
        stop_time = 0.5
        step_size = 0.125
        [[instances]]
        name = "p"
        fmu = "{tmp_path / 'Picky.fmu'}"
    """))
    csv = tmp_path / "p.csv"
    shipsim("run", tmp_path / "p.toml", "-o", csv)
    good = csv.read_text()
    assert good.splitlines() == ["time,p.y", "0,2", "0.125,2", "0.25,2", "0.375,2", "0.5,2"], good
    r = shipsim("run", tmp_path / "p.toml", "-o", csv, env_extra={"PICKY_NEEDS": "no_such_package_here"},
                check=False)
    assert r.returncode != 0
    assert "fmi2Instantiate returned NULL" in r.stderr, r.stderr
    assert csv.read_text() == good, "the failed run touched the last CSV"
    assert "the FMU runs on Python 3." in r.stderr and "SHIPSIM_PYTHON" in r.stderr, r.stderr
