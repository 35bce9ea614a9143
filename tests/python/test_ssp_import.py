"""SSP 1.0 import on the hand-written files of tests/fixtures/ssp (not written by shipsim): shipsim
runs them (`shipsim run SystemStructure.ssd` and the `.ssp` archive), the results are checked
against values computed here from the Feedthrough fixture FMU's equations, and where libcosim
accepts a file (`CosimExecution.from_ssp_file`) against libcosim's, bit for bit.

Feedthrough: real_continuous_output = real_continuous_input + real_tunable_parameter * t;
integer_output = integer_input + steps. The master's Jacobi exchange: row n of an input holds the
source's output of row n-1. Tolerance against the equations: 1e-12 absolute.

What libcosim does with each file (libcosim's ssp_parser reads components, connections,
LinearTransformation, parameter sets inline and in .ssv files, and the OSP step annotation):
- linear, params (component A): the same numbers, bit for bit;
- units: libcosim runs it without unit conversion (SSP Units are not read), so its B gets km/h;
- params (component B): libcosim does not read the .ssm mapping, so B keeps its start values;
- nested: libcosim refuses nested systems; mapping: libcosim refuses Enumeration connectors.

Environment: SHIPSIM_BIN (the master; default target/release/shipsim).
"""
import csv
import os
import pathlib
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimObserver import CosimObserver

import fixtures
from conftest import ROOT

BIN = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
CASES = ROOT / "tests" / "fixtures" / "ssp"
H = 0.0625
N = 16
T = np.arange(N + 1) * H


@pytest.fixture(scope="module")
def feedthrough(tmp_path_factory):
    return fixtures.build("Feedthrough", tmp_path_factory.mktemp("fmu"))


def case(name, feedthrough, tmp_path):
    d = tmp_path / name
    shutil.copytree(CASES / name, d)
    (d / "resources").mkdir()
    shutil.copy(feedthrough, d / "resources" / "Feedthrough.fmu")
    return d


def pack(d):
    ssp = d / "system.ssp"
    with zipfile.ZipFile(ssp, "w") as z:
        for f in sorted(d.iterdir()):
            if f.suffix in (".ssd", ".ssv", ".ssm"):
                z.write(f, f.name)
        z.write(d / "resources" / "Feedthrough.fmu", "resources/Feedthrough.fmu")
    return ssp


def shipsim(system):
    out = system.with_suffix(".csv")
    r = subprocess.run([BIN, "run", str(system), "-o", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with open(out) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def libcosim(system, columns):
    """libcosim's run of the SSD; {instance.variable: values at t_1..t_N} (Real variables)."""
    ex = CosimExecution.from_ssp_file(str(system))
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    refs = {}
    for c in columns:
        inst, var = c.split(".", 1)
        idx = ex.slave_index_from_instance_name(inst)
        vr = next(v.reference for v in ex.slave_variables(idx) if v.name.decode() == var)
        refs[c] = (idx, vr)
    rows = []
    for _ in range(N):
        assert ex.step(1)
        rows.append({c: obs.last_real_values(i, [vr])[0] for c, (i, vr) in refs.items()})
    return {c: np.array([r[c] for r in rows]) for c in columns}


def previous(x):
    """The input of row n: the output of row n-1 (row 0: the initial output)."""
    return np.concatenate([[x[0]], x[:-1]])


def test_linear_transformation_equals_equations_and_libcosim(feedthrough, tmp_path):
    d = case("linear", feedthrough, tmp_path)
    ours = shipsim(d / "SystemStructure.ssd")
    a = 3.0 * T
    np.testing.assert_allclose(ours["A.real_continuous_output"], a, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ours["B.real_continuous_output"], 2.5 * previous(a) - 1.0, rtol=0, atol=1e-12)
    theirs = libcosim(d / "SystemStructure.ssd", ["A.real_continuous_output", "B.real_continuous_output"])
    for c, v in theirs.items():
        assert ours[c][1:].tobytes() == v.tobytes(), c
    archive = shipsim(pack(d))
    for c in ours:
        assert ours[c].tobytes() == archive[c].tobytes(), c


def test_unit_conversion_km_per_h_to_m_per_s(feedthrough, tmp_path):
    d = case("units", feedthrough, tmp_path)
    ours = shipsim(d / "SystemStructure.ssd")
    a = 36.0 * T  # km/h
    np.testing.assert_allclose(ours["B.real_continuous_output"], previous(a) * 1000 / 3600, rtol=0, atol=1e-12)
    # libcosim runs the file without unit conversion: B receives km/h as they are
    theirs = libcosim(d / "SystemStructure.ssd", ["B.real_continuous_output"])
    assert theirs["B.real_continuous_output"].tobytes() == previous(a)[1:].tobytes()


def test_parameter_set_in_its_own_ssv(feedthrough, tmp_path):
    d = case("params", feedthrough, tmp_path)
    ours = shipsim(d / "SystemStructure.ssd")
    np.testing.assert_allclose(ours["A.real_continuous_output"], 1.25 * T, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(ours["A.integer_output"], 7 + np.arange(N + 1))
    # gains.ssm: slope (0.75) -> real_tunable_parameter, doubled; offset (-4) -> integer_input
    np.testing.assert_allclose(ours["B.real_continuous_output"], 1.5 * T, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(ours["B.integer_output"], -4 + np.arange(N + 1))
    theirs = libcosim(d / "SystemStructure.ssd", ["A.real_continuous_output"])
    assert ours["A.real_continuous_output"][1:].tobytes() == theirs["A.real_continuous_output"].tobytes()


def test_nested_system(feedthrough, tmp_path):
    d = case("nested", feedthrough, tmp_path)
    ours = shipsim(d / "SystemStructure.ssd")
    want = previous(2.0 * T) + 0.5 * T  # the root's binding (0.5) overrides B's own (9)
    np.testing.assert_allclose(ours["outer/inner/B.real_continuous_output"], want, rtol=0, atol=1e-12)
    with pytest.raises(Exception):
        CosimExecution.from_ssp_file(str(d / "SystemStructure.ssd"))


def test_mapping_transformations(feedthrough, tmp_path):
    d = case("mapping", feedthrough, tmp_path)
    ours = shipsim(pack(d))
    n = np.arange(N + 1)
    a_int = previous(n)
    mapped = np.where(a_int == 1, 100, np.where(a_int == 2, 200, a_int))
    np.testing.assert_array_equal(ours["B.integer_output"], mapped + n)
    a_bool = previous(n % 2)
    np.testing.assert_array_equal(ours["B.boolean_output"], (1 - a_bool) ^ (n % 2))
    a_enum = previous(n % 3 + 1)
    m = np.where(a_enum == 1, 3, np.where(a_enum == 3, 1, a_enum))
    np.testing.assert_array_equal(ours["B.enumeration_output"], (m - 1 + n) % 3 + 1)


def test_errors_name_file_and_element(feedthrough, tmp_path):
    d = case("linear", feedthrough, tmp_path)
    ssd = d / "SystemStructure.ssd"
    ssd.write_text(ssd.read_text().replace('endConnector="real_continuous_input"', 'endConnector="nope"'))
    r = subprocess.run([BIN, "check", str(ssd)], capture_output=True, text=True)
    assert r.returncode != 0
    assert "SystemStructure.ssd:" in r.stderr and 'endConnector "nope"' in r.stderr, r.stderr


def test_python_system_load_reads_an_ssp(feedthrough, tmp_path):
    """The Python package's System.load (through the library's System::load) on an .ssp: the same
    columns, bit for bit, as the CLI. Needs the shipsim package built from this tree."""
    import shipsim as package

    d = case("nested", feedthrough, tmp_path)
    ssp = pack(d)
    cli = shipsim(ssp)
    system = package.System.load(ssp)
    assert "outer/inner/B" in system.instances
    got = system.run(as_frame=False)
    for c in ("A.real_continuous_output", "outer/inner/B.real_continuous_output"):
        assert np.asarray(got[c], dtype=np.float64).tobytes() == cli[c].tobytes(), c
