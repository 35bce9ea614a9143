"""Campaign throughput, per-run fixed cost and warm-up forks, measured with `shipsim campaign`.

Three measurements on systems/rrs.toml (7 FMUs, h = 0.05 s), each from the campaign's own
summary ("runs/s") or from wall time around the command:

1. Throughput: the same campaign of RRS runs (--runs, of --stop s each) with --jobs 1 and
   --jobs 2; runs per second and the scaling.
2. Per-run fixed cost: the median of the runs' own wall times (the run table's wall_time:
   validation, instantiation, initialization, termination, freeing) in a campaign whose runs
   stop after two macro steps (0.1 s: the slowest instances step every 2 base steps, and a run
   shorter than one of their steps is refused), as a share of the median wall time of full 1200 s RRS runs;
   once for systems/rrs.toml (its FMUs' own initialization included: Waves discretizes its
   spectrum there) and once for the master alone (7 instances of the trivial C test FMU of
   bench_master.py, chained).
3. Warm-up forks: a slice of the RRS polar (campaigns/rrs_polar.toml: 9 directions, 2 arms,
   --fork-seeds seeds, H_s = 3 m), with fork_at = 200 s against cold runs, --jobs 2.

Prints a Markdown section on stdout (cargo xtask bench writes it into docs/bench.md).
"""
import argparse
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
SYSTEM = ROOT / "systems" / "rrs.toml"

KPI = """
[[kpis]]
name = "roll_var"
variable = "ship.roll"
stat = "variance"
window = [{w0}, {w1}]
"""


def campaign(stop, runs, fork_at=None, window=(0.0, 1e9)):
    text = f'system = "{SYSTEM}"\nstop_time = {stop!r}\nseed = 3\n'
    if fork_at is not None:
        text += f"fork_at = {fork_at!r}\n"
    text += f'[replications]\ncount = {runs}\nseeds = ["waves.seed", "wind.seed", "sensors.seed"]\n'
    return text + KPI.format(w0=window[0], w1=window[1])


def polar_slice(seeds, fork):
    text = (ROOT / "campaigns" / "rrs_polar.toml").read_text()
    text = text.replace('system = "../systems/rrs.toml"', f'system = "{SYSTEM}"')
    text = text.replace("values = [2.0, 3.0, 4.0]", "values = [3.0]")
    text = text.replace("count = 10", f"count = {seeds}")
    if not fork:
        text = text.replace("fork_at = 200.0", "")
    return text


def median_wall(out):
    import csv
    import statistics
    with open(out / "runs.csv") as f:
        return statistics.median(float(r["wall_time"]) for r in csv.DictReader(f))


def trivial_campaign(d, runs):
    """7 chained instances of the C test FMU, one 0.05 s step per run."""
    sys.path.insert(0, str(ROOT / "master" / "bench"))
    import bench_master
    bench_master.build_fmu(d)
    (d / "chain7.toml").write_text(bench_master.system_toml(7, 1, 0.05))
    return (f'system = "{d / "chain7.toml"}"\n[[factors]]\nname = "k"\nvariable = "a0.k"\n'
            f'linspace = [1, 2, {runs}]\n[[kpis]]\nname = "y"\nvariable = "a6.y"\nstat = "final"\n')


def run(exe, text, d, name, jobs):
    f = d / f"{name}.toml"
    f.write_text(text)
    out = d / f"{name}.out"
    t = time.perf_counter()
    r = subprocess.run([exe, "campaign", "run", "-j", str(jobs), "-o", str(out), str(f)],
                       capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t
    m = re.search(r"(\d+) of (\d+) runs (?:of shard \S+ )?ran \((\d+) failed\)", r.stderr)
    ran, failed = int(m.group(1)), int(m.group(3))
    assert failed == 0, r.stderr
    return wall, ran


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shipsim", default=os.environ.get("SHIPSIM_BIN", str(ROOT / "target/release/shipsim")))
    ap.add_argument("--runs", type=int, default=40)
    ap.add_argument("--stop", type=float, default=300.0)
    ap.add_argument("--fork-seeds", type=int, default=2)
    a = ap.parse_args()
    exe = a.shipsim
    with tempfile.TemporaryDirectory() as td:
        d = pathlib.Path(td)
        j1, j2 = [], []
        for i in range(3):
            j1.append(run(exe, campaign(a.stop, a.runs), d, f"j1_{i}", 1))
            j2.append(run(exe, campaign(a.stop, a.runs), d, f"j2_{i}", 2))
        (w1, n1), (w2, n2) = min(j1), min(j2)
        run(exe, campaign(0.1, a.runs), d, "fixed", 1)
        fixed = median_wall(d / "fixed.out")
        run(exe, trivial_campaign(d, a.runs), d, "trivial", 1)
        trivial = median_wall(d / "trivial.out")
        run(exe, campaign(1200.0, 4), d, "full", 1)
        full = median_wall(d / "full.out")
        # Alternating, best of 3 each (single timings of a few seconds vary by 10-20 % here).
        cold, fork = [], []
        for i in range(3):
            cold.append(run(exe, polar_slice(a.fork_seeds, False), d, f"cold{i}", 2))
            fork.append(run(exe, polar_slice(a.fork_seeds, True), d, f"fork{i}", 2))
        (cold_w, cold_n), (fork_w, fork_n) = min(cold), min(fork)
    r1, r2 = n1 / w1, n2 / w2
    print(f"## Campaigns ({os.cpu_count()} cores; systems/rrs.toml, 7 FMUs, h = 0.05 s)\n")
    print("| measurement | value |")
    print("|---|---|")
    print(f"| throughput, {a.runs} runs of {a.stop:g} s, --jobs 1 | {r1:.2f} runs/s |")
    print(f"| throughput, same campaign, --jobs 2 | {r2:.2f} runs/s |")
    print(f"| scaling --jobs 2 / --jobs 1 | {r2 / r1:.2f}x |")
    print(f"| one 1200 s RRS run (median wall time) | {full * 1e3:.0f} ms |")
    print(f"| master's per-run fixed cost, 7 trivial FMUs (validate, instantiate, initialize, terminate, free) | {trivial * 1e3:.2f} ms |")
    print(f"| master's fixed cost / RRS run | {100 * trivial / full:.2f} % |")
    print(f"| RRS per-run fixed cost, its FMUs' own initialization included | {fixed * 1e3:.2f} ms |")
    print(f"| RRS fixed cost / RRS run | {100 * fixed / full:.2f} % |")
    print(f"| RRS polar slice ({cold_n} runs, H_s = 3 m, {a.fork_seeds} seeds), cold, --jobs 2 | {cold_w:.2f} s |")
    print(f"| same, warm-up shared to 200 s (fork_at) | {fork_w:.2f} s |")
    print(f"| warm-up fork speed-up | {cold_w / fork_w:.2f}x |")
    print("\nThroughput and the polar slice: wall time around `shipsim campaign run` (process "
          "start, FMU loading and the tables included; best of 3). A fork saves "
          "the first 200 s of the 1200 s of stepping of every run but the group's first; each "
          "run still pays its FMUs' initialization (the RRS fixed cost above), so about "
          "1.1-1.2x is expected.")


if __name__ == "__main__":
    main()
