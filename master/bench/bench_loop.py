"""Loop analysis: the time of a margin analysis of the DDG-51 heading loop.

`shipsim loop systems/autopilot_current.toml --break "ap.rudder_command -> gear.rudder_command"`
(sensor noise off) with its defaults: 20 log-spaced frequencies, each measured again at twice the
amplitude, the crossings refined by more forks; every fork from the start. The issue's goal: a
20-frequency margin analysis of the heading loop in under 5 s on 2 cores. Beside it, for scale,
one plain `shipsim run` of the system (400 s). Prints a Markdown section on stdout.
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
SYSTEM = ROOT / "systems" / "autopilot_current.toml"


def timed(cmd, cwd):
    begin = time.perf_counter()
    out = subprocess.run(cmd, cwd=cwd, check=True, capture_output=True, text=True).stdout
    return time.perf_counter() - begin, out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    shipsim = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
    analysis, plain, result = [], [], None
    with tempfile.TemporaryDirectory() as d:
        for _ in range(args.runs):
            t, out = timed([shipsim, "loop", str(SYSTEM), "--break", "ap.rudder_command -> gear.rudder_command",
                            "--set", "sensors.noise_scale=0", "--json", "-o", "loop"], d)
            analysis.append(t)
            result = json.loads(out)
            t, _ = timed([shipsim, "run", str(SYSTEM), "--no-output", "-q"], d)
            plain.append(t)
    a, p = statistics.median(analysis), statistics.median(plain)
    verdict = "within" if a < 5.0 else "OVER"
    print("## Loop analysis (master/bench/bench_loop.py)\n")
    print(f"The DDG-51 heading loop (systems/autopilot_current.toml), margins at the autopilot's rudder "
          f"command with the defaults; median of {args.runs} runs, whole processes.\n")
    print("| measure | median |")
    print("|---|---|")
    print(f"| `shipsim loop --break ...`: {result['points']} measured points (20 on the grid, the rest "
          f"refining the crossings) and 20 linearity forks | {a:.3f} s (goal 5 s: {verdict}) |")
    print(f"| one plain `shipsim run` of the system (400 s), for scale | {p:.3f} s |")
    print(f"| margins | GM {result['gain_margin_db']:.2f} dB, PM {result['phase_margin_deg']:.2f} deg "
          f"at {result['crossover_rad_s']:.4f} rad/s |")
    print()


if __name__ == "__main__":
    main()
