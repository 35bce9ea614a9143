"""What a check compiled into our FMUs costs: the RRS system run with its FMUs as built
(target/fmu) against a variant of them built without the check (`cargo xtask bench` builds each
variant with `--cfg <name>` into target/variants/<name>/fmu; xtask/src/fmu.rs,
`build_fmu_variant`).

Variants:
- shipsim_no_call_log: without the per-call tracing test of every FMI entry
  (fmus/export/src/instance.rs, CALL_LOG), so the row is what per-call logging costs while it is
  off (issue 18: at most 1 %).
- shipsim_no_output_check: without the finiteness check of the values fmi2GetReal hands out
  (fmus/export/src/api.rs, OUTPUT_CHECK), so the row is what the check costs (issue 19: at most
  1 %).
- shipsim_platform_libm: the models' transcendental functions from the platform's C library
  (glibc) instead of the pure-Rust libm crate (models/src/math.rs), so the row is what identical
  bits on linux64 and win64 cost (issue 30).

The two builds run in pairs, back to back, pinned to one core (as bench_systems.py does); each run
is systems/rrs.toml extended to --stop-time (24,000 s by default: 480,000 macro steps) without
CSV output, and its figure is the step loop's µs per macro step from `--profile=json`. The cost is
the median over the pairs of (as built / variant - 1); the pairs are listed.

Wall time on a loaded two-core machine scatters by several per cent from pair to pair, so where
valgrind is installed each row also gives the cost in instructions, which does not scatter:
cachegrind's instruction count of the system run to 2 T and to T (T = 240 s), the difference
divided by the macro steps between them (start-up and loading cancel out).

Prints a Markdown section on stdout (cargo xtask bench writes it into docs/bench.md).

Usage (from the repository root, after the FMUs, the variants and shipsim are built):
    python master/bench/bench_variants.py [--repeat 9] [--stop-time 24000] NAME=DIR ...
"""
import argparse
import json
import os
import pathlib
import re
import shutil
import statistics
import subprocess
import tempfile

from bench_systems import ROOT, pinning, run_system

WHAT = {
    "shipsim_no_call_log": "per-call logging, off (`logCalls` not enabled)",
    "shipsim_no_output_check": "finiteness of every Real handed out (fmi2GetReal)",
    "shipsim_platform_libm": "one pure-Rust libm on every platform (models::math), against glibc's",
}

# The shorter run of the instruction count (s); the longer runs to twice this.
COUNT_TIME = 240.0


def instructions(shipsim, system, stop_time):
    """cachegrind's instruction count (I refs) of `shipsim run system` to `stop_time` (without
    the profiler, whose clock reads would count too), and its macro steps (from a run with
    `--profile=json`, not under valgrind); None without valgrind."""
    if shutil.which("valgrind") is None:
        return None
    run = [shipsim, "run", str(system), "--no-output", "-q", "--stop-time", repr(stop_time)]
    cmd = ["valgrind", "--tool=cachegrind", "--cache-sim=no", "--cachegrind-out-file=/dev/null"] + run
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    refs = re.search(r"I\s+refs:\s+([\d,]+)", r.stderr)
    if refs is None:
        raise SystemExit(f"{' '.join(cmd)}: no 'I refs' line in valgrind's output:\n{r.stderr}")
    steps = run_system(shipsim, [], system, stop_time=stop_time)["macro_steps"]
    return int(refs.group(1).replace(",", "")), steps


def per_macro_step(shipsim, system):
    """Instructions per macro step of the step loop (see the module doc), or None."""
    short = instructions(shipsim, system, COUNT_TIME)
    if short is None:
        return None
    long = instructions(shipsim, system, 2 * COUNT_TIME)
    return (long[0] - short[0]) / (long[1] - short[1])


def system_with_fmus(src, fmu_dir, dest):
    """A copy of the system file `src` whose FMUs are read from `fmu_dir`."""
    text = src.read_text().replace('"../target/fmu/', f'"{fmu_dir.resolve()}/')
    if str(fmu_dir.resolve()) not in text:
        raise SystemExit(f"{src}: no FMU path under ../target/fmu/ to replace")
    dest.write_text(text)
    return dest


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shipsim", default=os.environ.get("SHIPSIM_BIN", str(ROOT / "target/release/shipsim")))
    ap.add_argument("--repeat", type=int, default=9)
    ap.add_argument("--stop-time", type=float, default=24000.0)
    ap.add_argument("variants", nargs="+", help="NAME=DIR: a cfg name and its folder of FMUs")
    a = ap.parse_args()
    pin, pin_note = pinning()
    src = ROOT / "systems/rrs.toml"
    print("## Checks compiled into the FMUs (master/bench/bench_variants.py)\n")
    print(f"The RRS system (systems/rrs.toml to {a.stop_time:g} s, `--no-output`), {pin_note}, with "
          "its FMUs as built against the same FMUs built without one check (`--cfg NAME`); runs in "
          f"{a.repeat} pairs back to back; cost = median over the pairs of the ratio of step-loop "
          "time per macro step, minus 1.\n")
    print("| check | variant built with | µs / macro step, as built | without the check | cost | pairs "
          "| instructions / macro step, as built | without | cost in instructions |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        built = system_with_fmus(src, ROOT / "target/fmu", tmp / "built.toml")
        for spec in a.variants:
            name, _, folder = spec.partition("=")
            variant = system_with_fmus(src, pathlib.Path(folder), tmp / f"{name}.toml")
            pairs = []
            for _ in range(a.repeat):
                x = run_system(a.shipsim, pin, built, stop_time=a.stop_time)["us_per_macro_step"]
                y = run_system(a.shipsim, pin, variant, stop_time=a.stop_time)["us_per_macro_step"]
                pairs.append((x, y))
            med = statistics.median
            costs = sorted(100 * (x / y - 1) for x, y in pairs)
            ix, iy = per_macro_step(a.shipsim, built), per_macro_step(a.shipsim, variant)
            counted = ("| valgrind not installed | | |" if ix is None else
                       f"| {ix:,.0f} | {iy:,.0f} | **{100 * (ix / iy - 1):+.2f} %** |")
            print(f"| {WHAT.get(name, name)} | `--cfg {name}` | {med(p[0] for p in pairs):.4f} "
                  f"| {med(p[1] for p in pairs):.4f} | **{med(costs):+.2f} %** "
                  f"| {', '.join(f'{c:+.1f}' for c in costs)} {counted}")


if __name__ == "__main__":
    main()
