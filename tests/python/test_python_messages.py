"""Clear messages from the `shipsim` Python package (issue 38, item 14): each case was a pyo3
internal, a bare Python error or a pile of unrelated messages, and now says what is wrong and
what to do.

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
