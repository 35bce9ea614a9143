"""Current.fmu in FMPy and libcosim reproduces the Rust model (models::disturbances::current) to
1e-12 of scale (case `current_004` of model-reference), and shows the 004 passing-ship peaks."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim

OUTPUTS = ["current_sway", "n_prime", "y_prime", "yaw_moment", "side_force", "bias_surge", "bias_n"]
PARAMS = {
    "seed": 6, "current_speed_final": 5.0 * 1852.0 / 3600.0, "current_direction": np.pi / 2,
    "current_start_time": 30.0, "design_current": True, "passing_ship_factor": 4.0,
    "passing_ship_time": 20.0, "white_sigma_n": 2e-5, "shaping_sigma_y": 21.178e-5,
    "walk_q_y": 1.25e-7, "bias_psi_x": 10.0, "bias_initial_n": 1.0e5,
}
# scale of each output for the 1e-12 comparison (dimensional N, Y are ~1e8 N.m, ~1e6 N)
SCALE = {"yaw_moment": 1e9, "side_force": 1e7, "bias_surge": 1e3, "bias_n": 1e5}


def test_fmpy_matches_rust_model(fmu_path, reference):
    ref = reference("current_004")
    t = np.array([r["time"] for r in ref])
    h = t[1] - t[0]
    signal = np.array([(r["time"], r["heading"]) for r in ref],
                      dtype=[("time", np.float64), ("heading", np.float64)])
    result = simulate_fmu(str(fmu_path("Current")), start_time=0.0, stop_time=t[-1], step_size=h,
                          output_interval=h, input=signal, output=OUTPUTS, start_values=PARAMS)
    assert len(result) == len(ref)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * SCALE.get(name, 1.0),
                                   err_msg=name)


def test_libcosim_matches_rust_model(fmu_path, reference):
    ref = reference("current_004")
    h = ref[1]["time"] - ref[0]["time"]
    n = len(ref) - 1
    result = run_libcosim(fmu_path("Current"), h, n, OUTPUTS,
                          inputs={"heading": [r["heading"] for r in ref]}, initial=PARAMS)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref[1:]])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * SCALE.get(name, 1.0),
                                   err_msg=name)


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
