"""The win64 binary of every FMU, run under Wine: the same reference cases as the linux64 binary
(`CASES` of test_fmu_cases.py), compared with it variable by variable.

One C program, tests/harness/fmi2_script.c, drives the FMI 2.0 C API on both platforms: built with
gcc it loads `binaries/linux64/<id>.so`, built with MinGW-w64 and run under `wine64` it loads
`binaries/win64/<id>.dll`. Each case becomes a script (the reference's start values, inputs and time
grid, in FMPy's order of calls) that records every output and local variable after every step in
hexadecimal bits. The checks:

* `test_linux64_harness_matches_rust_model`: the linux64 run equals the Rust-model reference to the
  case's tolerance (1e-12 x scale, as FMPy in test_fmu_cases.py), so the harness drives the case as
  FMPy does and the comparisons below are not vacuous;
* `test_win64_matches_linux64`: on every output and local of every case,
  |win64 - linux64| <= 1e-12 x that variable's largest magnitude over the run on linux64 (1 for a
  variable that stays at 0); Integers and Booleans exactly. The differences are written to
  target/win64/wine-tests/differences.json (docs/windows.md quotes them);
* `test_state_crosses_platforms`: an FMU state serialized by the linux64 binary halfway through the
  case, restored into the win64 binary (and the other way round), continues as the uninterrupted run
  of the platform that saved it, to the same bar; the serialized bytes have the same length on both
  platforms.

Needs MinGW-w64 and Wine (`apt-get install gcc-mingw-w64-x86-64 wine64`) and FMUs built with
win64 binaries; where one is missing the module is skipped with one line saying what, or fails with
CI=true. Wine 8.0 lacks bcryptprimitives.dll (Rust's std calls its ProcessPrng): a test shim,
tests/harness/bcryptprimitives.c, goes beside the harness executable, never into an FMU.
"""
import json
import os
import shutil
import struct
import subprocess
import zipfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from fmpy import read_model_description

from conftest import ROOT, fmu_dir
from cosim import column
from test_fmu_cases import ATOL, CASES

HARNESS = ROOT / "tests" / "harness"
WORK = ROOT / "target" / "win64" / "wine-tests"
INSTALL = "apt-get install gcc-mingw-w64-x86-64 wine64"
# relative: |win64 - linux64| <= PLATFORM_RTOL x the variable's largest magnitude on linux64
PLATFORM_RTOL = 1e-12


def _ci():
    return os.environ.get("CI", "").lower() in ("true", "1")


def _missing(what):
    message = f"win64 FMUs not checked under Wine: {what}"
    if _ci():
        pytest.fail(f"{message} (CI=true)")
    pytest.skip(message)


def _wine():
    for candidate in ("wine64", "/usr/lib/wine/wine64", "wine"):
        found = shutil.which(candidate)
        if found:
            return found
    return None


def _hex(x):
    return struct.pack(">d", float(x)).hex()


def _real(bits):
    return struct.unpack(">d", bytes.fromhex(bits))[0]


class Platforms:
    """The two harness builds, the extracted binaries and the Wine environment."""

    def __init__(self):
        gcc, mingw, wine = shutil.which("gcc"), shutil.which("x86_64-w64-mingw32-gcc"), _wine()
        if not mingw or not wine:
            _missing(f"no {'MinGW-w64 (x86_64-w64-mingw32-gcc)' if not mingw else 'wine64'}; "
                     f"install with `{INSTALL}`")
        fmus = sorted(fmu_dir().glob("*.fmu"))
        without = [f.stem for f in fmus if f"binaries/win64/{f.stem}.dll" not in zipfile.ZipFile(f).namelist()]
        if without:
            _missing(f"{', '.join(without)} have no win64 binary (`cargo xtask build-fmus` says why)")
        if WORK.exists():
            shutil.rmtree(WORK)
        (WORK / "linux64").mkdir(parents=True)
        (WORK / "win64").mkdir()
        source = str(HARNESS / "fmi2_script.c")
        subprocess.run([gcc, "-O2", "-Wall", "-Werror", "-o", WORK / "linux64" / "fmi2_script", source,
                        "-ldl"], check=True)
        subprocess.run([mingw, "-O2", "-Wall", "-Werror", "-o", WORK / "win64" / "fmi2_script.exe",
                        source], check=True)
        subprocess.run([mingw, "-O2", "-Wall", "-Werror", "-shared", "-o",
                        WORK / "win64" / "bcryptprimitives.dll", str(HARNESS / "bcryptprimitives.c"),
                        "-ladvapi32"], check=True)
        for f in fmus:
            with zipfile.ZipFile(f) as z:
                for platform, ext in (("linux64", "so"), ("win64", "dll")):
                    (WORK / platform / f"{f.stem}.{ext}").write_bytes(
                        z.read(f"binaries/{platform}/{f.stem}.{ext}"))
        self.wine = wine
        self.env = dict(os.environ, WINEPREFIX=str(ROOT / "target" / "win64" / "wineprefix"),
                        WINEDEBUG="-all", WINEDLLOVERRIDES="bcryptprimitives=n,b")

    def library(self, platform, model_identifier):
        return f"./{model_identifier}.so" if platform == "linux64" else f"{model_identifier}.dll"

    def run(self, platform, jobs):
        """Runs (script text, name) jobs in one harness process; returns each job's output lines."""
        folder = WORK / platform
        args = []
        for text, name in jobs:
            (folder / f"{name}.txt").write_text(text)
            args += [f"{name}.txt", f"{name}.out"]
        exe = ["./fmi2_script"] if platform == "linux64" else [self.wine, "fmi2_script.exe"]
        done = subprocess.run(exe + args, cwd=folder, env=self.env, capture_output=True, text=True,
                              timeout=900)
        assert done.returncode == 0, f"{platform} harness failed:\n{done.stderr}"
        return [(folder / f"{name}.out").read_text().splitlines() for _, name in jobs]


class Case:
    """One reference case as a script, and the rows that script records."""

    def __init__(self, c, ref):
        fmu = fmu_dir() / f"{c.fmu}.fmu"
        md = read_model_description(str(fmu))
        self.c, self.ref, self.md = c, ref, md
        self.variables = {v.name: v for v in md.modelVariables}
        self.inputs, self.outputs = c.columns(fmu, ref)
        recorded = [v for v in md.modelVariables if v.causality in ("output", "local")]
        self.groups = [(cmd, [v for v in recorded if v.type in types])
                       for cmd, types in (("get", ("Real",)), ("geti", ("Integer", "Enumeration")),
                                          ("getb", ("Boolean",)))]
        self.groups = [(cmd, vs) for cmd, vs in self.groups if vs]
        self.names = [v.name for _, vs in self.groups for v in vs]
        self.t = column(ref, "time")
        self.mid = len(ref) // 2

    def _set(self, name, value):
        v = self.variables[name]
        if v.type == "Real":
            return f"real {v.valueReference} {_hex(value)}"
        if v.type == "Boolean":
            return f"boolean {v.valueReference} {int(bool(value))}"
        return f"integer {v.valueReference} {int(value)}"

    def _start(self, library, name):
        lines = [f"load {library}", f"instantiate {name} {self.md.guid} file:///nowhere"]
        lines += [self._set(n, x) for n, x in self.c.params.items()]
        lines += [f"setup {_hex(0.0)} {_hex(self.t[-1])}", "enter"]
        lines += [self._set(n, self.ref[0][n]) for n in self.inputs]
        lines.append("exit")
        return lines

    def _get(self):
        return [f"{cmd} " + " ".join(str(v.valueReference) for v in vs) for cmd, vs in self.groups]

    def _steps(self, first):
        lines = []
        for k in range(first, len(self.ref) - 1):
            lines += [self._set(n, self.ref[k][n]) for n in self.inputs]
            # FMPy's steps: from t_k to t_(k+1) of the reference grid
            lines.append(f"step {_hex(self.t[k])} {_hex(self.t[k + 1] - self.t[k])}")
            lines += self._get()
            if k + 1 == self.mid and first == 0:
                lines.append("save state.bin")
        return lines

    def full(self, library, name):
        """The whole case, saving the FMU state after step `mid` into `<name>.state`."""
        lines = self._start(library, name) + self._get() + self._steps(0) + ["free"]
        return "\n".join(lines).replace("save state.bin", f"save {name}.state") + "\n"

    def resume(self, library, name, state):
        """The case from the state `state` (saved after step `mid`) to the end."""
        lines = self._start(library, name) + [f"restore {state}"] + self._steps(self.mid) + ["free"]
        return "\n".join(lines) + "\n"

    def table(self, lines):
        """Output lines -> {name: array over rows} (Reals as floats, the others as ints)."""
        per_row = len(self.groups)
        assert len(lines) % per_row == 0
        values = {n: [] for n in self.names}
        for r in range(0, len(lines), per_row):
            for (cmd, vs), line in zip(self.groups, lines[r:r + per_row]):
                words = line.split()[1:]
                assert len(words) == len(vs)
                for v, w in zip(vs, words):
                    values[v.name].append(_real(w) if cmd == "get" else int(w))
        return {n: np.array(x) for n, x in values.items()}


def relative_difference(lin, win):
    """max |win - lin| / (the largest |lin|, 1 for a variable that stays at 0); NaN equals NaN."""
    both_nan = np.isnan(lin) & np.isnan(win)
    diff = np.where(both_nan, 0.0, np.abs(win - lin))
    magnitude = np.nanmax(np.abs(lin)) if np.any(np.isfinite(lin)) else 0.0
    return float(np.max(diff)) / (magnitude if magnitude > 0 else 1.0)


@pytest.fixture(scope="module")
def runs(reference):
    """Every case on both platforms: full runs, then each platform resumed from the other's state."""
    platforms = Platforms()
    cases = {c.id: Case(c, reference(c.case)) for c in CASES}

    def full(platform):
        jobs = [(k.full(platforms.library(platform, k.c.fmu), cid), cid) for cid, k in cases.items()]
        return platform, platforms.run(platform, jobs)

    def resume(platform, other):
        jobs = [(k.resume(platforms.library(platform, k.c.fmu), f"{cid}-resumed",
                          f"../{other}/{cid}.state"), f"{cid}-resumed") for cid, k in cases.items()]
        return platform, platforms.run(platform, jobs)

    with ThreadPoolExecutor(2) as pool:
        outs = dict(pool.map(full, ["linux64", "win64"]))
        resumed = dict(pool.map(lambda p: resume(*p), [("linux64", "win64"), ("win64", "linux64")]))
    result = {}
    for i, (cid, k) in enumerate(cases.items()):
        result[cid] = {
            "case": k,
            "linux64": k.table(outs["linux64"][i]),
            "win64": k.table(outs["win64"][i]),
            "linux64 from win64 state": k.table(resumed["linux64"][i]),
            "win64 from linux64 state": k.table(resumed["win64"][i]),
            "states": [(WORK / p / f"{cid}.state").read_bytes() for p in ("linux64", "win64")],
        }
    write_differences(result)
    return result


def write_differences(result):
    """target/win64/wine-tests/differences.json: per FMU, the largest relative difference over its
    cases and recorded variables, and whether every bit agreed."""
    per_fmu = {}
    for cid, r in result.items():
        k = r["case"]
        worst = max(relative_difference(r["linux64"][n].astype(float), r["win64"][n].astype(float))
                    for n in k.names)
        identical = all(np.array_equal(r["linux64"][n].view(np.int64) if r["linux64"][n].dtype == float
                                       else r["linux64"][n],
                                       r["win64"][n].view(np.int64) if r["win64"][n].dtype == float
                                       else r["win64"][n]) for n in k.names)
        entry = per_fmu.setdefault(k.c.fmu, {"cases": [], "max_relative_difference": 0.0,
                                             "identical_bits": True})
        entry["cases"].append(cid)
        entry["max_relative_difference"] = max(entry["max_relative_difference"], worst)
        entry["identical_bits"] &= identical
    (WORK / "differences.json").write_text(json.dumps(per_fmu, indent=1, sort_keys=True) + "\n")


def _params(cases):
    return [pytest.param(c.id, id=c.id) for c in cases]


@pytest.mark.parametrize("cid", _params(CASES))
def test_linux64_harness_matches_rust_model(cid, runs):
    r = runs[cid]
    k = r["case"]
    assert len(r["linux64"][k.names[0]]) == len(k.ref)
    for name in k.outputs:
        expected = column(k.ref, name)
        np.testing.assert_allclose(r["linux64"][name], expected, rtol=0,
                                   atol=ATOL * k.c.scale(k.ref, name), err_msg=name)
    for name in k.c.booleans:
        np.testing.assert_array_equal(r["linux64"][name].astype(float), column(k.ref, name),
                                      err_msg=name)


def _assert_platforms_agree(lin, win, names, what):
    for name in names:
        assert len(lin[name]) == len(win[name]), f"{what}: {name}"
        if lin[name].dtype != float:
            np.testing.assert_array_equal(win[name], lin[name], err_msg=f"{what}: {name}")
            continue
        d = relative_difference(lin[name], win[name])
        assert d <= PLATFORM_RTOL, f"{what}: {name} differs by {d:.3g} of its magnitude"


@pytest.mark.parametrize("cid", _params(CASES))
def test_win64_matches_linux64(cid, runs):
    r = runs[cid]
    _assert_platforms_agree(r["linux64"], r["win64"], r["case"].names, f"{cid}, win64 vs linux64")


@pytest.mark.parametrize("cid", _params(CASES))
def test_state_crosses_platforms(cid, runs):
    r = runs[cid]
    k = r["case"]
    linux_state, win_state = r["states"]
    assert len(linux_state) == len(win_state) > 0
    tail = slice(k.mid + 1, None)
    for saved, restored in (("linux64", "win64 from linux64 state"),
                            ("win64", "linux64 from win64 state")):
        uninterrupted = {n: x[tail] for n, x in r[saved].items()}
        assert len(r[restored][k.names[0]]) == len(k.ref) - 1 - k.mid
        _assert_platforms_agree(uninterrupted, r[restored], k.names, f"{cid}, {restored}")
