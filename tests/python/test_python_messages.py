"""Clear messages from the `shipsim` Python package (issue 38, item 14): each case was a pyo3
internal, a bare Python error or a pile of unrelated messages, and now says what is wrong and
what to do.

- (f) two threads running one Campaign into one folder: the second is told the folder is in use;
- (h) a stop time out of range is one message about the stop time, not four (three about
  step_multiple)."""
import pathlib
import threading
import time

import numpy as np
import pytest

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
RRS = ROOT / "systems" / "rrs.toml"


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
