"""Current.fmu (models::disturbances::current) shows the passing-ship peaks of [Parsons1980, Fig. 3]
(its surrogate). Its comparison with the Rust model (case `current_parsons1980`) in FMPy and libcosim is in
test_fmu_cases.py."""
import numpy as np
from fmpy import simulate_fmu


def test_passing_ship_peak_in_fmpy(fmu_path):
    """1x passing ship at t' = 7 (one ship length = 46.98 s): N' = -20.4e-5, Y' = 48.0e-5."""
    h = 290.0 / (12 * 1852.0 / 3600.0) / 200  # 200 steps per ship length
    result = simulate_fmu(str(fmu_path("Current")), stop_time=1400 * h, step_size=h,
                          output_interval=h, output=["n_prime", "y_prime", "nondimensional_time"],
                          start_values={"passing_ship_factor": 1.0, "passing_ship_time": 7.0})
    k = int(np.argmin(result["n_prime"]))
    assert abs(result["nondimensional_time"][k] - 7.0) < 1e-9
    assert abs(result["n_prime"][k] + 20.4e-5) < 1e-12
    assert abs(np.max(result["y_prime"]) - 48.0e-5) < 1e-12
