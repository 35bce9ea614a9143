"""Real time: how late a paced run's macro steps are.

`shipsim run systems/rrs.toml --real-time` (20 s at 1x real time) and `--real-time-factor 10`
(100 s in 10 s of wall time), h = 0.05 s: every communication point waits for its absolute
deadline; its lateness (the time from the deadline to the end of the wait) is measured in a
bounded log histogram and a step that ends after its deadline is an overrun (counted, never
skipped). The figures are parsed from the run's summary (`paced at Xx real time: lateness
median m ms, p99 p ms, max x ms; n late steps (overruns)`). Prints a Markdown section on
stdout.
"""
import argparse
import os
import pathlib
import re
import subprocess
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
SYSTEM = ROOT / "systems" / "rrs.toml"
SUMMARY = re.compile(r"paced at (\S+)x real time: lateness median ([\d.]+) ms, p99 ([\d.]+) ms, "
                     r"max ([\d.]+) ms; (\d+) late steps \(overruns\)")
STEPS = re.compile(r"in ([\d.]+) s wall, (\d+) macro steps")


def paced(shipsim, cwd, factor, stop):
    begin = time.perf_counter()
    err = subprocess.run([shipsim, "run", str(SYSTEM), "--real-time-factor", str(factor), "--stop-time",
                          str(stop), "-o", "paced.csv", "--journal", "paced.jsonl"],
                         cwd=cwd, check=True, capture_output=True, text=True).stderr
    whole = time.perf_counter() - begin
    m, s = SUMMARY.search(err), STEPS.search(err)
    if not (m and s):
        raise SystemExit(f"no pacing summary in:\n{err}")
    return {"factor": factor, "stop": stop, "whole": whole, "wall": float(s.group(1)), "steps": int(s.group(2)),
            "median": float(m.group(2)), "p99": float(m.group(3)), "max": float(m.group(4)),
            "overruns": int(m.group(5))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seconds", type=float, default=20.0, help="simulated seconds at 1x")
    args = ap.parse_args()
    shipsim = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
    with tempfile.TemporaryDirectory() as d:
        runs = [paced(shipsim, d, 1, args.seconds), paced(shipsim, d, 10, 100.0)]
    print("## Real time: lateness of paced runs (master/bench/bench_realtime.py)\n")
    print(f"systems/rrs.toml (7 FMUs, h = 0.05 s) run with `shipsim run --real-time-factor X`, the CSV and "
          f"the journal written; {os.cpu_count()} cores. Lateness: from a communication point's deadline to "
          f"the end of its wait; an overrun is a step that ended after its deadline.\n")
    print("| factor | simulated | macro steps | paced wall | whole process | lateness median | p99 | max | overruns |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in runs:
        print(f"| {r['factor']}x | {r['stop']:g} s | {r['steps']} | {r['wall']:.3f} s | {r['whole']:.3f} s | "
              f"{r['median']:.3f} ms | {r['p99']:.3f} ms | {r['max']:.3f} ms | {r['overruns']} |")
    print()
    print("Without pacing the step loop is unchanged: a plain run takes the ordinary run path, whose "
          "overhead is in the first section (bench_master.py) and the RRS system's time in "
          "bench_systems.py.\n")


if __name__ == "__main__":
    main()
