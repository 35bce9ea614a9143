"""Campaign KPIs checked independently with numpy: `shipsim campaign run` on a small RRS
campaign, then `shipsim run` of two of its runs with the same values (--set, full precision),
and every KPI recomputed from that CSV with numpy, to 1e-12 relative."""
import csv
import os
import pathlib
import subprocess

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
DEG = 180.0 / np.pi

CAMPAIGN = f"""
system = "{ROOT / 'systems' / 'rrs.toml'}"
stop_time = 150.0
seed = 11
[[factors]]
name = "hs"
variable = "waves.significant_wave_height"
values = [2.5, 4.0]
[replications]
count = 2
seeds = ["waves.seed", "wind.seed"]
[[kpis]]
name = "roll_var"
variable = "ship.roll"
stat = "variance"
window = [30, 150]
scale = {DEG!r}
[[kpis]]
name = "roll_mean"
variable = "ship.roll"
stat = "mean"
window = [30, 150]
[[kpis]]
name = "roll_std"
variable = "ship.roll"
stat = "std"
window = [30, 150]
[[kpis]]
name = "rudder_rms"
variable = "gear.rudder_angle"
stat = "rms"
window = [30, 150]
[[kpis]]
name = "rudder_min"
variable = "gear.rudder_angle"
stat = "min"
[[kpis]]
name = "rudder_max"
variable = "gear.rudder_angle"
stat = "max"
[[kpis]]
name = "roll_max_abs"
variable = "ship.roll"
stat = "max_abs"
window = [30, 150]
[[kpis]]
name = "heading_final"
variable = "ship.heading"
stat = "final"
[[kpis]]
name = "roll_above"
variable = "ship.roll"
stat = "time_above"
threshold = 0.01
window = [30, 150]
"""


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def numpy_kpis(data):
    t = data["time"]
    w = (t >= 30) & (t <= 150)
    roll, rudder, heading = data["ship.roll"], data["gear.rudder_angle"], data["ship.heading"]
    rw = roll[w]
    tw = t[w]
    above = np.sum(np.diff(tw)[rw[:-1] > 0.01])
    return {
        "roll_var": np.var(rw * DEG),
        "roll_mean": np.mean(rw),
        "roll_std": np.std(rw),
        "rudder_rms": np.sqrt(np.mean(rudder[w] ** 2)),
        "rudder_min": np.min(rudder),
        "rudder_max": np.max(rudder),
        "roll_max_abs": np.max(np.abs(rw)),
        "heading_final": heading[-1],
        "roll_above": above,
    }


def test_campaign_kpis_agree_with_numpy_over_the_csv_of_shipsim_run(tmp_path):
    file = tmp_path / "c.toml"
    file.write_text(CAMPAIGN)
    out = tmp_path / "out"
    subprocess.run([BIN, "campaign", "run", "-q", "-o", str(out), str(file)], check=True)
    with open(out / "runs.csv") as f:
        table = list(csv.DictReader(f))
    assert len(table) == 4 and all(r["status"] == "ok" for r in table)
    shown = subprocess.run([BIN, "campaign", "show", "--runs", str(file)], check=True,
                           capture_output=True, text=True).stdout.splitlines()
    sets = {int(l.split()[0]): l.split()[1:] for l in shown if l[:6].strip().isdigit()}
    for i in (0, 3):
        csv_path = tmp_path / f"run{i}.csv"
        cmd = [BIN, "run", "-q", "--stop-time", "150", "-o", str(csv_path), str(ROOT / "systems" / "rrs.toml")]
        for s in sets[i]:
            cmd += ["--set", s]
        subprocess.run(cmd, check=True)
        expected = numpy_kpis(read_csv(csv_path))
        row = table[i]
        for name, value in expected.items():
            got = float(row[name])
            assert got == value or abs(got - value) <= 1e-12 * abs(value), (i, name, got, value)
        assert expected["roll_above"] > 0 and expected["roll_var"] > 0
