"""The master's step-loop cost in instructions, for two shipsim builds side by side: the RRS
system (systems/rrs.toml, our FMUs) and the 10-FMU chain of bench_master.py (the C test FMU,
one multiply-add per step, so the figure is the master and its FMI calls).

Each figure is cachegrind's instruction count of the run to 2 T minus the run to T, divided by
the macro steps between (start-up, loading and initialization cancel out), as
bench_variants.py counts them; instructions do not scatter from run to run as wall time does
on a loaded machine. A refactor of the master's FMU-call layer is meant to move both figures by
less than 1 % (issue 29).

Usage (from the repository root; needs valgrind and gcc; the FMUs built into target/fmu):
    python master/bench/bench_instructions.py OLD_SHIPSIM NEW_SHIPSIM
Prints a Markdown table.
"""
import argparse
import pathlib
import sys
import tempfile

from bench_master import build_fmu, system_toml
from bench_systems import ROOT
from bench_variants import COUNT_TIME, instructions


def per_macro_step(shipsim, system, t):
    """Instructions per macro step between the runs to t and to 2 t."""
    short = instructions(shipsim, system, t)
    if short is None:
        sys.exit("valgrind is not installed (apt-get install valgrind)")
    long = instructions(shipsim, system, 2 * t)
    return (long[0] - short[0]) / (long[1] - short[1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--fmus", type=int, default=10, help="FMUs in the chain")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        build_fmu(tmp)
        chain = tmp / f"chain{a.fmus}.toml"
        # Base step 0.01 s: T = 24 s is 2,400 macro steps of the chain.
        chain.write_text(system_toml(a.fmus, 100, 0.01))
        systems = [("RRS (systems/rrs.toml)", ROOT / "systems/rrs.toml", COUNT_TIME),
                   (f"{a.fmus}-FMU chain (bench_master.py)", chain, 24.0)]
        print("| system | instructions / macro step, old | new | change |")
        print("|---|---|---|---|")
        for name, system, t in systems:
            old = per_macro_step(a.old, system, t)
            new = per_macro_step(a.new, system, t)
            print(f"| {name} | {old:,.1f} | {new:,.1f} | **{100 * (new / old - 1):+.2f} %** |")


if __name__ == "__main__":
    main()
