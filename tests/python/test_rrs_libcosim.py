"""Rudder roll stabilization [Klugt1987] (issue 8 system 1) in libcosim.

systems/rrs.toml (RrsShip + SteeringGear + Waves + Wind + Sensors + RrsFilter + RrsAutopilot, multi-rate,
wave moments mapped onto rudder-equivalent disturbances by LinearTransformation functions),
exported with `shipsim export-osp`, runs in libcosim (libcosimpy) with the same results as in
shipsim, RRS on and off.

Environment: SHIPSIM_BIN (the master), SHIPSIM_FMU_DIR (our built FMUs).
"""
import pytest

from test_master_interop import assert_same_as_libcosim, read_csv, shipsim
from test_path_control_libcosim import localise

FMUS = ["RrsShip", "SteeringGear", "Waves", "Wind", "Sensors", "RrsFilter", "RrsAutopilot"]


@pytest.mark.parametrize("roll_mode", ["1", "0"])
def test_rrs_equals_libcosim(tmp_path, roll_mode, monkeypatch):
    import test_path_control_libcosim as pc

    monkeypatch.setattr(pc, "FMUS", FMUS)
    toml = localise("rrs.toml", tmp_path, {"autopilot": {"roll_mode": roll_mode}})
    text = toml.read_text().replace("stop_time = 1200.0", "stop_time = 300.0")
    toml.write_text(text)
    out = tmp_path / "shipsim.csv"
    shipsim("run", toml, "-o", out, "-q")
    osp = tmp_path / "OspSystemStructure.xml"
    shipsim("export-osp", toml, "-o", osp)
    header, rows = read_csv(out)
    col = {h: i for i, h in enumerate(header)}
    roll = [r[col["ship.roll"]] for r in rows]
    assert max(roll) - min(roll) > 0.05  # the sea really rolls the ship (rad)
    rudder = [r[col["gear.rudder_angle"]] for r in rows]
    if roll_mode == "1":
        assert max(rudder) - min(rudder) > 0.1  # and the RRS really moves the rudder
    assert_same_as_libcosim(osp, out)
