"""The minimal example FMU of docs/ADDING_AN_FMU.md (examples/first_order_lag), built by
`cargo xtask build-fmus` into target/fmu-examples: it passes FMPy's validation and reproduces the
closed-form step response y(t) = K u (1 - exp(-t/T)) in FMPy."""
import numpy as np
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from conftest import fmu_dir


def example_fmu():
    path = fmu_dir().parent / "fmu-examples" / "FirstOrderLag.fmu"
    assert path.exists(), f"{path} is missing: run `cargo xtask build-fmus`"
    return path


def test_example_fmu_validates_in_fmpy():
    path = example_fmu()
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert md.coSimulation.modelIdentifier == "FirstOrderLag"
    assert [v.name for v in md.modelVariables] == ["gain", "time_constant", "initial_output", "u", "y"]


def test_example_fmu_step_response_in_fmpy():
    gain, tau, u = 3.0, 0.5, 2.0
    result = simulate_fmu(str(example_fmu()), start_time=0.0, stop_time=3.0, step_size=0.01,
                          output_interval=0.01, start_values={"gain": gain, "time_constant": tau, "u": u},
                          output=["y"])
    t = result["time"]
    assert len(t) == 301
    np.testing.assert_allclose(result["y"], gain * u * (1.0 - np.exp(-t / tau)), rtol=0, atol=1e-12)
