"""PassiveObserver.fmu in FMPy and libcosim reproduces the Rust model
(models::observers::passive_observer) to 1e-12 of each output's scale for the same inputs (case
`passive_observer` of model-reference)."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim

INPUTS = ["north_measured", "east_measured", "heading_measured", "tau_surge", "tau_sway", "tau_yaw"]
OUTPUTS = ["north_estimate", "east_estimate", "heading_estimate", "surge_velocity_estimate",
           "north_wf_estimate", "bias_north_estimate", "bias_yaw_estimate"]
CASE = "passive_observer"


def _scale(ref, name):
    return max(1.0e-3, max(abs(r[name]) for r in ref))


def test_fmpy_matches_rust_model(fmu_path, reference):
    ref = reference(CASE)
    t = np.array([r["time"] for r in ref])
    signal = np.array([tuple([r["time"]] + [r[n] for n in INPUTS]) for r in ref],
                      dtype=[("time", np.float64)] + [(n, np.float64) for n in INPUTS])
    h = t[1] - t[0]
    result = simulate_fmu(str(fmu_path("PassiveObserver")), start_time=0.0, stop_time=t[-1],
                          step_size=h, output_interval=h, input=signal, output=OUTPUTS)
    assert len(result) == len(ref)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * _scale(ref, name),
                                   err_msg=name)
    # the wave filter has picked up the 3 m, 0.9 rad/s motion
    assert max(abs(r["north_wf_estimate"]) for r in ref[300:]) > 1.0


def test_libcosim_matches_rust_model(fmu_path, reference):
    ref = reference(CASE)
    h = ref[1]["time"] - ref[0]["time"]
    n = len(ref) - 1
    result = run_libcosim(fmu_path("PassiveObserver"), h, n, OUTPUTS,
                          inputs={name: [r[name] for r in ref] for name in INPUTS})
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref[1:]])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * _scale(ref, name),
                                   err_msg=name)
