"""Adaptive path control of the Tokyo Maru [Parsons1980] (issue 8 system 2) in libcosim.

The system files systems/path_control_*.toml (TokyoMaru + SteeringGear + Current + Sensors +
PathKalmanFilter + PathController), exported with `shipsim export-osp`, run in libcosim
(libcosimpy) with the same results as in shipsim, to 1e-12: the passing-ship file with its
defaults (scenario S3 with the report's measurement noise, seed 1; a LinearTransformation carries
the B/2 track offset), and the design-current file as scenario S7 (deep water, the
[Parsons1980, Table 8] design reached through the controller's adaptation path) with noise seed 7.

Environment: SHIPSIM_BIN (the master), SHIPSIM_FMU_DIR (our built FMUs).
"""
import re
import shutil

import pytest

from conftest import ROOT, fmu_dir
from test_master_interop import assert_same_as_libcosim, read_csv, shipsim

FMUS = ["Current", "TokyoMaru", "SteeringGear", "Sensors", "PathKalmanFilter", "PathController"]

# Start values changed in the system file for a scenario (the OSP file carries no --set).
S7 = {
    "ship": {"deep_water": "true"},
    "kf": {"adapted_depth_ratio": "1e300"},
    "ctl": {"adaptation": "2", "dither_enabled": "true"},
    "sensors": {"seed": "7"},
}


def localise(system, tmp_path, changes=None):
    """Copies the system file and our FMUs into tmp_path; FMU paths become bare file names and
    `changes` {instance: {variable: value}} are written into the instances' parameter tables."""
    for name in FMUS:
        src = fmu_dir() / f"{name}.fmu"
        if not src.exists():
            raise RuntimeError(f"{src} is missing: run `cargo xtask build-fmus` first")
        shutil.copy(src, tmp_path / f"{name}.fmu")
    text = (ROOT / "systems" / system).read_text()
    text = text.replace("../target/fmu/", "")
    for inst, values in (changes or {}).items():
        block = re.search(r'name = "%s"\n.*?\nparameters = \{(.*?)\}' % inst, text, re.S)
        assert block, inst
        params = block.group(1)
        for var, value in values.items():
            new, n = re.subn(r"\b%s = [^,}]+" % var, f"{var} = {value}", params)
            params = new if n else f"{params.rstrip()}, {var} = {value} "
        text = text[: block.start(1)] + params + text[block.end(1):]
    path = tmp_path / system
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    "system,changes,label",
    [
        ("path_control_passing_ship.toml", None, "S3 noisy"),
        ("path_control_current.toml", S7, "S7 noisy"),
    ],
)
def test_path_control_equals_libcosim(tmp_path, system, changes, label):
    toml = localise(system, tmp_path, changes)
    out = tmp_path / "shipsim.csv"
    shipsim("run", toml, "-o", out, "-q")
    osp = tmp_path / "OspSystemStructure.xml"
    shipsim("export-osp", toml, "-o", osp)
    header, rows = read_csv(out)
    col = {h: i for i, h in enumerate(header)}
    eta = [r[col["ship.cross_track"]] for r in rows]
    # Not trivial: the loop moves the ship by metres and the noise reaches the filter.
    assert max(eta) - min(eta) > 5.0, label
    assert any(r[col["kf.cross_track_estimate"]] != r[col["ship.cross_track"]] for r in rows[1:])
    if changes is S7:
        # the adaptation path really produced the [Parsons1980, Table 8] design
        assert abs(rows[-1][col["ctl.gain_drift_angle"]] - 1.8986) < 2e-4
    assert_same_as_libcosim(osp, out)
