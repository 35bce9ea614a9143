"""Reading a system file with many `[[events]]` (issue 36, item 3): `shipsim check` of a
generated system with 8,000, 16,000 and 32,000 events.

Events are the only way to feed a test signal from a system file, so a long one must read in
time linear in its length. The generated system is one HeadingAutopilot FMU (`ap`, from
--fmu-dir: $SHIPSIM_FMU_DIR or target/fmu) and N events, one per base step of 0.1 s, each
setting `ap.heading_reference`; `shipsim check` reads the file, loads the FMU and validates
every event. Each size runs --repeat times (default 3); the table gives the median wall time
of the whole process. For comparison, Python's tomllib parses the same file (the median of as
many parses; the TOML parse only, no validation).

Prints a Markdown section on stdout (cargo xtask bench appends it to docs/bench.md).

Usage (from the repository root, after `cargo build --release -p shipsim` and the FMUs):
    python master/bench/bench_events.py [--repeat 3] [--sizes 8000 16000 32000]
"""
import argparse
import json
import os
import pathlib
import statistics
import subprocess
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
SIZES = (8000, 16000, 32000)


def system_text(fmu, n):
    """A system of one HeadingAutopilot and `n` events, one per base step of 0.1 s."""
    lines = [
        "[simulation]",
        "start_time = 0.0",
        f"stop_time = {n / 10 + 1:.1f}",
        "step_size = 0.1",
        "",
        "[[instances]]",
        'name = "ap"',
        f"fmu = {json.dumps(str(fmu))}",  # a JSON string is a TOML basic string
        "",
    ]
    for i in range(n):
        lines += ["[[events]]", f"time = {i / 10:.1f}", 'set = "ap.heading_reference"',
                  f"value = {(i % 7) * 0.01:.2f}", ""]
    return "\n".join(lines)


def time_check(exe, path):
    t0 = time.perf_counter()
    r = subprocess.run([exe, "check", str(path)], capture_output=True, text=True, cwd=ROOT)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        raise SystemExit(f"{exe} check {path} failed:\n{r.stderr}")
    return wall


def time_tomllib(path):
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        return None
    data = path.read_bytes().decode()
    t0 = time.perf_counter()
    tomllib.loads(data)
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--shipsim", default=os.environ.get("SHIPSIM_BIN",
                                                        str(ROOT / "target/release/shipsim")))
    ap.add_argument("--fmu-dir", default=os.environ.get("SHIPSIM_FMU_DIR",
                                                        str(ROOT / "target/fmu")))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    a = ap.parse_args()
    fmu = pathlib.Path(a.fmu_dir).resolve() / "HeadingAutopilot.fmu"
    if not fmu.is_file():
        raise SystemExit(f"{fmu} not found: cargo xtask build-fmus")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in a.sizes:
            path = pathlib.Path(tmp) / f"events_{n}.toml"
            path.write_text(system_text(fmu, n))
            check = statistics.median(time_check(a.shipsim, path) for _ in range(a.repeat))
            parses = [time_tomllib(path) for _ in range(a.repeat)]
            py = None if None in parses else statistics.median(parses)
            rows.append((n, path.stat().st_size, check, py))
    med = f"median of {a.repeat}"
    print("## Parsing events (master/bench/bench_events.py)\n")
    print("`shipsim check` of a generated system: one HeadingAutopilot FMU and N `[[events]]`, "
          f"each setting `ap.heading_reference` at its own base step; wall time of the whole "
          f"process ({med}, unpinned). tomllib: Python's own TOML parser on the same file "
          f"(parse only, {med}), for comparison.\n")
    print("| events | file size | `shipsim check` [s] | per event [µs] | tomllib parse [s] |")
    print("|---:|---:|---:|---:|---:|")
    for n, size, check, py in rows:
        py_s = "n/a" if py is None else f"{py:.3f}"
        print(f"| {n:,} | {size / 1e6:.2f} MB | {check:.3f} | {check * 1e6 / n:.1f} | {py_s} |")
    if len(rows) > 1:
        (n0, _, c0, _), (n1, _, c1, _) = rows[0], rows[-1]
        print(f"\n{n1:,} / {n0:,} events: {c1 / c0:.1f}x the time for {n1 / n0:.0f}x the "
              f"events (linear: {n1 / n0:.0f}x, quadratic: {(n1 / n0) ** 2:.0f}x).\n")


if __name__ == "__main__":
    main()
