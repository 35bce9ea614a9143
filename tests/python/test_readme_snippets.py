"""The README's FMPy and libcosim snippets ("In FMPy", "In libcosim (libcosimpy)"), extracted from
README.md and run as a user would: each prints a few lines (no per-call log lines from our FMUs, no
libcosim trace) and the numbers it says.

Paths: `target/fmu/` becomes SHIPSIM_FMU_DIR; `target/osp/rrs` becomes a temporary folder with
the RRS system exported by `shipsim export-osp` (so the test does not need `cargo xtask
export-osp`). Environment: SHIPSIM_FMU_DIR, SHIPSIM_BIN (see conftest.py).
"""
import csv
import math
import os
import pathlib
import re
import subprocess
import sys

import pytest
from conftest import ROOT, fmu_dir

# A snippet's whole output (stdout and stderr) is at most this many lines.
MAX_LINES = 20


def shipsim_bin() -> str:
    exe = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
    if not pathlib.Path(exe).exists():
        raise RuntimeError(f"{exe} is missing: run `cargo build --release -p shipsim`")
    return exe


def section(title: str) -> str:
    """The README text under `### {title}` up to the next heading of level 2 or 3."""
    text = (ROOT / "README.md").read_text()
    start = text.index(f"### {title}\n")
    end = re.compile(r"^##", re.M).search(text, start + 4)
    return text[start:end.start() if end else len(text)]


def python_blocks(title: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", section(title), re.S)


def run_snippet(code: str, cwd: pathlib.Path, osp: pathlib.Path | None = None) -> list[str]:
    """Runs a snippet in a fresh interpreter; returns its output lines (stdout, then stderr)."""
    code = code.replace("target/fmu/", f"{fmu_dir()}/")
    if osp is not None:
        code = code.replace('"target/osp/rrs"', repr(str(osp)))
    r = subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True, timeout=600)
    lines = r.stdout.splitlines() + r.stderr.splitlines()
    assert r.returncode == 0, f"snippet failed ({r.returncode}):\n" + "\n".join(lines[-30:])
    assert len(lines) < MAX_LINES, f"{len(lines)} lines of output:\n" + "\n".join(lines[:30])
    return r.stdout.splitlines()


def numbers(line: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+\.\d+(?:e-?\d+)?", line)]


def test_readme_has_the_snippets():
    assert len(python_blocks("In FMPy")) == 1
    assert len(python_blocks("In libcosim (libcosimpy)")) == 2


def test_fmpy_snippet_steps_at_10_ms(tmp_path):
    (code,) = python_blocks("In FMPy")
    out = run_snippet(code, tmp_path)
    assert len(out) == 3, out
    # time[1]: the first step is 0.01 s (FMPy's default output interval would give 0.08 s)
    assert float(out[0]) == pytest.approx(0.01, abs=1e-12)
    # at t = 6 s the gear has run 1 s at its rate limit rate_max = 0.0436 rad/s (tolerance 1e-9)
    assert float(out[1]) == pytest.approx(0.0436, abs=1e-9)
    # at 60 s it rests at the default angle limit, 22 deg (tolerance 1e-12)
    assert float(out[2]) == pytest.approx(math.radians(22.0), abs=1e-12)


def test_libcosim_snippet_is_quiet_and_reaches_the_command(tmp_path):
    code = python_blocks("In libcosim (libcosimpy)")[0]
    out = run_snippet(code, tmp_path)
    assert len(out) == 1, out
    # rudder_command 0.3 rad, within the 22 deg limit: after 10 s the gear is there (1e-9)
    (angle,) = numbers(out[0])
    assert angle == pytest.approx(0.3, abs=1e-9)


@pytest.fixture(scope="module")
def rrs(tmp_path_factory):
    """systems/rrs.toml with its FMUs from SHIPSIM_FMU_DIR, exported to OSP, and shipsim's CSV
    of it up to 600 s."""
    d = tmp_path_factory.mktemp("rrs")
    toml = d / "rrs.toml"
    toml.write_text((ROOT / "systems" / "rrs.toml").read_text().replace('"../target/fmu/', f'"{fmu_dir()}/'))
    osp = d / "osp" / "rrs"
    for args in (["export-osp", toml, "-o", osp / "OspSystemStructure.xml"],
                 ["run", toml, "--stop-time", "600", "-o", d / "rrs.csv", "-q"]):
        r = subprocess.run([shipsim_bin(), *map(str, args)], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
    with open(d / "rrs.csv") as f:
        rows = list(csv.reader(f))
    return osp, rows


def test_osp_snippet_runs_the_exported_rrs_quietly(tmp_path, rrs):
    osp, rows = rrs
    code = python_blocks("In libcosim (libcosimpy)")[1]
    out = run_snippet(code, tmp_path, osp)
    assert len(out) == 1, out
    (roll,) = numbers(out[0])
    header, last = rows[0], rows[-1]
    assert float(last[0]) == 600.0
    # libcosim and shipsim agree bit for bit on every system (test_systems_libcosim.py)
    assert roll == float(last[header.index("ship.roll")])
    assert roll != 0.0


def test_osp_snippet_without_the_export_says_what_to_run(tmp_path):
    code = python_blocks("In libcosim (libcosimpy)")[1]
    missing = tmp_path / "nothing" / "rrs"
    r = subprocess.run([sys.executable, "-c", code.replace('"target/osp/rrs"', repr(str(missing)))],
                       cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert r.returncode == 1
    lines = r.stderr.splitlines()
    assert lines == [f"{missing}/OspSystemStructure.xml is missing: run `cargo xtask export-osp` or "
                     f"`shipsim export-osp systems/rrs.toml -o {missing}/OspSystemStructure.xml`"], lines


def test_libcosim_at_trace_level_gets_no_per_call_lines(tmp_path):
    """libcosim instantiates with loggingOn = true; at trace level it shows whatever the FMU logs:
    the lifecycle (logEvents: instantiated, initialized, terminated), not one line per call."""
    code = python_blocks("In libcosim (libcosimpy)")[0]
    code = code.replace("log_output_level(CosimLogLevel.WARNING)", "log_output_level(CosimLogLevel.TRACE)")
    code = code.replace("target/fmu/", f"{fmu_dir()}/")
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    lines = (r.stdout + r.stderr).splitlines()
    assert sum("category=logCalls" in l for l in lines) == 0
    events = [l for l in lines if "category=logEvents" in l]
    assert len(events) == 3 and "instantiated SteeringGear" in events[0], events
