"""Every system of systems/: speed and where its time goes, from `shipsim run --profile=json`.

Each system runs --repeat times (default 5) without CSV output (`--no-output`), pinned to one
core (`taskset -c 1`; without taskset, or on one core, unpinned and the table says so), twice
over; every figure is the median over the runs of its set:

- with the default profile (1 in 127 macro steps timed, under 1 % overhead): the real-time
  factor and µs per macro step (simulated time and the step loop's wall time over all steps, as
  the run's summary reports them), the profile's own cost, and how much of the measured step
  loop the sample accounts for (well below 100 % when an FMU does costly work on few steps,
  which a sample of 1 in 127 catches by chance);
- with every macro step timed (`--profile-every 1`, about 10 % slower, shares corrected for the
  clock reads): the most expensive instance and its share, and the master's share. The most
  expensive instance is the one with the largest median share.

See master/src/run/profile.rs for the method.

The pure-Rust model loop of the RRS system (the `rrs-model-loop` binary of system-tests:
--model-loop, $SHIPSIM_MODEL_LOOP_BIN or target/release/rrs-model-loop; it prints one JSON line
{"stop_time": ..., "macro_steps": ..., "wall_s": ...} for its step loop) runs in pairs with the
FMU system, pinned alike, back to back; the section gives the median of the pairs' ratios of
step-loop time per macro step.

Prints a Markdown section on stdout (cargo xtask bench writes it into docs/bench.md).

Usage (from the repository root, after `cargo build --release -p shipsim` and the FMUs):
    python master/bench/bench_systems.py [--repeat 5] [--only rrs ...]
"""
import argparse
import json
import os
import pathlib
import shutil
import statistics
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]
CORE = 1


def pinning():
    """The command prefix that pins a process to one core, and a note for the table."""
    if shutil.which("taskset") is None:
        return [], "not pinned (taskset is not installed)"
    if (os.cpu_count() or 1) <= CORE:
        return [], f"not pinned (no core {CORE})"
    return ["taskset", "-c", str(CORE)], f"pinned to core {CORE} (`taskset -c {CORE}`)"


def run_system(exe, pin, system, every=None, stop_time=None):
    cmd = pin + [exe, "run", str(system), "--no-output", "--profile=json", "-q"]
    if every is not None:
        cmd += ["--profile-every", str(every)]
    if stop_time is not None:
        cmd += ["--stop-time", repr(stop_time)]
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def summarize(runs, every_step):
    """The medians of one system's runs: speed from `runs`, shares from `every_step`."""
    med = statistics.median
    names = [i["name"] for i in every_step[0]["profile"]["instances"]]
    shares = {n: med(r["profile"]["instances"][j]["share"] for r in every_step)
              for j, n in enumerate(names)}
    top = max(names, key=lambda n: shares[n])
    return {
        "instances": len(names),
        "macro_steps": runs[0]["macro_steps"],
        "rtf": med(r["real_time_factor"] for r in runs),
        "us": med(r["us_per_macro_step"] for r in runs),
        "top": top,
        "top_share": shares[top],
        "master_share": med(r["profile"]["master_share"] for r in every_step),
        "overhead": med(r["profile"]["overhead_share"] for r in runs),
        "covered": med(100 * r["profile"]["sampled_us_per_step"] / r["profile"]["loop_us_per_step"]
                       for r in runs),
        "end_time": runs[0]["end_time"] - runs[0]["start_time"],
    }


def model_loop_bin(arg):
    """The rrs-model-loop binary: --model-loop, $SHIPSIM_MODEL_LOOP_BIN or the release build."""
    exe = pathlib.Path(arg or os.environ.get("SHIPSIM_MODEL_LOOP_BIN")
                       or ROOT / "target/release/rrs-model-loop")
    if not exe.is_file():
        raise SystemExit(f"{exe} not found: cargo build --release -p system-tests --bin rrs-model-loop")
    return exe


def run_model_loop(exe, pin):
    r = subprocess.run(pin + [str(exe)], capture_output=True, text=True, cwd=ROOT)
    if r.returncode != 0:
        raise SystemExit(f"{exe} failed:\n{r.stderr}")
    line = [l for l in r.stdout.splitlines() if l.strip().startswith("{")][-1]
    return json.loads(line)


def model_loop_section(exe, shipsim, pin, repeat):
    """The pure-Rust model loop against the FMU system rrs (Markdown lines). The two run in
    pairs, back to back, so that a slow phase of a shared machine hits both; the ratio is the
    median of the pairs' ratios, and the per-pair ratios are listed."""
    out = ["", "### RRS: FMU system against the pure-Rust model loop", ""]
    system = ROOT / "systems/rrs.toml"
    pairs = []
    for _ in range(repeat):
        fmu = run_system(shipsim, pin, system)
        loop = run_model_loop(exe, pin)
        pairs.append((fmu["us_per_macro_step"], loop["wall_s"] * 1e6 / loop["macro_steps"], loop))
    med = statistics.median
    fmu_us, model_us = med(p[0] for p in pairs), med(p[1] for p in pairs)
    ratios = sorted(p[0] / p[1] for p in pairs)
    steps, stop = pairs[0][2]["macro_steps"], pairs[0][2]["stop_time"]
    out += [
        "| loop | simulated | macro steps | µs / macro step | real-time factor |",
        "|---|---|---|---|---|",
        f"| FMU system (`shipsim run systems/rrs.toml --no-output`) | {stop:g} s | {steps} "
        f"| {fmu_us:.3f} | {stop / (fmu_us * 1e-6 * steps):,.0f} |",
        f"| pure-Rust model loop (`{exe.name}`) | {stop:g} s | {steps} | {model_us:.3f} "
        f"| {stop / (model_us * 1e-6 * steps):,.0f} |",
        "",
        f"FMU system / model loop, step-loop time per macro step: **{med(ratios):.3f}x** (median "
        f"of {repeat} pairs run back to back; the pairs: {', '.join(f'{r:.2f}' for r in ratios)}).",
    ]
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shipsim", default=os.environ.get("SHIPSIM_BIN", str(ROOT / "target/release/shipsim")))
    ap.add_argument("--model-loop", default=None, help="the rrs-model-loop binary")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--only", nargs="*", help="system names (file stems) to run")
    a = ap.parse_args()
    pin, pin_note = pinning()
    systems = sorted((ROOT / "systems").glob("*.toml"))
    if a.only:
        systems = [s for s in systems if s.stem in a.only]
    rows = {}
    for s in systems:
        runs = [run_system(a.shipsim, pin, s) for _ in range(a.repeat)]
        every_step = [run_system(a.shipsim, pin, s, every=1) for _ in range(a.repeat)]
        rows[s.stem] = summarize(runs, every_step)
    print(f"## Systems (master/bench/bench_systems.py)\n")
    print(f"Every system of systems/ without CSV output (`shipsim run --no-output --profile=json`), "
          f"{pin_note}; each figure is the median of {a.repeat} runs. Real-time factor and µs per "
          "macro step: the step loop's wall time over all steps, with the default profile (1 in "
          "127 macro steps timed); its cost is the next column, and the share of the measured "
          "step loop that its sample accounts for the one after (far below 100 % where an FMU "
          "does costly work on few steps). Shares: from separate runs that time every macro step "
          "(`--profile-every 1`, corrected for the clock reads); an instance's share is its "
          "fmi2DoStep and get/set, the master's is everything else in the step loop (recording "
          "is off here). Method: master/src/run/profile.rs.\n")
    print("| system | instances | macro steps | real-time factor | µs / macro step "
          "| profile cost | sample / measured | most expensive instance | its share | master's share |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        print(f"| {name} | {r['instances']} | {r['macro_steps']} | {r['rtf']:,.0f} | {r['us']:.3f} "
              f"| {r['overhead']:.2f} % | {r['covered']:.0f} % | {r['top']} | {r['top_share']:.1f} % "
              f"| {r['master_share']:.1f} % |")
    print("\nProfile cost: the profile's own clock reads (their number times the measured cost of "
          "one) as a share of the step loop.")
    if a.only is None or "rrs" in a.only:
        exe = model_loop_bin(a.model_loop)
        print("\n".join(model_loop_section(exe, a.shipsim, pin, max(a.repeat, 9))))


if __name__ == "__main__":
    main()
