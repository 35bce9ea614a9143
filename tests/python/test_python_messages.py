"""Clear messages from the `shipsim` Python package (issue 38, item 14): each case was a pyo3
internal, a bare Python error or a pile of unrelated messages, and now says what is wrong and
what to do.

- (a) System.set while another thread runs the System: "is running in another thread", not
  RuntimeError('Already borrowed');
- (b) an Integer variable takes a whole float (3.0, numpy.float64(3.0)) as that integer;
  3.5 is a VariableError naming variable and value;
- (c) an int outside the Integer range (2**100) is a VariableError naming the range, not an
  OverflowError; a Real variable takes a big int as the nearest double;
- (d) run(variables="ship.roll") is one pattern, not nine one-letter names;
- (e) Campaign.run(client="bogus") says what a client must be, before the folder is touched;
- (f) two threads running one Campaign into one folder: the second is told the folder is in use;
- (h) a stop time out of range is one message about the stop time, not four (three about
  step_multiple)."""
import os
import pathlib
import threading
import time

import numpy as np
import pytest

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
RRS = ROOT / "systems" / "rrs.toml"


def raised_while_running(system, action):
    """Runs `system` in a thread and calls `action()` until it raises or the run ends; returns
    what it raised (None if the run ended first)."""
    done = threading.Event()

    def run():
        try:
            system.run(stop_time=20000, variables=["ship.roll"])
        finally:
            done.set()

    t = threading.Thread(target=run)
    t.start()
    raised = None
    try:
        while not done.is_set():
            try:
                action()
            except shipsim.ShipsimError as e:
                raised = e
                break
            time.sleep(0.001)
    finally:
        t.join()
    return raised


def test_changing_a_running_system_says_it_is_running():
    s = shipsim.System.load(RRS)
    e = raised_while_running(s, lambda: s.set("waves.seed", 7))
    assert e is not None, "the run ended before set was tried during it"
    assert not isinstance(e, RuntimeError)
    msg = str(e)
    assert msg.startswith("System.set('waves.seed'): the System (") and "rrs.toml" in msg, msg
    assert "is running in another thread; change it before or after its runs" in msg, msg
    assert "load a System per thread" in msg, msg

    def strict():
        s.strict_units = False

    e = raised_while_running(s, strict)
    assert e is not None and str(e).startswith("System.strict_units: the System ("), e
    assert s.strict_units is True  # refused: nothing changed
    # after the runs, both work again
    s.set("waves.seed", 7).strict_units = True
    assert s.values["waves.seed"] == "7"


def test_an_integer_variable_takes_whole_floats():
    s = shipsim.System.load(RRS)
    ref = s.set("waves.seed", 3).run(stop_time=30, variables=["ship.roll"])
    for value in (3.0, np.float64(3.0), np.int64(3)):
        s.set("waves.seed", 99)
        s.set("waves.seed", value)
        assert s.values["waves.seed"] == "3", value
        df = s.run(stop_time=30, variables=["ship.roll"])
        assert np.array_equal(df["ship.roll"].to_numpy(), ref["ship.roll"].to_numpy()), value
    for value, shown in [(3.5, "3.5"), (np.float64(3.5), "np.float64(3.5)"), (float("nan"), "nan")]:
        with pytest.raises(shipsim.VariableError) as e:
            s.set("waves.seed", value)
        assert str(e.value) == (
            f"'waves.seed' = {shown}: variable 'seed' is an Integer; give a whole number from "
            "0 to 2147483647"
        )
    assert s.values["waves.seed"] == "3"  # a refused value changes nothing


def test_a_boolean_variable_takes_numpy_bools():
    """np.True_ and np.False_ (what a boolean array holds) were taken as the Reals 1.0 and 0.0
    and refused when the system ran. The steering gear alone, a large command: its rate limit
    acts from the first step."""
    fmu = pathlib.Path(os.environ.get("SHIPSIM_FMU_DIR", ROOT / "target" / "fmu")) / "SteeringGear.fmu"
    s = shipsim.System.load(fmu).set("SteeringGear.rudder_command", 0.3)
    angle = ["SteeringGear.rudder_angle"]
    ref = s.set("SteeringGear.rate_limited", False).run(stop_time=2, variables=angle)
    on = s.set("SteeringGear.rate_limited", True).run(stop_time=2, variables=angle)
    assert not np.array_equal(on[angle[0]].to_numpy(), ref[angle[0]].to_numpy())
    for value, expect in ((np.False_, ref), (np.array([True, False])[1], ref), (np.True_, on)):
        s.set("SteeringGear.rate_limited", value)
        df = s.run(stop_time=2, variables=angle)
        assert np.array_equal(df[angle[0]].to_numpy(), expect[angle[0]].to_numpy()), value


def test_an_int_out_of_range_names_the_range():
    s = shipsim.System.load(RRS)
    for value in (2**100, -(2**40), 2.0**40):
        with pytest.raises(shipsim.VariableError) as e:
            s.set("waves.seed", value)
        assert str(e.value) == (
            f"'waves.seed' = {value!r}: variable 'seed' is an Integer; give a whole number "
            "from 0 to 2147483647"
        )
    # a number of 1001 digits is not written out
    with pytest.raises(shipsim.VariableError) as e:
        s.set("waves.seed", 10**1000)
    assert str(e.value).startswith("'waves.seed' = 1" + "0" * 23 + "... (1001 characters): variable 'seed'")
    # a Real takes any int a double holds, as the nearest double
    s.set("waves.significant_wave_height", 2**100)
    assert float(s.values["waves.significant_wave_height"]) == 2.0**100
    with pytest.raises(shipsim.VariableError, match="is a Real, and this number is beyond the largest double"):
        s.set("waves.significant_wave_height", 10**400)


def test_variables_as_one_string():
    s = shipsim.System.load(RRS)
    df = s.run(stop_time=1, variables="ship.roll")
    assert list(df.columns) == ["ship.roll"]
    df = s.run(stop_time=1, variables="gear.*")
    assert list(df.columns) == list(s.run(stop_time=1, variables=["gear.*"]).columns)


def test_a_client_that_is_no_dask_client(tmp_path):
    c = shipsim.Campaign.load(ROOT / "campaigns" / "rrs_polar_reduced.toml")
    for bogus in ("bogus", 42):
        with pytest.raises(TypeError) as e:
            c.run(tmp_path / "out", client=bogus, progress=False)
        assert str(e.value).startswith(f"client={bogus!r} ({type(bogus).__name__}): a client must "
                                       "be a dask.distributed.Client"), e.value
        assert '"local" for a LocalCluster on this machine' in str(e.value)
    assert not (tmp_path / "out").exists()


def test_two_threads_on_one_campaign_folder(tmp_path):
    c = shipsim.Campaign.load(ROOT / "campaigns" / "rrs_polar_reduced.toml")
    out = tmp_path / "out"
    start = threading.Barrier(2)
    outcomes = []

    def run():
        start.wait()
        try:
            outcomes.append(("ok", len(c.run(out, jobs=1, progress=False))))
        except Exception as e:  # noqa: BLE001 (every failure is checked below)
            outcomes.append((type(e).__name__, str(e)))

    threads = [threading.Thread(target=run) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    outcomes.sort()
    assert outcomes[0] == ("ShipsimError", f"{out / 'runs.jsonl'} is in use: a campaign is running "
                           f"into {out} (in another process, or in another thread of this one); wait "
                           "for it to end, or give another output folder"), outcomes
    assert outcomes[1] == ("ok", 12), outcomes


@pytest.mark.parametrize("stop, expect", [
    (-5, "stop_time = -5 must be greater than start_time = 0"),
    (float("nan"), "stop_time = NaN; it must be a finite number"),
    (float("inf"), "stop_time = inf; it must be a finite number"),
    (1e300, "the run from 0 to 1e300 has 2e301 steps of 0.05 s, more than the"),
])
def test_a_stop_time_out_of_range_is_one_message(stop, expect):
    s = shipsim.System.load(RRS)
    with pytest.raises(shipsim.SystemFileError) as e:
        s.run(stop_time=stop, variables=["ship.roll"])
    msg = str(e.value)
    assert expect in msg, msg
    assert "step_multiple" not in msg and "error(s)" not in msg, msg
