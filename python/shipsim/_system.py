"""Single runs: :func:`inspect` and :class:`System`."""

from __future__ import annotations

import difflib
import math
import os
import warnings
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, Optional, Union

import numpy as np

from . import _native
from ._native import VariableError

PathLike = Union[str, "os.PathLike[str]"]


class ShipsimWarning(UserWarning):
    """A warning of the master (e.g. a system-file check that does not stop the run)."""


@dataclass(frozen=True)
class Variable:
    """One variable of an FMU's model description (FMI 2.0, sec. 2.2.7)."""

    name: str
    value_reference: int
    type: str
    causality: str
    variability: str
    initial: Optional[str]
    start: Any
    unit: Optional[str]
    display_unit: Optional[str]
    declared_type: Optional[str]
    min: Any
    max: Any
    nominal: Optional[float]
    description: Optional[str]


@dataclass(frozen=True)
class ModelDescription:
    """An FMU's model description, as :func:`inspect` reads it."""

    path: str
    model_name: str
    fmi_version: str
    guid: str
    description: Optional[str]
    generation_tool: Optional[str]
    model_identifier: str
    capabilities: Dict[str, bool]
    default_experiment: Dict[str, Optional[float]]
    variables: List[Variable] = field(repr=False)

    def variable(self, name: str) -> Variable:
        """The variable called ``name`` (:class:`VariableError` with close names if none)."""
        for v in self.variables:
            if v.name == name:
                return v
        close = difflib.get_close_matches(name, [v.name for v in self.variables], n=3)
        hint = f" (did you mean {', '.join(repr(c) for c in close)}?)" if close else ""
        raise VariableError(f"{self.path}: no variable '{name}'{hint}")

    def by_causality(self, causality: str) -> List[Variable]:
        """The variables of one causality: parameter, input, output, local, ..."""
        return [v for v in self.variables if v.causality == causality]

    def to_frame(self):
        """The variables as a pandas DataFrame indexed by name."""
        import pandas as pd

        rows = [v.__dict__ for v in self.variables]
        return pd.DataFrame(rows).set_index("name")


def inspect(path: PathLike) -> ModelDescription:
    """Reads an FMU's model description without loading its binary: variables with their
    type, causality, variability, units, start values and ranges; capabilities; default
    experiment. Raises :class:`FmuError` for an archive that cannot be used."""
    d = _native.inspect(os.fspath(path))
    variables = [Variable(**v) for v in d.pop("variables")]
    d["path"] = os.fspath(d["path"])
    return ModelDescription(variables=variables, **d)


def _have_pandas() -> bool:
    try:
        import pandas  # noqa: F401
    except ImportError:
        return False
    return True


class Columns(dict):
    """The result of :meth:`System.run` without pandas: ``time`` and one numpy array per
    recorded variable; ``units`` (column -> unit or None) and ``summary`` as attributes."""

    units: Dict[str, Optional[str]]
    summary: Dict[str, Any]


_DTYPES = {"Real": np.float64, "Integer": np.int32, "Enumeration": np.int32, "Boolean": np.bool_}


class System:
    """A coupled system (native TOML or OSP ``OspSystemStructure.xml``) with its FMUs loaded
    once; every :meth:`run` makes fresh instances, so runs are independent and repeatable.

    Threads: several threads may call :meth:`run` on one System at the same time (each run has
    its own instances and copy of the values; the GIL is released while it runs). Changing the
    System (:meth:`set`, ``strict_units = ...``) while a run of it is in progress raises
    :class:`ShipsimError` saying it is running, and changes nothing: set values before or
    after the runs, or load one System per thread."""

    def __init__(self, native: "_native.System"):
        self._native = native

    @classmethod
    def load(cls, path: PathLike) -> "System":
        """Reads a system file and loads its FMUs. Raises :class:`SystemFileError` for a file
        that cannot be read or parsed, :class:`FmuError` for an FMU that cannot be loaded."""
        return cls(_native.System.load(os.fspath(path)))

    def set(self, name: str, value: Union[bool, int, float, str]) -> "System":
        """Sets a parameter or start value, as ``shipsim run --set name=value`` does: ``name``
        is ``instance.variable``; a str is parsed by the variable's type. An Integer (or
        Enumeration) variable takes an int or a whole float (``3.0``, ``numpy.float64(3.0)``),
        as campaign factors do. Returns the system, so calls chain. Raises
        :class:`VariableError` for an unknown instance or variable, and for a number the
        variable cannot take (a float that is not whole, or an int outside the Integer range,
        which the message names), and :class:`ShipsimError` while the system is running in
        another thread (see the class's notes on threads)."""
        self._native.set(name, value)
        return self

    @property
    def source(self) -> str:
        return os.fspath(self._native.source)

    @property
    def start_time(self) -> float:
        return self._native.start_time

    @property
    def stop_time(self) -> Optional[float]:
        return self._native.stop_time

    @property
    def step_size(self) -> float:
        return self._native.step_size

    @property
    def algorithm(self) -> str:
        return self._native.algorithm

    @property
    def strict_units(self) -> bool:
        """Unit mismatches across connections are errors (True, the default for native TOML)
        or warnings (False, the default for OSP XML, as libcosim does not check units), like
        ``shipsim run --strict-units``."""
        return self._native.strict_units

    @strict_units.setter
    def strict_units(self, strict: bool) -> None:
        self._native.strict_units = bool(strict)

    @property
    def instances(self) -> Dict[str, str]:
        """Instance name -> FMU path, in system order."""
        return {name: os.fspath(p) for name, p in self._native.instances}

    @property
    def connections(self) -> List[tuple]:
        """(from, to, gain, offset) per connection."""
        return list(self._native.connections)

    @property
    def values(self) -> Dict[str, str]:
        """The values set on instances (by the file and :meth:`set`), as text."""
        return dict(self._native.values())

    def inspect(self, instance: str) -> ModelDescription:
        """The model description of an instance's FMU."""
        try:
            return inspect(self.instances[instance])
        except KeyError:
            close = difflib.get_close_matches(instance, list(self.instances), n=3)
            hint = f" (did you mean {', '.join(repr(c) for c in close)}?)" if close else ""
            raise VariableError(f"{self.source}: no instance '{instance}'{hint}") from None

    def check(self) -> List[str]:
        """Validates the system against its FMUs (``shipsim check``); returns the warnings."""
        return list(self._native.check())

    def run(
        self,
        stop_time: Optional[float] = None,
        variables: Union[str, Iterable[str], None] = None,
        *,
        start_time: Optional[float] = None,
        step_size: Optional[float] = None,
        algorithm: Optional[str] = None,
        verbose: bool = False,
        as_frame: Optional[bool] = None,
        isolate=None,
        call_timeout: Optional[float] = None,
        real_time: bool = False,
        real_time_factor: Optional[float] = None,
    ):
        """Runs the system and returns the recorded variables.

        ``variables``: a list of ``instance.variable`` or ``instance.*`` (every output of the
        instance), or one of them as a str; default: the system file's ``[output]`` list, else
        every output. ``stop_time``,
        ``start_time``, ``step_size`` [s] and ``algorithm`` override the file's.
        ``algorithm`` is read as in system files and by ``shipsim run --algorithm``, in any
        case: ``"jacobi"``, or ``"gauss-seidel"`` (also ``"gauss_seidel"``, ``"gauss seidel"``,
        ``"gaussseidel"``, ``"seidel"``); another name raises ``ValueError``. An OSP or SSP
        file without an end time needs ``stop_time`` (as ``shipsim run`` needs
        ``--stop-time``): without it the run raises :class:`SystemFileError`.

        Returns a pandas DataFrame indexed by time [s], one column per variable, with
        ``df.attrs["units"]`` (column -> unit), ``df.attrs["summary"]`` (steps, wall time,
        real-time factor) and ``df.attrs["warnings"]``; without pandas (or with
        ``as_frame=False``), a :class:`Columns` dict of numpy arrays with ``time``.

        ``isolate`` runs FMU instances out of process (docs/isolation.md), like ``shipsim run
        --isolate``, with the same values and messages: ``True`` or ``"all"`` (every instance),
        ``"foreign"`` (FMUs not built by this project), instance names separated by commas
        (``"gear,autopilot"``) or a list of them; ``None`` or ``False``: none. A name that is no
        instance raises :class:`VariableError`, an empty string ``ValueError``. A segfault,
        ``abort()``, ``exit()`` or hang of an isolated FMU then raises
        :class:`SimulationError` naming the instance, the call and the time, and this Python
        process lives on. ``call_timeout`` [s] (a positive number, at most 1e9; else
        ``ValueError``) kills an isolated FMU call that runs longer. Instances with
        ``isolate = true`` in the system file are isolated whatever the argument.

        ``real_time=True`` paces the run to the wall clock, ``real_time_factor=X`` at X times
        real time (a positive number; else ``ValueError``), as ``shipsim run --real-time``
        (``--real-time-factor X``) does, through the same runner: each macro step waits for
        its deadline, a late step is counted, never skipped. The rows are the unpaced run's, bit
        for bit; the summary is then ``start_time``, ``end_time``, ``macro_steps``,
        ``wall_time``, ``paced_factor``, ``lateness_median``, ``lateness_p99``,
        ``lateness_max`` [s] and ``overruns`` (late steps), and a run that cannot keep up adds
        its messages to the warnings. The system file's ``[[io]]`` channels are not opened.

        The GIL is released while the master runs. Ctrl-C stops the run at its next
        communication point and raises ``KeyboardInterrupt``. FMU log messages go to the
        ``shipsim.fmu`` logger (warnings and worse; everything with ``verbose``).
        """
        if isinstance(variables, str):
            variables = [variables]  # one pattern, not its characters
        isolate, names = _isolation(isolate)
        factor = None
        if real_time_factor is not None:
            factor = float(real_time_factor)
            if not (factor > 0 and math.isfinite(factor)):
                raise ValueError(f"real_time_factor = {real_time_factor!r}: a positive number")
        elif real_time:
            factor = 1.0
        raw = self._native.run(
            stop_time=stop_time,
            variables=None if variables is None else list(variables),
            start_time=start_time,
            step_size=step_size,
            algorithm=algorithm,
            verbose=verbose,
            isolate=isolate,
            isolate_instances=names,
            call_timeout=call_timeout,
            real_time_factor=factor,
        )
        for w in raw["warnings"]:
            warnings.warn(w, ShipsimWarning, stacklevel=2)
        return _frame(raw, as_frame, raw["summary"])

    def start(
        self,
        stop_time: Optional[float] = None,
        variables: Union[str, Iterable[str], None] = None,
        *,
        start_time: Optional[float] = None,
        step_size: Optional[float] = None,
        algorithm: Optional[str] = None,
        verbose: bool = False,
        isolate=None,
        call_timeout: Optional[float] = None,
        journal: Union[PathLike, bool, None] = None,
    ) -> "Session":
        """Starts a stepping session: the instances are made and initialized, and the session
        is at the start time, ready to :meth:`Session.step`. The options are :meth:`run`'s.
        ``journal``: every value set from outside is journaled (JSON Lines; :meth:`replay`
        replays it bit for bit), in memory by default (:meth:`Session.journal_text`), also in
        this file if a path is given, or not at all with ``False`` (a long training loop that
        sets values every step: the journal would grow by about 100 bytes a value). See
        :class:`Session`."""
        from ._session import Session

        if isinstance(variables, str):
            variables = [variables]
        isolate, names = _isolation(isolate)
        native = self._native.start(
            stop_time=stop_time,
            variables=None if variables is None else list(variables),
            start_time=start_time,
            step_size=step_size,
            algorithm=algorithm,
            verbose=verbose,
            isolate=isolate,
            isolate_instances=names,
            call_timeout=call_timeout,
            journal=journal if journal is None or isinstance(journal, bool) else os.fspath(journal),
        )
        for w in native.warnings:
            warnings.warn(w, ShipsimWarning, stacklevel=2)
        return Session(native)

    @staticmethod
    def replay(journal: PathLike, *, verbose: bool = False, as_frame: Optional[bool] = None):
        """Replays a session's journal (written by ``System.start(journal=...)`` or
        :meth:`Session.save_journal`): loads the system file it names, checks that the file
        and every FMU have the SHA-256 the journal gives (else :class:`ShipsimError` naming
        the difference), applies the start values and options the session had and the values
        set from outside in the session's final history (a restored checkpoint drops those
        set after it), and runs to the session's last time. Returns the rows as
        :meth:`run` does; they equal the session's bit for bit. ``shipsim replay JOURNAL``
        does the same from the command line."""
        raw = _native.replay(os.fspath(journal), verbose=verbose)
        return _frame(raw, as_frame, {})

    # -- loop analysis (docs/loop-analysis.md) ---------------------------------------------
    def loop_margins(
        self,
        connection: str,
        *,
        at: Optional[float] = None,
        frequencies: Optional[Iterable[float]] = None,
        amplitude: Optional[float] = None,
        periods: Optional[int] = None,
        settle: Optional[float] = None,
        linearity: bool = True,
        jobs: Optional[int] = None,
        output: Optional[PathLike] = None,
        client=None,
    ) -> Dict[str, Any]:
        """The loop transfer function at ``connection`` (``"ap.rudder_command ->
        gear.rudder_command"``) and its stability margins, as ``shipsim loop --break``
        measures them: the loop stays closed, a sinusoid of ``amplitude`` (default 0.01, in the
        connection's unit) rides on the connection, and L = -(returned)/(sent) is measured by
        correlation over ``periods`` whole periods (default 4) after ``settle`` seconds
        (default 3 periods), each frequency a fork from the state at ``at`` (default: the
        start, after initialization). ``frequencies`` [rad/s] default to 20 log-spaced from
        0.001 to 0.3 times pi/h; crossings are refined by more forks.

        Returns a dict: ``gain_margin_db``, ``gain_margin_rad_s``, ``phase_margin_deg``,
        ``crossover_rad_s``, ``delay_margin_s``, ``sensitivity_peak`` (max |1/(1+L)|) and
        ``sensitivity_peak_rad_s`` (None where the range has no such crossing; with several
        crossings the one nearest -1, and the least delay over the crossovers),
        ``gain_crossovers`` and ``phase_crossovers`` (every crossing as (omega, phase margin
        [deg]) and (omega, gain margin [dB])), and
        ``table``: a DataFrame (omega_rad_s, gain_db, phase_deg, re, im, distortion,
        gain_change_db, phase_change_deg: the change at twice the amplitude, with
        ``linearity``). With ``output``, the tables (CSV, Parquet) and the Bode and Nyquist
        plots are written into that folder too.

        ``client`` (a ``dask.distributed.Client``): the grid's forks run on its workers, in
        chunks, and the crossings are refined here; the result is the same, bit for bit. The
        workers read the system file and its FMUs at this process's absolute paths."""
        from ._campaign import _table

        options = dict(
            at=at, frequencies=None if frequencies is None else [float(w) for w in frequencies],
            amplitude=amplitude, periods=periods, settle=settle, linearity=linearity,
        )
        grid = None
        if client is not None:
            from ._dask import loop_on_dask

            grid = loop_on_dask(self, connection, options, client)
            options["frequencies"] = _native.loop_grid(self._native, frequencies=options["frequencies"])
        raw = _native.loop_margins(
            self._native, connection, jobs=jobs,
            output=None if output is None else os.fspath(output), grid=grid, **options,
        )
        raw["table"] = _table(raw["table"], None)
        return raw

    def frequency_response(
        self,
        input: str,
        outputs: Union[str, Iterable[str]],
        *,
        at: Optional[float] = None,
        frequencies: Optional[Iterable[float]] = None,
        amplitude: Optional[float] = None,
        periods: Optional[int] = None,
        settle: Optional[float] = None,
        linearity: bool = True,
        jobs: Optional[int] = None,
        output: Optional[PathLike] = None,
    ):
        """The frequency response from ``input`` (an input or tunable parameter, or a
        connection ``"a.y -> b.u"``) to each of ``outputs``, as ``shipsim loop --input X
        --output Y`` measures it (the options of :meth:`loop_margins`). Returns a DataFrame:
        omega_rad_s, output, gain_db, phase_deg (unwrapped per output), re, im, distortion,
        gain_change_db, phase_change_deg."""
        from ._campaign import _table

        if isinstance(outputs, str):
            outputs = [outputs]
        raw = _native.frequency_response(
            self._native, input, list(outputs), at=at,
            frequencies=None if frequencies is None else [float(w) for w in frequencies],
            amplitude=amplitude, periods=periods, settle=settle, linearity=linearity, jobs=jobs,
            output=None if output is None else os.fspath(output),
        )
        return _table(raw["table"], None)

    def describing_function(
        self,
        input: str,
        output: str,
        frequency: float,
        amplitudes: Iterable[float],
        *,
        at: Optional[float] = None,
        periods: Optional[int] = None,
        settle: Optional[float] = None,
        jobs: Optional[int] = None,
        directory: Optional[PathLike] = None,
    ):
        """The describing function from ``input`` to ``output`` at ``frequency`` [rad/s]
        over ``amplitudes``: the fundamental of the output over the injected sinusoid, for
        nonlinear elements (rate and angle limits). Returns a DataFrame: amplitude,
        omega_rad_s, output, gain, gain_db, phase_deg, re, im, distortion."""
        from ._campaign import _table

        raw = _native.describing_function(
            self._native, input, output, float(frequency), [float(a) for a in amplitudes],
            at=at, periods=periods, settle=settle, jobs=jobs,
            directory=None if directory is None else os.fspath(directory),
        )
        return _table(raw["table"], None)

    def __repr__(self) -> str:
        names = ", ".join(self.instances)
        return f"System({self.source!r}: {names}; step {self.step_size} s, stop {self.stop_time} s)"


def _isolation(isolate):
    """``isolate=`` of :meth:`System.run` as (value, instance names) for the native call."""
    if isolate is True:
        return "all", None
    if isolate is False or isolate is None:
        return None, None
    if not isinstance(isolate, str):
        return None, [str(n) for n in isolate]
    return isolate, None


def _frame(raw, as_frame: Optional[bool], summary):
    """Recorded rows from the native layer (``time`` and ``data`` as little-endian f64
    buffers) as a DataFrame indexed by time, or a :class:`Columns` dict without pandas."""
    time = np.frombuffer(raw["time"], dtype="<f8")
    arrays = {}
    for name, kind, buf in zip(raw["columns"], raw["types"], raw["data"]):
        values = np.frombuffer(buf, dtype="<f8")
        dtype = _DTYPES.get(kind, np.float64)
        arrays[name] = values if dtype is np.float64 else values.astype(dtype)
    units = dict(zip(raw["columns"], raw["units"]))
    if as_frame is None:
        as_frame = _have_pandas()
    if as_frame:
        import pandas as pd

        df = pd.DataFrame(arrays, index=pd.Index(time, name="time"))
        df.attrs["units"] = units
        df.attrs["summary"] = summary
        df.attrs["warnings"] = list(raw["warnings"])
        return df
    out = Columns(time=time, **arrays)
    out.units = units
    out.summary = summary
    return out
