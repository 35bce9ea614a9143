"""Wind.fmu (models::disturbances::wind): same seed identical across importers, other seed
uncorrelated. Its comparison with the Rust model (case `wind_gusts`) in FMPy and libcosim is in
test_fmu_cases.py."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim


def test_seeds(fmu_path):
    fmu = str(fmu_path("Wind"))
    n, h = 100_000, 20.0
    a = simulate_fmu(fmu, stop_time=n * h, step_size=h, output_interval=h,
                     output=["true_wind_speed"], start_values={"seed": 1, "internal_step": 1.0})
    b = run_libcosim(fmu_path("Wind"), h, n, ["true_wind_speed"], initial={"seed": 1, "internal_step": 1.0})
    c = simulate_fmu(fmu, stop_time=n * h, step_size=h, output_interval=h,
                     output=["true_wind_speed"], start_values={"seed": 2, "internal_step": 1.0})
    assert np.array_equal(a["true_wind_speed"][1:], b["true_wind_speed"])
    assert abs(np.std(a["true_wind_speed"]) / 1.5 - 1.0) < 0.03
    assert abs(np.corrcoef(a["true_wind_speed"], c["true_wind_speed"])[0, 1]) < 0.05
