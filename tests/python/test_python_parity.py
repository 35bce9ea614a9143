"""One rule for every entry point (issue 29), from Python: the end-time rule of OSP and SSP
files, the algorithm names and the isolation options are accepted and refused by
`System.run` and `Campaign` as by `shipsim run` and `shipsim campaign run`, with the same
messages (each case asks the CLI, SHIPSIM_BIN, and Python side by side, and expects the exact
strings master/tests/parity.rs expects).

Before issue 29: `System.run()` ran an OSP file without <EndTime> for 1 s, `algorithm="seidel"`
and `isolate="gear,autopilot"` were ValueErrors, `--isolate=NAME` of no instance isolated
nothing, and every entry point had its own message for a bad value.

The system is the C test FMU (master/tests/c/testfmu.c, built with gcc here): src integrates
u = 1 and dst integrates src.y, so that dst.y(1 s) is 0.45 under Jacobi and 0.55 under
Gauss-Seidel."""
import os
import pathlib
import subprocess
import textwrap
import zipfile

import numpy as np
import pytest

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
C = ROOT / "master" / "tests" / "c"
BIN = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))

GIVE = ("give the run a stop time: shipsim run --stop-time SECONDS, "
        "System.run(stop_time=SECONDS) in Python, or stop_time = SECONDS in a campaign file")

CHAIN = textwrap.dedent("""\
    connections = [{ from = "src.y", to = "dst.u" }]
    [simulation]
    stop_time = 1.0
    step_size = 0.1
    algorithm = "ALGO"
    [[instances]]
    name = "dst"
    fmu = "testfmu.fmu"
    [[instances]]
    name = "src"
    fmu = "testfmu.fmu"
    parameters = { u = 1.0 }
    """)
ALGORITHM_LINE = 5

OSP_WITHOUT_END = """<OspSystemStructure version="0.1"><BaseStepSize>0.1</BaseStepSize><Simulators>
<Simulator name="a" source="testfmu.fmu"/></Simulators></OspSystemStructure>"""

SSD_WITHOUT_STOP = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations" name="one" version="1.0">
  <ssd:System name="root">
    <ssd:Elements>
      <ssd:Component name="a" source="testfmu.fmu"/>
    </ssd:Elements>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="0.1"/></osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""

SPELLINGS = [
    ("jacobi", 0.45), ("Jacobi", 0.45), ("JACOBI", 0.45),
    ("gauss-seidel", 0.55), ("gauss_seidel", 0.55), ("gauss seidel", 0.55),
    ("gaussseidel", 0.55), ("seidel", 0.55), ("Gauss-Seidel", 0.55), ("GAUSS_SEIDEL", 0.55),
    ("SEIDEL", 0.55),
]


@pytest.fixture()
def d(tmp_path):
    """tmp_path with testfmu.fmu (the test FMU's model description and binary)."""
    so = tmp_path / "testfmu.so"
    subprocess.run(["gcc", "-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-o", str(so),
                    str(C / "testfmu.c"), "-lm"], check=True)
    md = (C / "testfmu.xml").read_text().replace("FMI_VERSION", "2.0").replace("GUID", "{shipsim-test-fmu}")
    with zipfile.ZipFile(tmp_path / "testfmu.fmu", "w") as z:
        z.writestr("modelDescription.xml", md)
        z.write(so, "binaries/linux64/testfmu.so")
    return tmp_path


def cli(*args):
    """`shipsim ARGS`: (exit status, stderr)."""
    p = subprocess.run([BIN, *map(str, args)], capture_output=True, text=True, timeout=300)
    return p.returncode, p.stderr


def cli_refuses(args, message):
    assert cli(*args) == (1, f"error: {message}\n"), args


def cli_accepts(*args):
    code, err = cli(*args)
    assert code == 0, (args, err)


def write(path, text):
    path.write_text(text)
    return path


def campaign(d, name, system, variable, stop=None):
    """A campaign file of one run recording the final value of `variable` as KPI `last`."""
    stop = "" if stop is None else f"stop_time = {stop!r}\n"
    return write(d / name, f'system = "{system.name}"\n{stop}[[kpis]]\nname = "last"\n'
                           f'variable = "{variable}"\nstat = "final"\n')


def raises(exc, message, f, *args, **kwargs):
    """f(*args, **kwargs) raises exactly `exc` with exactly `message`."""
    with pytest.raises(exc) as e:
        f(*args, **kwargs)
    assert type(e.value) is exc and str(e.value) == message, (type(e.value), str(e.value))


@pytest.mark.parametrize("name, text, missing", [
    ("OspSystemStructure.xml", OSP_WITHOUT_END, "<EndTime>"),
    ("SystemStructure.ssd", SSD_WITHOUT_STOP, '<DefaultExperiment stopTime="...">'),
], ids=["osp", "ssp"])
def test_a_file_without_an_end_time_needs_a_stop_time_everywhere(d, name, text, missing):
    sys_file = write(d / name, text)
    message = f"{sys_file}: the file has no {missing}; {GIVE}"
    cli_refuses(["run", sys_file, "-q"], message)
    s = shipsim.System.load(sys_file)
    raises(shipsim.SystemFileError, message, s.run, as_frame=False)
    r = s.run(stop_time=0.3, variables=["a.t_last"], as_frame=False)
    assert abs(r["a.t_last"][-1] - 0.3) < 1e-12
    cli_accepts("run", sys_file, "-q", "--stop-time", "0.3")

    c = campaign(d, "c.toml", sys_file, "a.t_last")
    raises(shipsim.SystemFileError, message, shipsim.Campaign.load, c)
    cli_refuses(["campaign", "run", c, "-q", "-o", d / "out"], message)
    c = campaign(d, "c_stop.toml", sys_file, "a.t_last", stop=0.3)
    t = shipsim.Campaign.load(c).run(d / "py_out", jobs=1, progress=False, as_frame=False)
    assert abs(t["last"][0] - 0.3) < 1e-12 and t["status"][0] == "ok"
    cli_accepts("campaign", "run", c, "-q", "-o", d / "cli_out")


def test_algorithm_names_are_the_same_everywhere(d):
    base = write(d / "chain.toml", CHAIN.replace("ALGO", "jacobi"))
    s = shipsim.System.load(base)
    for i, (name, dst) in enumerate(SPELLINGS):
        r = s.run(algorithm=name, variables=["dst.y"], as_frame=False)
        assert abs(r["dst.y"][-1] - dst) < 1e-12, name
        cli_accepts("run", base, "-q", f"--algorithm={name}", "--no-output")
        in_file = write(d / f"chain_{i}.toml", CHAIN.replace("ALGO", name))
        r = shipsim.System.load(in_file).run(variables=["dst.y"], as_frame=False)
        assert abs(r["dst.y"][-1] - dst) < 1e-12, name
        c = campaign(d, f"c_{i}.toml", in_file, "dst.y")
        t = shipsim.Campaign.load(c).run(d / f"out_{i}", jobs=1, progress=False, as_frame=False)
        assert abs(t["last"][0] - dst) < 1e-12, name
    for name in ["rk4", "gauss--seidel", " jacobi"]:
        message = f'unknown algorithm "{name}"; use "jacobi" or "gauss-seidel"'
        raises(ValueError, message, s.run, algorithm=name)
        cli_refuses(["run", base, "-q", f"--algorithm={name}"], message)
        bad = write(d / "bad.toml", CHAIN.replace("ALGO", name))
        in_file = f"{bad}:{ALGORITHM_LINE}: {message}"
        raises(shipsim.SystemFileError, in_file, shipsim.System.load, bad)
        cli_refuses(["run", bad, "-q"], in_file)
        c = campaign(d, "c_bad.toml", bad, "dst.y")
        in_campaign = f"campaign {c}: base system: {in_file}"
        raises(shipsim.SystemFileError, in_campaign, shipsim.Campaign.load, c)
        cli_refuses(["campaign", "run", c, "-q", "-o", d / "out_bad"], in_campaign)


def test_isolation_options_are_the_same_for_python_and_the_cli(d):
    sys_file = write(d / "chain.toml", CHAIN.replace("ALGO", "jacobi"))
    s = shipsim.System.load(sys_file)
    inside = s.run(as_frame=False)
    # (Python's isolate=, the CLI's option or None where the CLI has no such form)
    for isolate, option in [
        (True, "--isolate"), ("all", "--isolate=all"), ("foreign", "--isolate=foreign"),
        ("src", "--isolate=src"), ("src,dst", "--isolate=src,dst"),
        (" dst , src,", "--isolate= dst , src,"), (["src"], None), (["dst", "src"], None),
        (False, None), (None, None),
    ]:
        out = s.run(isolate=isolate, call_timeout=30.0, as_frame=False)
        for k in inside:
            assert inside[k].dtype == out[k].dtype and np.array_equal(inside[k], out[k]), (isolate, k)
        if option:
            cli_accepts("run", sys_file, "-q", option, "--call-timeout=30", "--no-output")
    bad_value = "give all, foreign or instance names separated by commas"
    for kwargs, option, exc, message in [
        ({"isolate": ""}, "--isolate=", ValueError, f'isolate "": {bad_value}'),
        ({"isolate": " , "}, "--isolate= , ", ValueError, f'isolate " , ": {bad_value}'),
        ({"isolate": "srcc"}, "--isolate=srcc", shipsim.VariableError,
         f"isolate: no instance 'srcc' in {sys_file} (did you mean 'src'?)"),
        ({"isolate": "src,bogus"}, "--isolate=src,bogus", shipsim.VariableError,
         f"isolate: no instance 'bogus' in {sys_file}"),
        ({"isolate": ["src", "bogus"]}, None, shipsim.VariableError,
         f"isolate: no instance 'bogus' in {sys_file}"),
        ({"call_timeout": -1.0}, "--call-timeout=-1", ValueError,
         "call timeout -1: give a positive number of seconds (at most 1e9)"),
        ({"call_timeout": 0.0}, "--call-timeout=0", ValueError,
         "call timeout 0: give a positive number of seconds (at most 1e9)"),
        ({"call_timeout": 2e9}, "--call-timeout=2e9", ValueError,
         "call timeout 2000000000: give a positive number of seconds (at most 1e9)"),
    ]:
        raises(exc, message, s.run, **kwargs)
        if option:
            cli_refuses(["run", sys_file, "-q", option], message)
