"""Stepping sessions from Python: what one `session.step()` costs beyond the macro step.

systems/rrs.toml (7 FMUs, h = 0.05 s, two rates), recording nothing (`variables=[]`):

- the macro step: `System.run` of the same span, its step loop's own wall time per step;
- `session.step()` called once per macro step from a Python loop: the loop's wall time per
  call, and the session's own stepping time per step (the master's, from `rows()`); the
  difference is the Python-side overhead of a call (the method call, the session's lock, the
  GIL released and taken back, the state checks);
- `session.step(n)` in one call over the same span, for comparison;
- `session.get(name)` of one Real, and `session.set(name, value)` of one tunable Real before
  each step (the set's cost is the loop with set and step minus the loop with step alone:
  the value's check as an event, the journal record, the event's place in the step loop).

The issue's goal: at most 2 us of Python-side overhead per step call. Prints a Markdown
section on stdout.
"""
import argparse
import pathlib
import statistics
import time

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
SYSTEM = ROOT / "systems" / "rrs.toml"


def stepping(system, steps, set_each=False):
    """(wall time of a loop of `steps` step() calls, the master's own stepping time)."""
    session = system.start(stop_time=steps * system.step_size, variables=[])
    step, setv = session.step, session.set
    begin = time.perf_counter()
    if set_each:
        for k in range(steps):
            setv("autopilot.lambda", 4.0 + 1e-3 * (k & 7))
            step()
    else:
        for _ in range(steps):
            step()
    total = time.perf_counter() - begin
    master = session.rows(as_frame=False).summary["wall_time"]
    assert session.state == "ended", session.state
    session.close()
    return total, master


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--steps", type=int, default=24000)
    args = ap.parse_args()
    system = shipsim.System.load(SYSTEM)
    n = args.steps
    stop = n * system.step_size
    system.run(stop_time=1.0, variables=[])  # warm the caches once
    run_loop, call, master, one_call, with_set, gets = [], [], [], [], [], []
    for _ in range(args.runs):
        run_loop.append(system.run(stop_time=stop, variables=[], as_frame=False).summary["wall_time"] / n)
        total, own = stepping(system, n)
        call.append(total / n)
        master.append(own / n)
        session = system.start(stop_time=stop, variables=[])
        begin = time.perf_counter()
        session.step(n)
        one_call.append((time.perf_counter() - begin) / n)
        get = session.get
        begin = time.perf_counter()
        for _ in range(n):
            get("ship.roll")
        gets.append((time.perf_counter() - begin) / n)
        session.close()
        total, _ = stepping(system, n, set_each=True)
        with_set.append(total / n)
    med = statistics.median
    us = lambda x: f"{x * 1e6:.3f} us"  # noqa: E731
    overhead = med([c - m for c, m in zip(call, master)])
    set_cost = med(with_set) - med(call)
    verdict = "within" if overhead <= 2e-6 else "OVER"
    print("## Stepping sessions from Python (master/bench/bench_session.py)\n")
    print(f"systems/rrs.toml, {n} macro steps ({stop:g} s), nothing recorded; median of "
          f"{args.runs} rounds.\n")
    print("| measure | per macro step or call |")
    print("|---|---|")
    print(f"| `System.run` step loop (the macro step itself) | {us(med(run_loop))} |")
    print(f"| `session.step()` from a Python loop, whole call | {us(med(call))} |")
    print(f"| the session's own stepping in those calls (the master's) | {us(med(master))} |")
    print(f"| Python-side overhead of one `step()` call | {us(overhead)} (goal 2 us: {verdict}) |")
    print(f"| `session.step({n})` in one call, per step | {us(med(one_call))} |")
    print(f"| `session.get(\"ship.roll\")` | {us(med(gets))} |")
    print(f"| `session.set(\"autopilot.lambda\", x)` before each step (journaled) | {us(set_cost)} |")
    print()


if __name__ == "__main__":
    main()
