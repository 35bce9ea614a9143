"""Every system file in libcosim: systems/*.toml exported with `shipsim export-osp` runs in libcosim
(libcosimpy) with the same results as in shipsim (acceptance criterion "each system runs in
libcosim from its exported OspSystemStructure.xml with results equal to our master's").

The systems are found with a glob, so a new system file is covered without editing this file.
Those with a dedicated libcosim test of their own (variants, own tolerance) are listed in
COVERED with the file that covers them, and the list is checked against systems/ and against those
files, so it cannot go stale.

Each case: the system file and the FMUs it names are copied into tmp_path (bare FMU file names, the
FMUs from SHIPSIM_FMU_DIR), the run is cut to at most MAX_STEPS base steps (long runs only; the
cut keeps the part where the system does something, checked below), every base step is recorded
(decimation 1, as libcosim_runner.py records every step), then shipsim runs it, exports it, and
libcosim runs the exported OspSystemStructure.xml; test_master_interop.assert_same_as_libcosim
compares every recorded value at every step: they are bit-identical (see TOLERANCE for why).

What OspSystemStructure.xml cannot carry, and what is done about it:
* [[events]] (timed changes of an input or tunable parameter): the OSP system structure has no
  scenario; `export-osp` writes them to scenario.json next to it, libcosim's own place for them
  (what `cosim run --scenario` loads). The test checks that file against its own reading of the
  system's events (action "override", same time, same value) and runs the exported system with
  it through libcosim's scenario manager, so the systems with events
  are compared in full, not excluded. shipsim sets an event's value before the step that starts
  at the event time; libcosim's scenario manager applies it at the same step's start
  (step_commencing). The override holds to the end, a shipsim event sets the value once: the
  same thing as long as no connection drives the variable (checked; shipsim would overwrite the
  value at the next exchange, libcosim would keep the override).
* algorithm = "gauss-seidel": OSP's fixedStep algorithm is Jacobi-type; `export-osp` warns that
  the setting is not carried. Such a system cannot give the same results in libcosim and is
  skipped with that reason (none of the current systems is one).
* [output] (file, variables, decimation) is not part of the OSP file either; it only selects what
  shipsim records, and the same columns are read from libcosim.

Environment: SHIPSIM_BIN (the master), SHIPSIM_FMU_DIR (our built FMUs).
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import time
import tomllib

import pytest

import test_master_interop
from conftest import ROOT, fmu_dir
from cosim import variables_by_name
from test_master_interop import assert_same_as_libcosim, read_csv, shipsim

SYSTEMS = ROOT / "systems"

# Systems compared with libcosim by a test file of their own (with variants, and dp_observer with
# its own tolerance): {system file: test file}.
COVERED = {
    "rrs.toml": "test_rrs_libcosim.py",
    "path_control_passing_ship.toml": "test_path_control_libcosim.py",
    "path_control_current.toml": "test_path_control_libcosim.py",
    "dp_observer.toml": "test_dp_libcosim.py",
}

# Longer runs are cut to this many base steps (libcosim plus the comparison: 0.3-0.6 ms per step
# for 4-7 FMUs; shipsim is 10-20 times faster), so that a case costs a few seconds.
MAX_STEPS = 6000

# Tolerance of assert_same_as_libcosim (|shipsim - libcosim| <= tol * max(1, |libcosim|) at every
# recorded step): 0, the runs are bit-identical. libcosim keeps time in integer nanoseconds and
# calls fmi2DoStep with t_k = (t0_ns + k h_ns)/1e9 and the step size fl(t_k+1) - fl(t_k) (its
# to_double_duration); shipsim uses the same clock (master/src/run/time_grid.rs, TimeGrid). Before it
# did (t0 + k*h and h itself) the runs differed by ulps from the third step of h = 0.05 on
# (0.15 - 0.1 = 0.04999999999999999), which integration and feedback carried up to 4e-12
# relative (autopilot_track_offset) and 2e-10 (dp_observer). Empty: no system needs an exception.
TOLERANCE = {}

# Some systems need more than MAX_STEPS to reach what they are about: {system: stop time}.
STOP_TIME = {
    # the lateral offset manoeuvre starts at t = 300 s (after the current gust at 60 s)
    "autopilot_track_offset.toml": 420.0,
}


def uncovered_systems():
    return sorted(p.name for p in SYSTEMS.glob("*.toml") if p.name not in COVERED)


def test_covered_list_is_current():
    """The systems left out here exist and are run in libcosim by the file that claims them."""
    for system, test_file in COVERED.items():
        assert (SYSTEMS / system).exists(), f"{system} is listed as covered but is not in systems/"
        text = (ROOT / "tests" / "python" / test_file).read_text()
        assert system in text and "assert_same_as_libcosim" in text, (system, test_file)
    assert uncovered_systems(), "no system left to cover here"


def localise(system, tmp_path):
    """Copies systems/<system> and the FMUs it names into tmp_path: bare FMU file names, the run cut
    to at most MAX_STEPS base steps (or STOP_TIME), decimation 1. Returns (path, parsed TOML)."""
    text = (SYSTEMS / system).read_text()
    spec = tomllib.loads(text)
    for inst in spec["instances"]:
        name = os.path.basename(inst["fmu"])
        src = fmu_dir() / name
        if not src.exists():
            raise RuntimeError(f"{src} (instance {inst['name']} of {system}) is missing: "
                               "run `cargo xtask build-fmus` first")
        shutil.copy(src, tmp_path / name)
        text = text.replace(f'"{inst["fmu"]}"', f'"{name}"')
    sim = spec["simulation"]
    t0, h = sim.get("start_time", 0.0), sim["step_size"]
    n = round((sim["stop_time"] - t0) / h)
    stop = STOP_TIME.get(system, t0 + min(n, MAX_STEPS) * h)
    stop = min(round(stop, 9), sim["stop_time"])
    # the [simulation] table's stop_time only (trailing comments kept)
    section = re.search(r"(?ms)^\[simulation\]\n(.*?)(?=^\[|\Z)", text)
    new, k = re.subn(r"(?m)^(stop_time\s*=\s*)[-+0-9.eE_]+", rf"\g<1>{stop!r}", section.group(1))
    assert k == 1, f"{system}: no stop_time in [simulation]"
    text = text[: section.start(1)] + new + text[section.end(1):]
    text, _ = re.subn(r"(?m)^(decimation\s*=\s*)\d+", r"\g<1>1", text)
    spec = tomllib.loads(text)
    for e in spec.get("events", []):
        assert e["time"] < stop, f"{system}: the shortened run (to {stop} s) drops the event at {e['time']} s"
    path = tmp_path / system
    path.write_text(text)
    return path, spec


def write_scenario(system, spec, path):
    """The system's [[events]] as a libcosim scenario file (JSON)."""
    t0 = spec["simulation"].get("start_time", 0.0)
    driven = set()
    for c in spec.get("connections", []):
        driven.add(c.split("->")[1].strip() if isinstance(c, str) else c["to"])
    events = []
    for e in spec["events"]:
        assert e["set"] not in driven, (
            f"{system}: the event sets {e['set']}, which a connection drives: a libcosim override would "
            "hold against the connection, shipsim's set does not")
        inst, var = e["set"].split(".", 1)
        events.append({"time": e["time"] - t0, "model": inst, "variable": var, "action": "override",
                       "value": e["value"]})
    # "end" = the run's end: when a scenario ends (without "end": when its last event has run)
    # libcosim resets the overridden variables, and a variable with an InitialValue falls back
    # to it (seen: the rudder command went back to -35 deg one step after the event).
    end = spec["simulation"]["stop_time"] - t0
    path.write_text(json.dumps({"description": f"the [[events]] of {system}", "events": events, "end": end},
                               indent=2))
    return path


def libcosim_rows_with_scenario(scenario):
    """test_master_interop.libcosim_rows, with a libcosim scenario loaded into the execution (this
    file run as a script: libcosim_runner.main with the scenario manager added)."""

    def rows(osp_file, header, n_steps):
        r = subprocess.run([sys.executable, __file__, str(scenario), str(osp_file), str(n_steps), *header[1:]],
                           capture_output=True, text=True)
        assert r.returncode == 0, f"libcosim run of {osp_file} with {scenario} failed ({r.returncode}):\n{r.stderr}"
        return json.loads(r.stdout)

    return rows


def assert_moves(system, header, rows):
    """Something happens in the (shortened) run: the manoeuvre, disturbance or estimator the
    system is about really acts, so that the comparison compares more than constants."""
    col = {h: i for i, h in enumerate(header)}

    def span(name, start=0):
        v = [r[col[name]] for r in rows[start:]]
        return max(v) - min(v)

    def last(name):
        return rows[-1][col[name]]

    def at(name, t):
        return next(r[col[name]] for r in rows if r[0] >= t)

    checks = {
        # the 5-kn beam current pushes the ship sideways, the autopilot answers with rudder
        "autopilot_current.toml": lambda: span("ship.y") > 20.0 and span("ap.rudder_command") > 0.02,
        # the 90 deg turn from t = 60 s at 1 deg/s is flown
        "autopilot_track_change.toml": lambda: span("ship.heading") > 1.4 and span("gear.rudder_angle") > 0.05,
        # gust at 60 s, then the ship moves off towards the 284 m port offset; waves act on the hull
        "autopilot_track_offset.toml": lambda: span("ship.y") > 20.0 and span("waves.yaw_moment") > 0.01,
        # the turning circle: more than half a circle, with the speed loss of the turn
        "container_ship_turning_circle.toml": lambda: span("ship.heading") > 3.2 and span("ship.speed") > 1.0,
        # the event cuts the shaft at 60 s and the ship slows down; the filters track it
        "dgps_stopping.toml": lambda: (at("ship.shaft_speed", 59.0) > 60.0 and last("ship.shaft_speed") < 2.0
                                       and at("ship.speed", 59.0) - last("ship.speed") > 2.0
                                       and span("kf.velocity_north_estimate") > 2.0),
        # the 35 deg turn from 60 s; the filters see the noisy fixes and the turn
        "dgps_trial.toml": lambda: (span("ship.heading") > 3.0 and span("kf.velocity_east_estimate") > 2.0
                                    and any(r[col["gps.north_measured"]] != r[col["ship.x"]] for r in rows[20:])),
        # zig-zag, and the EKF moves its coefficient estimates
        "identification_zigzag.toml": lambda: (span("ship.rudder_angle") > 0.3 and last("kf.update_count") > 100
                                               and span("kf.neg_y_v_estimate") > 1e-4),
        # the sea rolls the ship and the RRS moves the rudder (as test_rrs_libcosim)
        "rrs_simulation_plant.toml": lambda: span("ship.roll") > 0.05 and span("gear.rudder_angle") > 0.1,
        # the events at 5 s send both gears hard over, 35 deg port to 35 deg starboard
        "steering_gear_classification.toml": lambda: (abs(last("slow.rudder_angle") - 0.6109) < 1e-3
                                                      and abs(last("rrs.rudder_angle") - 0.6109) < 1e-3
                                                      and at("slow.rudder_angle", 4.9) < -0.6),
    }
    if system in checks:
        assert checks[system](), f"{system}: the run does not do what the system is about"
    else:
        # a system added after this file: at least some recorded variable changes
        assert any(span(h) > 1e-9 * max(1.0, max(abs(r[col[h]]) for r in rows)) for h in header[1:]), (
            f"{system}: every recorded variable is constant over the run")


@pytest.mark.parametrize("system", uncovered_systems(), ids=lambda s: s.removesuffix(".toml"))
def test_system_equals_libcosim(system, tmp_path, monkeypatch):
    toml, spec = localise(system, tmp_path)
    if spec["simulation"].get("algorithm", "jacobi") != "jacobi":
        # Not exportable with the same results: OSP's fixedStep algorithm is Jacobi-type, and
        # `export-osp` does not carry the Gauss-Seidel order (master/src/format/osp.rs).
        pytest.skip(f"{system}: algorithm {spec['simulation']['algorithm']!r} cannot be expressed in "
                    "OspSystemStructure.xml (libcosim fixedStep is Jacobi)")
    start = time.perf_counter()
    out = tmp_path / "shipsim.csv"
    shipsim("run", toml, "-o", out, "-q")
    osp = tmp_path / "OspSystemStructure.xml"
    r = shipsim("export-osp", toml, "-o", osp)
    header, rows = read_csv(out)
    n = round((spec["simulation"]["stop_time"] - spec["simulation"].get("start_time", 0.0))
              / spec["simulation"]["step_size"])
    assert len(rows) == n + 1, f"{system}: expected every base step recorded"
    assert_moves(system, header, rows)
    # libcosim_runner.py reads Real values only: other recorded columns (none in the current
    # systems) are left out of the comparison
    fmus = {i["name"]: tmp_path / os.path.basename(i["fmu"]) for i in spec["instances"]}
    real = [0] + [j for j, h in enumerate(header) if j and
                  variables_by_name(fmus[h.split(".", 1)[0]])[h.split(".", 1)[1]].type == "Real"]
    if len(real) < len(header):
        out = tmp_path / "shipsim_real.csv"
        with open(out, "w", newline="") as f:
            csv.writer(f).writerows([[header[j] for j in real]] + [[repr(r[j]) for j in real] for r in rows])
    if spec.get("events"):
        assert "scenario event(s) are not part of OspSystemStructure.xml" in r.stderr
        # export-osp writes the events as a libcosim scenario next to the system structure; it
        # must say what this file's own reading of the system file says
        scenario = tmp_path / "scenario.json"
        exported = json.loads(scenario.read_text())
        expected = json.loads(write_scenario(system, spec, tmp_path / "expected_scenario.json").read_text())
        for d in (exported, expected):
            d.pop("description")
        assert exported == expected
        monkeypatch.setattr(test_master_interop, "libcosim_rows", libcosim_rows_with_scenario(scenario))
    worst = assert_same_as_libcosim(osp, out, tol=TOLERANCE.get(system, 0.0))
    print(f"{system}: {n} steps, {len(header) - 1} columns, worst |shipsim - libcosim| = {worst:.3e}, "
          f"{time.perf_counter() - start:.1f} s")


def _libcosim_runner_with_scenario():
    """Child process: python test_systems_libcosim.py SCENARIO OSP_FILE N_STEPS COLUMN...; runs
    libcosim_runner.main with a scenario manager holding SCENARIO added to the execution."""
    import libcosim_runner
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimManipulator import CosimManipulator

    scenario = sys.argv.pop(1)
    from_osp = CosimExecution.from_osp_config_file
    keep = []

    def with_scenario(osp):
        ex = from_osp(osp)
        manager = CosimManipulator.create_scenario_manager()
        if not ex.add_manipulator(manager) or not ex.load_scenario(manager, scenario):
            raise SystemExit(f"libcosim: could not load the scenario {scenario}")
        keep.append(manager)
        return ex

    CosimExecution.from_osp_config_file = staticmethod(with_scenario)
    try:
        libcosim_runner.main()
    except SystemExit as e:
        sys.stderr.write(f"{e}\n")
        sys.stderr.flush()
        os._exit(2)
    os._exit(0)


if __name__ == "__main__":
    _libcosim_runner_with_scenario()
