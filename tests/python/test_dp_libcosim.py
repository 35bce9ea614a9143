"""Dynamic positioning with the passive observer [Fossen1999] (issue 8 system 4) in libcosim.

systems/dp_observer.toml (SupplyVessel + Current bias + Waves + Sensors + PassiveObserver +
DpController, multi-rate 0.1 s / 1 s), exported with `shipsim export-osp`, runs in libcosim
(libcosimpy) with the same results as in shipsim: the DP closed loop as the file stands, and the
paper's open-loop simulation study ([Fossen1999, eq. (61)] thrust, Markov bias with T = 1000 s) as
tests/src/studies/dp_observer.rs runs it. The stop time is shortened to 1200 s and every base
step recorded (decimation 1) so that each libcosim step is compared.

Tolerance 0: the runs are bit-identical. (They were not while shipsim handed the FMUs t0 + k*h and
h itself while libcosim hands its nanosecond clock's t_k and fl(t_k+1) - fl(t_k): the ship's state
then differed by one ulp from t = 0.3 s, and the closed loop carried it to 2e-10 in the bias
estimate J M J^T b_hat, a difference of 1e7-sized terms. shipsim now keeps libcosim's clock,
master/src/run/time_grid.rs, TimeGrid.)

Environment: SHIPSIM_BIN (the master), SHIPSIM_FMU_DIR (our built FMUs).
"""
import re
import shutil

import pytest

from conftest import ROOT, fmu_dir
from test_master_interop import assert_same_as_libcosim, read_csv, shipsim

FMUS = ["SupplyVessel", "Current", "Waves", "Sensors", "PassiveObserver", "DpController"]

OPEN_LOOP = {
    "dp": {"bandwidth_surge": "0.0", "bandwidth_sway": "0.0", "bandwidth_yaw": "0.0",
           "test_amplitude_surge": "1000.0", "test_amplitude_sway": "1000.0",
           "test_amplitude_yaw": "1000.0"},
    "bias": {"bias_time_constant": "1000.0", "seed": "3", "bias_psi_x": "1000.0",
             "bias_psi_y": "1000.0", "bias_psi_n": "10000.0", "bias_initial_x": "20000.0",
             "bias_initial_y": "-20000.0", "bias_initial_n": "100000.0"},
}


def localise(tmp_path, changes=None):
    """Copies systems/dp_observer.toml and our FMUs into tmp_path: bare FMU file names, 1200 s,
    decimation 1, and `changes` {instance: {variable: value}} written into the parameter tables."""
    for name in FMUS:
        src = fmu_dir() / f"{name}.fmu"
        if not src.exists():
            raise RuntimeError(f"{src} is missing: run `cargo xtask build-fmus` first")
        shutil.copy(src, tmp_path / f"{name}.fmu")
    text = (ROOT / "systems" / "dp_observer.toml").read_text()
    text = text.replace("../target/fmu/", "")
    text, n = re.subn(r"stop_time = [0-9.]+", "stop_time = 1200.0", text)
    assert n == 1
    text, n = re.subn(r"decimation = \d+", "decimation = 1", text)
    assert n == 1
    for inst, values in (changes or {}).items():
        block = re.search(r'name = "%s"\n[^\[]*?parameters = \{(.*?)\}' % inst, text, re.S)
        assert block, inst
        params = block.group(1)
        for var, value in values.items():
            new, n = re.subn(r"\b%s = [^,}]+" % var, f"{var} = {value}", params)
            params = new if n else f"{params.rstrip()}, {var} = {value} "
        text = text[: block.start(1)] + params + text[block.end(1):]
    path = tmp_path / "dp_observer.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("changes,label", [(None, "DP closed loop"), (OPEN_LOOP, "Eq. 61 open loop")])
def test_dp_observer_equals_libcosim(tmp_path, changes, label):
    toml = localise(tmp_path, changes)
    out = tmp_path / "shipsim.csv"
    shipsim("run", toml, "-o", out, "-q")
    osp = tmp_path / "OspSystemStructure.xml"
    shipsim("export-osp", toml, "-o", osp)
    header, rows = read_csv(out)
    col = {h: i for i, h in enumerate(header)}
    assert len(rows) == 12001, label
    # Not trivial: waves of metres reach the measurement, the observer estimates a bias, and the
    # thrust acts (the PID in the closed loop, [Fossen1999, eq. (61)] in the open loop).
    meas = [r[col["sensors.north_measured"]] for r in rows]
    assert max(meas) - min(meas) > 5.0, label
    assert max(abs(r[col["observer.bias_north_estimate"]]) for r in rows) > 1e4, label
    assert max(abs(r[col["dp.tau_surge"]]) for r in rows[10:]) > 500.0, label
    worst = assert_same_as_libcosim(osp, out, tol=0.0)
    print(f"{label}: worst |shipsim - libcosim| = {worst:.3e}")
