"""SteeringGear.fmu in FMPy and libcosim reproduces the Rust model (models::steering_gear) to
1e-12 for the same input sequence (the `steering_gear_sine` case of model-reference)."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim

OUTPUTS = ["rudder_angle", "rudder_rate", "rate_saturated_time"]


def test_fmpy_matches_rust_model(fmu_path, reference):
    ref = reference("steering_gear_sine")
    t = np.array([r["time"] for r in ref])
    signal = np.array(list(zip(t, [r["rudder_command"] for r in ref])),
                      dtype=[("time", np.float64), ("rudder_command", np.float64)])
    h = t[1] - t[0]
    result = simulate_fmu(str(fmu_path("SteeringGear")), start_time=0.0, stop_time=t[-1],
                          step_size=h, output_interval=h, input=signal, output=OUTPUTS)
    assert len(result) == len(ref)
    np.testing.assert_array_equal(result["time"], t)
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12, err_msg=name)
    # the case exercises both limiters
    assert max(abs(r["rudder_angle"]) for r in ref) > 0.38
    assert ref[-1]["rate_saturated_time"] > 1.0


def test_libcosim_matches_rust_model(fmu_path, reference):
    ref = reference("steering_gear_sine")
    commands = [r["rudder_command"] for r in ref]
    h = ref[1]["time"] - ref[0]["time"]
    n = len(ref) - 1
    result = run_libcosim(fmu_path("SteeringGear"), h, n, OUTPUTS, inputs={"rudder_command": commands})
    for name in OUTPUTS:
        expected = np.array([r[name] for r in ref[1:]])
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=1e-12, err_msg=name)
