"""PathWlsEstimator.fmu in FMPy and libcosim reproduces the Rust model
(models::controllers::wls::WlsEstimator) to 1e-12 for the same input sequence (the
`path_wls_windows` case of model-reference: three data windows of 1 L every 1.5 L, each fitted by
Levenberg-Marquardt, on the deep-water Tokyo Maru under the constant disturbance)."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim

INPUTS = ["heading", "yaw_rate", "drift_angle", "cross_track", "rudder_angle",
          "heading_estimate", "yaw_rate_estimate", "drift_angle_estimate", "cross_track_estimate"]
OUTPUTS = ["f22_estimate", "f23_estimate", "f25_estimate", "f32_estimate", "f33_estimate", "f35_estimate",
           "yaw_moment_prime_estimate", "sway_force_prime_estimate", "validity", "evaluations", "final_cost",
           "residual_sum_of_squares", "updates"]
BOOLEANS = ["estimate_valid", "loading"]
# tests/src/reference/path_wls.rs: WINDOW_START, WINDOW_LENGTH, UPDATE_CYCLE
PARAMS = {"window_start": 0.5, "window_length": 1.0, "update_cycle": 1.5}


def test_fmpy_matches_rust_model(fmu_path, reference):
    ref = reference("path_wls_windows")
    t = np.array([r["time"] for r in ref])
    signal = np.array([tuple([r["time"]] + [r[n] for n in INPUTS]) for r in ref],
                      dtype=[("time", np.float64)] + [(n, np.float64) for n in INPUTS])
    h = t[1] - t[0]
    result = simulate_fmu(str(fmu_path("PathWlsEstimator")), start_time=0.0, stop_time=t[-1],
                          step_size=h, output_interval=h, input=signal, output=OUTPUTS + BOOLEANS,
                          start_values=PARAMS)
    assert len(result) == len(ref)
    np.testing.assert_array_equal(result["time"], t)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12, err_msg=name)
    for name in BOOLEANS:
        expected = np.array([r[name] for r in ref])
        np.testing.assert_array_equal(result[name].astype(float), expected, err_msg=name)
    # three fits, each near the deep-water truth (f23 = 3.1591) from the 1.89 start (5.7359)
    assert ref[-1]["updates"] == 3.0
    assert abs(ref[-1]["f23_estimate"] - 3.1591) < 0.01


def test_libcosim_matches_rust_model(fmu_path, reference):
    ref = reference("path_wls_windows")
    h = ref[1]["time"] - ref[0]["time"]
    n = len(ref) - 1
    inputs = {name: [r[name] for r in ref] for name in INPUTS}
    result = run_libcosim(fmu_path("PathWlsEstimator"), h, n, OUTPUTS, inputs=inputs, initial=PARAMS)
    # h = 0.25 s is exact in libcosim's integer-ns clock and in FMPy's t_k = k h
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref[1:]])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12, err_msg=name)
