"""PathController.fmu in FMPy and libcosim reproduces the Rust model
(models::controllers::path) to 1e-12 for the same input sequence (the `path_controller_adaptive`
case of model-reference: dither windows and two partial adaptations of f23/f25)."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim

INPUTS = ["heading", "yaw_rate", "drift_angle", "cross_track", "rudder_angle", "yaw_moment_prime",
          "sway_force_prime", "f22_estimate", "f23_estimate", "f25_estimate", "f32_estimate",
          "f33_estimate", "f35_estimate"]
OUTPUTS = ["rudder_command", "gain_yaw_moment", "design_f23", "gain_updates"]
PARAMS = {"adaptation": 2, "dither_enabled": True, "dither_start": 1.0, "dither_window": 1.0,
          "dither_cycle": 3.0}


def test_fmpy_matches_rust_model(fmu_path, reference):
    ref = reference("path_controller_adaptive")
    t = np.array([r["time"] for r in ref])
    signal = np.array([tuple([r["time"]] + [r[n] for n in INPUTS]) for r in ref],
                      dtype=[("time", np.float64)] + [(n, np.float64) for n in INPUTS])
    h = t[1] - t[0]
    result = simulate_fmu(str(fmu_path("PathController")), start_time=0.0, stop_time=t[-1],
                          step_size=h, output_interval=h, input=signal, output=OUTPUTS,
                          start_values=PARAMS)
    assert len(result) == len(ref)
    np.testing.assert_array_equal(result["time"], t)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12, err_msg=name)
    # the case exercises the dither (+-0.5 rad) and two gain updates
    commands = {r["rudder_command"] for r in ref}
    assert 0.5 in commands and -0.5 in commands
    assert ref[-1]["gain_updates"] == 2.0


def test_libcosim_matches_rust_model(fmu_path, reference):
    ref = reference("path_controller_adaptive")
    h = ref[1]["time"] - ref[0]["time"]
    n = len(ref) - 1
    inputs = {name: [r[name] for r in ref] for name in INPUTS}
    result = run_libcosim(fmu_path("PathController"), h, n, OUTPUTS, inputs=inputs, initial=PARAMS)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref[1:]])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12, err_msg=name)
