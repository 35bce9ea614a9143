"""A stop time off the base-step grid (issue 18, interop defect "Step grid"): FMPy takes a
shorter last step to reach it (fmpy.simulation.simulateCS, when the FMU declares
canHandleVariableCommunicationStepSize); shipsim does the same with `last_step = "short"` (or
`shipsim run --last-step short`), and by default stops at the last grid point before it.

Our SteeringGear alone, with the rudder command as a start value, the base step 1/16 s (dyadic,
so that FMPy's t0 + k*h and shipsim's nanosecond grid are the same doubles, as in
test_fixture_fmus.py) and stop times 2.03 s and 0.1 s, off the grid: both tools give the same
rows, the last one at the stop time itself, every Real output equal bit for bit (tolerance 0).
The stop times are chosen so that the rate limiter is active in the short step (2.03 s: the
rudder is still moving; 0.1 s: one full step and a short one).

Environment: SHIPSIM_BIN (the master), SHIPSIM_FMU_DIR (our built FMUs).
"""
import shutil
import textwrap

import numpy as np
import pytest
from fmpy import simulate_fmu

from test_master_interop import our_fmu, read_csv, shipsim

H = 0.0625
OUTPUTS = ["rudder_angle", "rudder_rate", "limited_command", "rate_saturated_time"]
PARAMS = {"rudder_command": 0.3}


def system(stop, last_step):
    line = f'last_step = "{last_step}"' if last_step else ""
    return textwrap.dedent(f"""
        [simulation]
        stop_time = {stop!r}
        step_size = {H!r}
        {line}
        [[instances]]
        name = "gear"
        fmu = "SteeringGear.fmu"
        parameters = {{ rudder_command = {PARAMS["rudder_command"]!r} }}
        [output]
        variables = [{", ".join(f'"gear.{o}"' for o in OUTPUTS)}]
    """)


@pytest.mark.parametrize("stop", [2.03, 0.1])
def test_short_last_step_equals_fmpy_bit_for_bit(tmp_path, stop):
    shutil.copy(our_fmu("SteeringGear"), tmp_path / "SteeringGear.fmu")
    (tmp_path / "short.toml").write_text(system(stop, "short"))
    r = shipsim("run", tmp_path / "short.toml", "-o", tmp_path / "short.csv")
    assert "the last step was shortened to end at it" in r.stderr, r.stderr
    header, rows = read_csv(tmp_path / "short.csv")
    ours = np.array(rows)
    assert header[1:] == [f"gear.{o}" for o in OUTPUTS]
    theirs = simulate_fmu(str(tmp_path / "SteeringGear.fmu"), start_time=0.0, stop_time=stop, step_size=H,
                          output_interval=H, start_values=PARAMS, output=OUTPUTS)
    assert len(theirs) == len(ours), f"FMPy {len(theirs)} rows, shipsim {len(ours)}"
    times = theirs["time"].astype(np.float64)
    # Both end at the stop time itself, after a step shorter than H.
    assert times[-1] == stop and ours[-1, 0] == stop
    assert 0 < stop - times[-2] < H
    assert times.tobytes() == ours[:, 0].tobytes(), "time grids differ"
    for j, out in enumerate(OUTPUTS, start=1):
        a = ours[:, j]
        b = theirs[out].astype(np.float64)
        diff = np.flatnonzero(a.view(np.uint64) != b.view(np.uint64))
        assert diff.size == 0, f"{out}: first difference at row {diff[0]}: shipsim {a[diff[0]]!r}, FMPy {b[diff[0]]!r}"
    # The short step changed the state: the last row differs from the one before it.
    assert ours[-1, 1] != ours[-2, 1]


def test_default_drops_the_last_step_and_the_flag_takes_it(tmp_path):
    shutil.copy(our_fmu("SteeringGear"), tmp_path / "SteeringGear.fmu")
    (tmp_path / "default.toml").write_text(system(2.03, None))
    r = shipsim("run", tmp_path / "default.toml", "-o", tmp_path / "drop.csv")
    assert "the run stopped before it, at the last grid point" in r.stderr, r.stderr
    _, drop = read_csv(tmp_path / "drop.csv")
    assert drop[-1][0] == 2.0 and len(drop) == 33
    r = shipsim("run", tmp_path / "default.toml", "--last-step", "short", "-o", tmp_path / "short.csv")
    assert "the last step was shortened" in r.stderr, r.stderr
    _, short = read_csv(tmp_path / "short.csv")
    # The same run up to t = 2.0, then one more row at the stop time.
    assert short[:-1] == drop and short[-1][0] == 2.03
