"""Crash isolation from Python (issue 19; docs/isolation.md): `System.run(isolate=...)` and
campaigns run isolated FMU instances in processes of this interpreter
(`python -m shipsim._fmu_host`), so an FMU that segfaults raises SimulationError, or fails its
campaign run, and the Python process lives on. The FMUs that misbehave are the C test FMUs of
master/tests/c (testfmu.c, evilfmu.c), built with gcc here; everything that could crash runs in
a subprocess, so that a failure of the isolation cannot take pytest with it."""
import csv
import pathlib
import subprocess
import sys
import textwrap
import zipfile

import numpy as np

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
C = ROOT / "master" / "tests" / "c"
RRS = ROOT / "systems" / "rrs.toml"


def c_fmu(dest, name, source, defines=()):
    """dest/<name>.fmu from master/tests/c/<source> (the test FMU's model description)."""
    so = dest / f"{name}.so"
    cmd = ["gcc", "-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-o", str(so), str(C / source)]
    cmd += [f"-D{d}" for d in defines] + ["-lm"]
    subprocess.run(cmd, check=True)
    md = (C / "testfmu.xml").read_text().replace("FMI_VERSION", "2.0").replace("GUID", "{shipsim-test-fmu}")
    fmu = dest / f"{name}.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.writestr("modelDescription.xml", md)
        z.write(so, "binaries/linux64/testfmu.so")
    return fmu


def evil_system(d, defines):
    """good (testfmu.c) and evil (evilfmu.c with `defines`), both integrating u = 1 at 0.1 s."""
    c_fmu(d, "testfmu", "testfmu.c")
    c_fmu(d, "evil", "evilfmu.c", defines)
    (d / "sys.toml").write_text(textwrap.dedent("""\
        [simulation]
        stop_time = 1.0
        step_size = 0.1
        [[instances]]
        name = "good"
        fmu = "testfmu.fmu"
        parameters = { u = 1.0 }
        [[instances]]
        name = "evil"
        fmu = "evil.fmu"
        parameters = { u = 1.0 }
        [output]
        variables = ["good.y", "evil.y"]
        """))
    return d / "sys.toml"


def python(script, cwd):
    """Runs `script` in a new interpreter in `cwd`; (exit status, stdout, stderr)."""
    p = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], cwd=cwd,
                       capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout, p.stderr


def test_isolated_run_gives_the_same_bits():
    s = shipsim.System.load(RRS)
    inside = s.run(stop_time=20.0, as_frame=False)
    for isolate in (True, ["gear", "autopilot"], "foreign"):
        outside = s.run(stop_time=20.0, isolate=isolate, as_frame=False)
        for name in inside:
            assert np.array_equal(inside[name].view(np.uint64), outside[name].view(np.uint64)), (isolate, name)


def test_a_segfault_in_an_isolated_fmu_raises_and_python_lives_on(tmp_path):
    evil_system(tmp_path, ["EVIL_SEGV"])
    code, out, err = python("""
        import shipsim
        s = shipsim.System.load("sys.toml")
        try:
            s.run(isolate=["evil"])
        except shipsim.SimulationError as e:
            print("raised:", e.instance, e.function, e.time)
            print(e)
        print("alive")
    """, tmp_path)
    assert code == 0, err
    assert "raised: evil fmi2DoStep 0.3" in out, out + err
    assert "the FMU's process was killed by signal 11 (SIGSEGV" in out, out
    assert out.rstrip().endswith("alive"), out


def test_bad_isolate_arguments_are_errors():
    s = shipsim.System.load(RRS)
    # A string other than "all" and "foreign" names instances, as `--isolate=NAME,NAME` does
    # (test_python_parity.py checks the messages against the CLI's).
    for isolate, name in ((["shipp"], "shipp"), ("shipp", "shipp"), ("some", "some")):
        try:
            s.run(stop_time=1.0, isolate=isolate)
        except shipsim.VariableError as e:
            assert f"no instance '{name}'" in str(e), e
            assert name != "shipp" or "did you mean 'ship'" in str(e), e
        else:
            raise AssertionError("an unknown instance was accepted")
    for kwargs in ({"isolate": ""}, {"isolate": True, "call_timeout": -1.0}):
        try:
            s.run(stop_time=1.0, **kwargs)
        except ValueError as e:
            assert "isolate" in str(e) or "call timeout" in str(e), e
        else:
            raise AssertionError(f"{kwargs} accepted")


def test_a_python_campaign_survives_a_foreign_fmu_that_segfaults(tmp_path):
    """The campaign of master/tests/isolation.rs, from Python: the evil FMU (not built by this
    project) segfaults when u > 1.5, in the second of three runs only."""
    evil_system(tmp_path, ["EVIL_SEGV", "EVIL_IF_U_ABOVE=1.5"])
    (tmp_path / "c.toml").write_text(textwrap.dedent("""\
        system = "sys.toml"
        [[factors]]
        name = "u"
        variable = "evil.u"
        values = [1, 2, 0.5]
        [[kpis]]
        name = "y_max"
        variable = "good.y"
        stat = "max"
        """))
    code, out, err = python("""
        import shipsim
        table = shipsim.Campaign.load("c.toml").run("out", jobs=2, progress=False)
        print("statuses:", ",".join(str(s) for s in table["status"]))
    """, tmp_path)
    assert code == 0, f"status {code}: {err}"
    assert "statuses: ok,error,ok" in out, out + err
    with open(tmp_path / "out" / "runs.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert rows[1]["message"].startswith("instance 'evil': the FMU's process was killed by signal 11 (SIGSEGV"), rows[1]
