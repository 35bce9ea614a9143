"""The hull FMUs (ContainerShip, Mariner, RrsShip, TokyoMaru, NomotoShip, SupplyVessel): outputs
independent of the communication step. Their comparison (and the Manoeuvre FMU's) with the Rust
models (models::hull, models::manoeuvre) in FMPy and libcosim, and the check that every reference
case moves its main outputs, are in test_fmu_cases.py."""
import numpy as np
import pytest
from fmpy import simulate_fmu

HULLS = ["ContainerShip", "Mariner", "RrsShip", "TokyoMaru", "NomotoShip", "SupplyVessel"]


@pytest.mark.parametrize("model", HULLS)
def test_output_independent_of_communication_step(fmu_path, model):
    """With the start values (constant inputs), communication steps of 0.1 s and 0.5 s give the
    same outputs at the common times: the hulls integrate with a fixed internal step (RK4
    sub-steps that divide both, or exact ZOH), so only round-off may differ."""
    fmu = str(fmu_path(model))
    runs = [simulate_fmu(fmu, stop_time=120.0, step_size=h, output_interval=0.5) for h in (0.1, 0.5)]
    fine, coarse = runs
    assert len(fine) == len(coarse) == 241
    for name in fine.dtype.names:
        if name == "time" or fine.dtype[name] != np.float64:
            continue
        np.testing.assert_allclose(fine[name], coarse[name], rtol=1e-9, atol=1e-9, err_msg=name)
