"""Master overhead per FMU-step: shipsim vs libcosim (libcosimpy) vs an FMPy loop, same FMUs, same run.

The FMU is master/tests/c/testfmu.c (one multiply-add per step, so the figures are master and
FMI-call overhead), compiled here with gcc. Systems: 1 FMU alone, and a chain of N FMUs with
N-1 connections (a_i.y -> a_(i+1).u), base step 0.01 s. shipsim reports its step-loop time
(after initialization); libcosim is timed around simulate_until; FMPy is a Jacobi loop in
Python over fmpy.fmi2.FMU2Slave (FMPy has no multi-FMU master), timed around the loop.

shipsim runs --shipsim-steps macro steps (default 1e7), the others --steps (1e5; FMPy
--fmpy-steps, 1e4), so that each timing is long enough to be precise.

Usage (from the repository root, after `cargo build --release -p shipsim`):
    python master/bench/bench_master.py [--steps 100000] [--shipsim-steps 10000000] [--fmus 10] [--repeat 3]
Needs: gcc, fmpy, libcosimpy.
"""
import argparse
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time
import zipfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
GUID = "{shipsim-test-fmu}"


def build_fmu(d: pathlib.Path) -> pathlib.Path:
    so = d / "testfmu.so"
    subprocess.run(["gcc", "-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-o", str(so),
                    str(ROOT / "master/tests/c/testfmu.c"), "-lm"], check=True)
    md = (ROOT / "master/tests/c/testfmu.xml").read_text().replace("FMI_VERSION", "2.0").replace("GUID", GUID)
    fmu = d / "testfmu.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.writestr("modelDescription.xml", md)
        z.write(so, "binaries/linux64/testfmu.so")
    return fmu


def system_toml(n: int, steps: int, h: float) -> str:
    conns = ", ".join(f'"a{i}.y -> a{i + 1}.u"' for i in range(n - 1))
    s = f"connections = [{conns}]\n[simulation]\nstop_time = {steps * h!r}\nstep_size = {h!r}\n"
    for i in range(n):
        s += f'[[instances]]\nname = "a{i}"\nfmu = "testfmu.fmu"\n'
        if i == 0:
            s += "parameters = { u = 1.0 }\n"
    s += "[output]\nvariables = []\n"
    return s


def bench_shipsim(exe, system):
    """The step-loop wall time shipsim reports (ms resolution: give it enough steps)."""
    r = subprocess.run([exe, "run", str(system)], capture_output=True, text=True, check=True)
    m = re.search(r"wall time ([0-9.]+) s \(step loop\)", r.stderr)
    return float(m.group(1))


def bench_libcosim(osp, steps, h):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_osp_config_file(str(osp))
    ex.step(1)  # initialization and the first step outside the timing
    t = time.perf_counter()
    ok = ex.simulate_until(int(round(steps * h * 1e9)))
    w = time.perf_counter() - t
    assert ok
    return w * steps / (steps - 1)


def bench_fmpy(fmu, n, steps, h):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(str(fmu))
    d = extract(str(fmu))
    slaves = []
    for i in range(n):
        s = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier="testfmu", instanceName=f"a{i}")
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        slaves.append(s)
    slaves[0].setReal([0], [1.0])
    t = time.perf_counter()
    for k in range(steps):
        tk = k * h
        ys = [s.getReal([1])[0] for s in slaves]
        for i in range(1, n):
            slaves[i].setReal([0], [ys[i - 1]])
        for s in slaves:
            s.doStep(tk, h)
    w = time.perf_counter() - t
    for s in slaves:
        s.terminate()
        s.freeInstance()
    return w


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--fmpy-steps", type=int, default=10_000)
    # shipsim is thousands of times faster: 100x the steps keep its ms-resolution wall time
    # (about 0.1-2 s) precise to about 1 %.
    ap.add_argument("--shipsim-steps", type=int, default=10_000_000)
    ap.add_argument("--fmus", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--shipsim", default=os.environ.get("SHIPSIM_BIN", str(ROOT / "target/release/shipsim")))
    a = ap.parse_args()
    h = 0.01
    with tempfile.TemporaryDirectory() as td:
        d = pathlib.Path(td)
        fmu = build_fmu(d)
        print(f"machine: {os.cpu_count()} cores; macro steps of {h} s; FMU: master/tests/c/testfmu.c")
        print(f"{'master':<10} {'FMUs':>4} {'macro steps':>11} {'wall [s]':>9} {'us/macro step':>14} {'us/FMU-step':>12}")
        results = {}
        for n in sorted({1, a.fmus}):
            sysf = d / f"chain{n}.toml"
            sysf.write_text(system_toml(n, a.steps, h))
            long = d / f"chain{n}_long.toml"
            long.write_text(system_toml(n, a.shipsim_steps, h))
            osp = d / f"chain{n}.xml"
            subprocess.run([a.shipsim, "export-osp", str(sysf), "-o", str(osp)], check=True, capture_output=True)
            for name, fn, steps in [
                ("shipsim", lambda: bench_shipsim(a.shipsim, long), a.shipsim_steps),
                ("libcosim", lambda: bench_libcosim(osp, a.steps, h), a.steps),
                ("fmpy-loop", lambda: bench_fmpy(fmu, n, a.fmpy_steps, h), a.fmpy_steps),
            ]:
                w = min(fn() for _ in range(a.repeat))
                per_macro = w / steps * 1e6
                per_fmu = per_macro / n
                results[(name, n)] = per_fmu
                print(f"{name:<10} {n:>4} {steps:>11} {w:>9.3f} {per_macro:>14.4f} {per_fmu:>12.4f}")
        for n in sorted({1, a.fmus}):
            r = results[("libcosim", n)] / results[("shipsim", n)]
            f = results[("fmpy-loop", n)] / results[("shipsim", n)]
            print(f"{n} FMU(s): shipsim is {r:.0f}x less overhead per FMU-step than libcosim, {f:.0f}x less than the FMPy loop")


if __name__ == "__main__":
    sys.exit(main())
