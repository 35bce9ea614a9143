"""Small helpers around FMPy and libcosimpy used by several test files."""
import numpy as np
from fmpy import read_model_description, simulate_fmu
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimManipulator import CosimManipulator
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

NS = 1_000_000_000


def real_outputs(fmu):
    md = read_model_description(str(fmu))
    return {v.name: v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"}


def variables_by_name(fmu):
    md = read_model_description(str(fmu))
    return {v.name: v for v in md.modelVariables}


def run_libcosim(fmu, step, n_steps, outputs, inputs=None, initial=None):
    """Runs one FMU alone in libcosim (fixed-step algorithm).

    `outputs`: variable names recorded after every step: row k holds the values at t_(k+1).
    `inputs`: optional {name: sequence}; value k is held over the step from t_k (initial value,
    then the override manipulator before each step).
    `initial`: optional {name: value} initial values (parameters).
    Returns {name: np.array of n_steps samples}.
    """
    variables = variables_by_name(fmu)
    step_ns = int(round(step * NS))
    execution = CosimExecution.from_step_size(step_ns)
    index = execution.add_local_slave(CosimLocalSlave(fmu_path=str(fmu), instance_name="fmu"))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    manipulator = CosimManipulator.create_override()
    execution.add_manipulator(manipulator)
    for name, value in (initial or {}).items():
        v = variables[name]
        if v.type == "Real":
            execution.real_initial_value(index, v.valueReference, float(value))
        elif v.type == "Boolean":
            execution.boolean_initial_value(index, v.valueReference, bool(value))
        else:
            execution.integer_initial_value(index, v.valueReference, int(value))
    for name, seq in (inputs or {}).items():
        execution.real_initial_value(index, variables[name].valueReference, float(seq[0]))
    refs = [variables[n].valueReference for n in outputs]
    rows = []
    for k in range(n_steps):
        for name, seq in (inputs or {}).items():
            manipulator.slave_real_values(index, [variables[name].valueReference], [float(seq[k])])
        assert execution.step(1), f"libcosim step {k} failed for {fmu}"
        rows.append(observer.last_real_values(index, refs))
    return {n: np.array([r[i] for r in rows]) for i, n in enumerate(outputs)}


# --- runs on the rows of a model-reference case (see tests/src/reference/mod.rs for the CSV) ---


def column(ref, name):
    """One column of reference rows as an array."""
    return np.array([r[name] for r in ref])


def reference_step(ref):
    """The communication step of a reference case: t_1 - t_0."""
    return ref[1]["time"] - ref[0]["time"]


def input_signal(ref, inputs):
    """FMPy's input signal for `inputs` from reference rows: value k is set at t_k."""
    return np.array([tuple([r["time"]] + [r[n] for n in inputs]) for r in ref],
                    dtype=[("time", np.float64)] + [(n, np.float64) for n in inputs])


def fmpy_on_reference(fmu, ref, inputs, outputs, start_values=None):
    """Runs the FMU in FMPy over the reference's time grid with its inputs: result row k holds the
    outputs at t_k (row 0 after initialization), as the reference rows do."""
    t = column(ref, "time")
    h = t[1] - t[0]
    return simulate_fmu(str(fmu), start_time=0.0, stop_time=t[-1], step_size=h, output_interval=h,
                        input=input_signal(ref, inputs), output=list(outputs),
                        start_values=dict(start_values or {}))


def libcosim_on_reference(fmu, ref, inputs, outputs, initial=None):
    """Runs the FMU in libcosim with the reference's step and inputs for len(ref) - 1 steps: sample k
    holds the outputs at t_(k+1), i.e. compares with ref[1:]."""
    return run_libcosim(fmu, reference_step(ref), len(ref) - 1, list(outputs),
                        inputs={name: [r[name] for r in ref] for name in inputs},
                        initial=dict(initial or {}))
