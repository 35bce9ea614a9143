"""The cost of crash isolation: the RRS system (systems/rrs.toml) in process and with every
instance in its own `shipsim fmu-host` process (`shipsim run --isolate`, docs/isolation.md).

Each mode runs --repeat times (default 5), alternating, without CSV output, over --stop-time
simulated seconds (default 120 s: 2,400 macro steps of 0.05 s), unpinned (an isolated run is
seven processes). Two figures per mode, each the minimum over the runs (the least disturbed
run on a shared machine):

- the step loop's wall time per macro step, as the run's summary reports it
  (`--profile=json`: us_per_macro_step);
- the CPU time per macro step of the whole run, master and hosts together (user + system
  time of the finished processes, from getrusage(RUSAGE_CHILDREN); it includes loading and
  initialization, which are the same few milliseconds in both modes at this length).

The isolated mode costs one round trip over a pipe per FMI call (each instance's set, doStep
and get of a macro step), so its cost per macro step is that of the round trips, whatever the
models' own cost; the ratio is large for a system of fast models like this one.

Prints a Markdown section on stdout (cargo xtask bench appends it to docs/bench.md).

Usage (from the repository root, after `cargo build --release -p shipsim` and the FMUs):
    python master/bench/bench_isolated.py [--repeat 5] [--stop-time 120]
"""
import argparse
import json
import os
import pathlib
import resource
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]
SYSTEM = ROOT / "systems" / "rrs.toml"


def one_run(exe, stop_time, isolate):
    cmd = [exe, "run", str(SYSTEM), "--no-output", "--profile=json", "-q",
           "--stop-time", str(stop_time)]
    if isolate:
        cmd.append("--isolate")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    summary = json.loads(r.stdout.strip().splitlines()[-1])
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    steps = summary["macro_steps"]
    return summary["us_per_macro_step"], cpu * 1e6 / steps, steps


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--stop-time", type=float, default=120.0)
    args = ap.parse_args()
    exe = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
    results = {False: [], True: []}
    steps = 0
    for _ in range(args.repeat):
        for isolate in (False, True):
            wall, cpu, steps = one_run(exe, args.stop_time, isolate)
            results[isolate].append((wall, cpu))
    best = {k: (min(w for w, _ in v), min(c for _, c in v)) for k, v in results.items()}
    print("## Crash isolation: RRS in process and isolated (master/bench/bench_isolated.py)\n")
    print(f"systems/rrs.toml, {steps} macro steps, 7 instances, min of {args.repeat} runs "
          "per mode (alternating, unpinned); wall: the step loop per macro step; CPU: the "
          "whole run (master and FMU hosts) per macro step.\n")
    print("| mode | wall per macro step [us] | CPU per macro step [us] |")
    print("|---|---:|---:|")
    for isolate, name in ((False, "in process"), (True, "`--isolate` (7 host processes)")):
        w, c = best[isolate]
        print(f"| {name} | {w:.2f} | {c:.2f} |")
    (w0, c0), (w1, c1) = best[False], best[True]
    print(f"\nIsolated / in process: step loop wall time {w1 / w0:.0f}x; "
          f"{c1 - c0:.1f} us more CPU per macro step (master and hosts; about 3 FMI calls, "
          "each a round trip over a pipe, per instance and macro step).\n")


if __name__ == "__main__":
    main()
