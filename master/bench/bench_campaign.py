"""Campaign throughput, per-run fixed cost and warm-up forks, measured with `shipsim campaign`.

Three measurements on systems/rrs.toml (7 FMUs, h = 0.05 s), each from the campaign's own
summary ("runs/s") or from wall time around the command:

1. Throughput: the same campaign of RRS runs (--runs, of --stop s each) with --jobs 1 and
   --jobs 2; runs per second and the scaling.
2. Per-run fixed cost: a campaign whose runs stop after one macro step (validation,
   instantiation, initialization, termination, freeing, and the durable journal append), as
   a share of one full 1200 s RRS run (its wall time per run in the same way, --jobs 1).
3. Warm-up forks: a slice of the RRS polar (campaigns/rrs_polar.toml: 9 directions, 2 arms,
   --fork-seeds seeds, H_s = 3 m), with fork_at = 200 s against cold runs, --jobs 2.

Prints a Markdown section on stdout (cargo xtask bench writes it into docs/bench.md).
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


def run(exe, text, d, name, jobs):
    f = d / f"{name}.toml"
    f.write_text(text)
    out = d / f"{name}.out"
    t = time.perf_counter()
    r = subprocess.run([exe, "campaign", "run", "-j", str(jobs), "-o", str(out), str(f)],
                       capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t
    m = re.search(r"(\d+) of (\d+) runs in this shard ran \((\d+) failed\)", r.stderr)
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
        w1, n1 = run(exe, campaign(a.stop, a.runs), d, "j1", 1)
        w2, n2 = run(exe, campaign(a.stop, a.runs), d, "j2", 2)
        fixed_w, fixed_n = run(exe, campaign(0.05, a.runs), d, "fixed", 1)
        full_w, full_n = run(exe, campaign(1200.0, 4), d, "full", 1)
        cold_w, cold_n = run(exe, polar_slice(a.fork_seeds, False), d, "cold", 2)
        fork_w, fork_n = run(exe, polar_slice(a.fork_seeds, True), d, "fork", 2)
    r1, r2 = n1 / w1, n2 / w2
    fixed, full = fixed_w / fixed_n, full_w / full_n
    print(f"## Campaigns ({os.cpu_count()} cores; systems/rrs.toml, 7 FMUs, h = 0.05 s)\n")
    print("| measurement | value |")
    print("|---|---|")
    print(f"| throughput, {a.runs} runs of {a.stop:g} s, --jobs 1 | {r1:.2f} runs/s |")
    print(f"| throughput, same campaign, --jobs 2 | {r2:.2f} runs/s |")
    print(f"| scaling --jobs 2 / --jobs 1 | {r2 / r1:.2f}x |")
    print(f"| per-run fixed cost (1-step runs: validate, instantiate, initialize, free, journal) | {fixed * 1e3:.2f} ms |")
    print(f"| one 1200 s RRS run | {full * 1e3:.0f} ms |")
    print(f"| fixed cost / RRS run | {100 * fixed / full:.2f} % |")
    print(f"| RRS polar slice ({cold_n} runs, H_s = 3 m, {a.fork_seeds} seeds), cold, --jobs 2 | {cold_w:.2f} s |")
    print(f"| same, warm-up shared to 200 s (fork_at) | {fork_w:.2f} s |")
    print(f"| warm-up fork speed-up | {cold_w / fork_w:.2f}x |")
    print("\nWall time around `shipsim campaign run` (process start, FMU loading and the tables "
          "included); the fork speed-up is bounded by 1200/(1200-200) = 1.2x for the runs' "
          "own stepping.")


if __name__ == "__main__":
    main()
