"""Every FMU we build: FMPy validates it, FMPy and libcosim simulate it, and the two agree.

FMPy's `validate_fmu` checks the XML schema, the causality/variability/initial rules, units and
ModelStructure (it never loads the binary); simulating exercises the binary.
"""
import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from conftest import all_fmus
from cosim import real_outputs, run_libcosim

FMUS = all_fmus()
IDS = [f.stem for f in FMUS]


@pytest.mark.parametrize("fmu", FMUS, ids=IDS)
def test_fmpy_validate_finds_no_problems(fmu):
    problems = validate_fmu(str(fmu))
    assert problems == [], "\n".join(problems)


@pytest.mark.parametrize("fmu", FMUS, ids=IDS)
def test_capabilities_declared(fmu):
    cs = read_model_description(str(fmu)).coSimulation
    assert cs.modelIdentifier == fmu.stem
    assert cs.canHandleVariableCommunicationStepSize
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    assert not cs.canBeInstantiatedOnlyOncePerProcess
    assert not cs.needsExecutionTool


@pytest.mark.parametrize("fmu", FMUS, ids=IDS)
def test_fmpy_and_libcosim_agree_on_the_default_experiment(fmu):
    """Both importers run the FMU with its start values for 200 steps; every Real output agrees
    to 1e-12 at every step (same FMU, same inputs: the importers must not matter)."""
    md = read_model_description(str(fmu))
    h = float(md.defaultExperiment.stepSize)
    n = 200
    outputs = list(real_outputs(fmu))
    result = simulate_fmu(str(fmu), start_time=0.0, stop_time=n * h, step_size=h, output_interval=h,
                          output=outputs)
    assert len(result) == n + 1
    cosim = run_libcosim(fmu, h, n, outputs)
    for name in outputs:
        ours = result[name][1:]
        assert np.all(np.isfinite(ours)), name
        np.testing.assert_allclose(cosim[name], ours, rtol=0, atol=1e-12, err_msg=name)


@pytest.mark.parametrize("fmu", FMUS, ids=IDS)
def test_fmpy_variable_step_and_state_rollback(fmu):
    """FMPy drives the FMU with uneven communication steps (canHandleVariableCommunicationStepSize)
    and FMU-state get/set: restoring a state and repeating the steps gives identical outputs."""
    from fmpy import extract, instantiate_fmu

    md = read_model_description(str(fmu))
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    refs = [v.valueReference for v in outputs]
    unzipdir = extract(str(fmu))
    slave = instantiate_fmu(unzipdir, md, fmi_type="CoSimulation")
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        t = 0.0
        for h in (0.01, 0.003, 0.05):
            slave.doStep(t, h)
            t += h
        state = slave.getFMUstate()
        first = []
        t0 = t
        for h in (0.02, 0.007, 0.1):
            slave.doStep(t, h)
            t += h
            first.append(slave.getReal(refs))
        slave.setFMUstate(state)
        t = t0
        again = []
        for h in (0.02, 0.007, 0.1):
            slave.doStep(t, h)
            t += h
            again.append(slave.getReal(refs))
        assert first == again
        serialized = slave.serializeFMUstate(state)
        restored = slave.deSerializeFMUstate(serialized)
        slave.setFMUstate(restored)
        t = t0
        for h, row in zip((0.02, 0.007, 0.1), first):
            slave.doStep(t, h)
            t += h
            assert slave.getReal(refs) == row
        slave.freeFMUstate(state)
        slave.freeFMUstate(restored)
        slave.terminate()
    finally:
        slave.freeInstance()
