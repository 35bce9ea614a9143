"""Sensors.fmu (models::sensors): DGPS noise sigma 2 m at 1 s; same seed identical across
importers, different seeds uncorrelated. Its comparison with the Rust model (case
`sensors_default`) in FMPy and libcosim is in test_fmu_cases.py."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim


def test_dgps_noise_and_seeds(fmu_path):
    fmu = str(fmu_path("Sensors"))
    n = 100_000
    out = ["north_measured", "east_measured"]
    a = simulate_fmu(fmu, stop_time=n * 1.0, step_size=1.0, output_interval=1.0, output=out,
                     start_values={"seed": 21})
    b = run_libcosim(fmu_path("Sensors"), 1.0, n, out, initial={"seed": 21})
    c = simulate_fmu(fmu, stop_time=n * 1.0, step_size=1.0, output_interval=1.0, output=out,
                     start_values={"seed": 22})
    assert np.array_equal(a["north_measured"][1:], b["north_measured"])
    assert abs(np.std(a["north_measured"]) / 2.0 - 1.0) < 0.01
    assert abs(np.corrcoef(a["north_measured"], a["east_measured"])[0, 1]) < 0.05
    assert abs(np.corrcoef(a["north_measured"], c["north_measured"])[0, 1]) < 0.05
