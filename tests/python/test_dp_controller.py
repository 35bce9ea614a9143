"""DpController.fmu in FMPy and libcosim reproduces the Rust model (models::controllers::dp) to
1e-12 of each output's scale for the same inputs (case `dp_controller` of model-reference). The
outputs have direct feedthrough: an importer samples them after the step, before the next input
is set, so row k holds tau of the inputs of row k - 1 (see the case's documentation)."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim

INPUTS = ["north_estimate", "east_estimate", "heading_estimate", "surge_velocity_estimate",
          "sway_velocity_estimate", "yaw_rate_estimate", "north_setpoint", "east_setpoint",
          "heading_setpoint"]
OUTPUTS = ["tau_surge", "tau_sway", "tau_yaw", "error_surge", "error_sway", "error_yaw"]
CASE = "dp_controller"
PARAMS = {"test_amplitude_surge": 1e5, "test_amplitude_sway": 1e5, "test_amplitude_yaw": 1e7}


def _scale(ref, name):
    return max(1.0e-3, max(abs(r[name]) for r in ref))


def test_fmpy_matches_rust_model(fmu_path, reference):
    ref = reference(CASE)
    t = np.array([r["time"] for r in ref])
    signal = np.array([tuple([r["time"]] + [r[n] for n in INPUTS]) for r in ref],
                      dtype=[("time", np.float64)] + [(n, np.float64) for n in INPUTS])
    h = t[1] - t[0]
    result = simulate_fmu(str(fmu_path("DpController")), start_time=0.0, stop_time=t[-1],
                          step_size=h, output_interval=h, input=signal, output=OUTPUTS,
                          start_values=PARAMS)
    assert len(result) == len(ref)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * _scale(ref, name),
                                   err_msg=name)
    # the PID and the test input both act
    assert max(abs(r["tau_surge"]) for r in ref) > 1e5


def test_libcosim_matches_rust_model(fmu_path, reference):
    ref = reference(CASE)
    h = ref[1]["time"] - ref[0]["time"]
    n = len(ref) - 1
    result = run_libcosim(fmu_path("DpController"), h, n, OUTPUTS,
                          inputs={name: [r[name] for r in ref] for name in INPUTS}, initial=PARAMS)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref[1:]])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * _scale(ref, name),
                                   err_msg=name)
