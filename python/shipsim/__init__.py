"""shipsim: the FMI 2.0 co-simulation master for ship-control systems, from Python.

The package calls the Rust master that the ``shipsim`` command line runs (the native module
``shipsim._native``); nothing is computed in Python. Results are bit for bit those of the
command line.

Quick start::

    import shipsim

    md = shipsim.inspect("target/fmu/RrsShip.fmu")      # variables, units, start values
    s = shipsim.System.load("systems/rrs.toml")         # native TOML or OSP XML
    s.set("waves.seed", 3)
    df = s.run(stop_time=600, variables=["ship.roll", "gear.*"])   # pandas DataFrame

    with s.start(stop_time=600) as session:             # step it from Python
        while session.time < 600:
            session.set("autopilot.roll_mode", 0 if session.get("ship.roll") < 0.1 else 1)
            session.step()

    c = shipsim.Campaign.load("campaigns/rrs_polar.toml")
    table = c.run(jobs=2)                               # one KPI row per run
    table = c.run(client=dask.distributed.Client(...))  # the same on a Dask cluster

Errors are raised as :class:`ShipsimError` subclasses with the command line's message:
:class:`FmuError`, :class:`SystemFileError`, :class:`VariableError`,
:class:`SimulationError`, :class:`CheckpointError`, :class:`SessionError`. Ctrl-C stops a run cleanly (instances
terminated and freed) and raises ``KeyboardInterrupt``.
"""

from ._native import (
    CheckpointError,
    FmuError,
    SessionError,
    ShipsimError,
    SimulationError,
    SystemFileError,
    VariableError,
    __version__,
    fmu_load_count,
)
from ._system import ModelDescription, ShipsimWarning, System, Variable, inspect
from ._campaign import Campaign
from ._session import Checkpoint, Session

__all__ = [
    "Campaign",
    "Checkpoint",
    "CheckpointError",
    "FmuError",
    "ModelDescription",
    "ShipsimError",
    "Session",
    "SessionError",
    "ShipsimWarning",
    "SimulationError",
    "System",
    "SystemFileError",
    "Variable",
    "VariableError",
    "__version__",
    "fmu_load_count",
    "inspect",
]
