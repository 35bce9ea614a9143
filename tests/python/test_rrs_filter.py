"""RrsFilter.fmu in FMPy and libcosim reproduces the Rust model
(models::observers::rrs_filter) to 1e-12 of each output's scale for the same inputs (case
`rrs_filter` of model-reference)."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim

INPUTS = ["roll_measured", "heading_measured", "speed_measured", "roll_rudder", "course_rudder"]
OUTPUTS = ["roll_estimate", "roll_rate_estimate", "heel_offset_estimate", "heading_estimate",
           "yaw_rate_estimate", "yaw_bias_estimate", "yaw_e_w3_used", "yaw_k1", "speed_estimate"]
CASE = "rrs_filter"


def _scale(ref, name):
    return max(1.0e-3, max(abs(r[name]) for r in ref))


def test_fmpy_matches_rust_model(fmu_path, reference):
    ref = reference(CASE)
    t = np.array([r["time"] for r in ref])
    signal = np.array([tuple([r["time"]] + [r[n] for n in INPUTS]) for r in ref],
                      dtype=[("time", np.float64)] + [(n, np.float64) for n in INPUTS])
    h = t[1] - t[0]
    result = simulate_fmu(str(fmu_path("RrsFilter")), start_time=0.0, stop_time=t[-1],
                          step_size=h, output_interval=h, input=signal, output=OUTPUTS)
    assert len(result) == len(ref)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * _scale(ref, name),
                                   err_msg=name)
    # the roll filter has found the 0.02 rad heel, the yaw filter adapted E[w3^2]
    assert abs(ref[-1]["heel_offset_estimate"] - 0.02) < 5e-3
    assert ref[-1]["yaw_e_w3_used"] != ref[0]["yaw_e_w3_used"]


def test_libcosim_matches_rust_model(fmu_path, reference):
    ref = reference(CASE)
    h = ref[1]["time"] - ref[0]["time"]
    n = len(ref) - 1
    result = run_libcosim(fmu_path("RrsFilter"), h, n, OUTPUTS,
                          inputs={name: [r[name] for r in ref] for name in INPUTS})
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref[1:]])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * _scale(ref, name),
                                   err_msg=name)
