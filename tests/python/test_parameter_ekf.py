"""ParameterEkf.fmu in FMPy and libcosim reproduces the Rust model
(models::observers::parameter_ekf) to 1e-12 of each output's scale for the same inputs (case
`parameter_ekf` of model-reference: the Esso Osaka linear model in a 10/10 zig-zag)."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim

INPUTS = ["surge_velocity_measured", "sway_velocity_measured", "yaw_rate_measured",
          "shaft_speed_measured", "rudder_angle"]
OUTPUTS = ["surge_velocity_estimate", "sway_velocity_estimate", "yaw_rate_estimate",
           "shaft_speed_estimate", "neg_y_v_estimate", "m_minus_y_r_estimate", "neg_n_v_estimate",
           "mxg_minus_n_r_estimate", "neg_y_v_mean", "m_minus_y_r_mean", "neg_n_v_mean",
           "mxg_minus_n_r_mean", "neg_y_v_std", "neg_n_v_std", "nomoto_time_constant_prime",
           "nomoto_gain_prime", "innovation_sway", "innovation_yaw_rate", "update_count"]
CASE = "parameter_ekf"


def _scale(ref, name):
    return max(1.0e-6, max(abs(r[name]) for r in ref))


def test_fmpy_matches_rust_model(fmu_path, reference):
    ref = reference(CASE)
    t = np.array([r["time"] for r in ref])
    signal = np.array([tuple([r["time"]] + [r[n] for n in INPUTS]) for r in ref],
                      dtype=[("time", np.float64)] + [(n, np.float64) for n in INPUTS])
    h = t[1] - t[0]
    result = simulate_fmu(str(fmu_path("ParameterEkf")), start_time=0.0, stop_time=t[-1],
                          step_size=h, output_interval=h, input=signal, output=OUTPUTS)
    assert len(result) == len(ref)
    np.testing.assert_array_equal(result["time"], t)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * _scale(ref, name),
                                   err_msg=name)
    # the filter has learned: -Y_v moved from half the Table 2.3 value towards 0.0244
    assert ref[-1]["neg_y_v_estimate"] > 0.018
    assert ref[-1]["update_count"] == 900


def test_libcosim_matches_rust_model(fmu_path, reference):
    ref = reference(CASE)
    h = ref[1]["time"] - ref[0]["time"]
    n = len(ref) - 1
    result = run_libcosim(fmu_path("ParameterEkf"), h, n, OUTPUTS,
                          inputs={name: [r[name] for r in ref] for name in INPUTS})
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref[1:]])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12 * _scale(ref, name),
                                   err_msg=name)
