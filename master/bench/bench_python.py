"""The Python package's overhead: the RRS system run from Python and from the CLI.

systems/rrs.toml (7 FMUs, h = 0.05 s) for --stop seconds, without output, alternately:

- CLI: `shipsim run --no-output --profile=json --profile-every 1000003`: the JSON line gives
  the step loop's wall time at full precision (timing 1 macro step in a million costs
  nothing measurable);
- Python: `System.run(stop_time, variables=[])` on a System loaded once (its FMUs stay
  loaded, as in a notebook): the wall time of the whole call, i.e. validation, instantiation,
  initialization, the step loop, termination, the GIL hand-offs and the conversion of the
  result.

The issue's bound: the Python call's median time beyond the CLI's median step-loop time is at
most 5 ms + 2 % of the latter. Prints a Markdown section on stdout.
"""
import argparse
import json
import os
import pathlib
import statistics
import subprocess
import time

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
SYSTEM = ROOT / "systems" / "rrs.toml"


def cli_loop(shipsim_bin, stop):
    out = subprocess.run(
        [shipsim_bin, "run", str(SYSTEM), "--no-output", "--stop-time", repr(stop), "-q",
         "--profile=json", "--profile-every", "1000003"],
        check=True, capture_output=True, text=True).stdout
    return json.loads(out.splitlines()[-1])["wall_s"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=10)
    ap.add_argument("--stop", type=float, default=1200.0)
    args = ap.parse_args()
    shipsim_bin = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))

    begin = time.perf_counter()
    system = shipsim.System.load(SYSTEM)
    load = time.perf_counter() - begin
    system.run(stop_time=1.0, variables=[])  # warm the caches once, as the CLI's loads do
    cli, py, py_loop = [], [], []
    for _ in range(args.runs):
        cli.append(cli_loop(shipsim_bin, args.stop))
        begin = time.perf_counter()
        cols = system.run(stop_time=args.stop, variables=[], as_frame=False)
        py.append(time.perf_counter() - begin)
        py_loop.append(cols.summary["wall_time"])
    c, p, pl = (statistics.median(x) for x in (cli, py, py_loop))
    excess = p - c
    bound = 5e-3 + 0.02 * c
    verdict = "within" if excess <= bound else "OVER"
    ms = lambda x: f"{x * 1e3:.2f} ms"  # noqa: E731
    print("## The Python package: overhead over the CLI (master/bench/bench_python.py)\n")
    print(f"systems/rrs.toml, {args.stop:g} s, no output; median of {args.runs} runs each, "
          "alternating CLI and Python.\n")
    print("| measure | median |")
    print("|---|---|")
    print(f"| CLI step loop (`shipsim run`, its own wall time) | {ms(c)} |")
    print(f"| Python `System.run` call (whole call) | {ms(p)} |")
    print(f"| Python step loop (the same run's own wall time) | {ms(pl)} |")
    print(f"| Python call beyond the CLI step loop | {ms(excess)} |")
    print(f"| bound: 5 ms + 2 % of the CLI step loop | {ms(bound)} ({verdict}) |")
    print(f"| `System.load` once (FMUs unpacked and loaded) | {ms(load)} |")
    print()
    print("Each run, CLI / Python call [ms]: "
          + ", ".join(f"{a * 1e3:.1f}/{b * 1e3:.1f}" for a, b in zip(cli, py)))
    print()


if __name__ == "__main__":
    main()
