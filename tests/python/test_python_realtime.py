"""Paced runs from Python: `System.run(real_time=True)` and `real_time_factor=X` go through the
runner of `shipsim run --real-time` (shipsim::realtime::run_system).

- a paced RRS run of 2 s takes 2 s plus start-up (a loose band: 2 to 5 s on a loaded machine),
  at factor 4 a run of 8 s takes 2 s, and both give the unpaced run's rows bit for bit;
- the summary gives the lateness and the overruns;
- a factor that is not a positive number raises ValueError.

Tolerance: none for the rows (bit patterns); wall time within the bands above."""
import pathlib
import time

import numpy as np
import pytest

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
RRS = ROOT / "systems" / "rrs.toml"


def bits(df):
    cols = [df.index.to_numpy(dtype=np.float64)] + [df[c].to_numpy(dtype=np.float64) for c in df.columns]
    return np.stack(cols).view(np.uint64)


@pytest.mark.parametrize("kwargs,stop", [({"real_time": True}, 2.0), ({"real_time_factor": 4}, 8.0)])
def test_paced_run_takes_its_time_and_equals_the_plain_run(kwargs, stop):
    system = shipsim.System.load(RRS)
    plain = system.run(stop_time=stop)
    begin = time.monotonic()
    paced = system.run(stop_time=stop, **kwargs)
    wall = time.monotonic() - begin
    assert 2.0 <= wall < 5.0, wall
    assert list(paced.columns) == list(plain.columns)
    assert np.array_equal(bits(paced), bits(plain))
    s = paced.attrs["summary"]
    assert s["paced_factor"] == kwargs.get("real_time_factor", 1.0)
    assert s["end_time"] == stop and s["macro_steps"] == len(plain) - 1
    assert 0 <= s["lateness_median"] <= s["lateness_p99"] <= s["lateness_max"]
    assert s["overruns"] >= 0 and 1.9 <= s["wall_time"] < 5.0


@pytest.mark.parametrize("factor", [0, -1, float("nan"), float("inf")])
def test_a_bad_factor_raises(factor):
    with pytest.raises(ValueError, match="real_time_factor"):
        shipsim.System.load(RRS).run(stop_time=1, real_time_factor=factor)
