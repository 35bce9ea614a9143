"""Stepping sessions: a system run from Python one macro step (or a stretch) at a time."""

from __future__ import annotations

import os
from typing import Optional, Tuple, Union

from . import _native
from ._system import PathLike, _frame

Number = Union[bool, int, float, str]


class Checkpoint:
    """A session at one communication point, taken by :meth:`Session.checkpoint` and given
    back to :meth:`Session.restore` of the same session (any number of times)."""

    def __init__(self, native: "_native.Checkpoint"):
        self._native = native

    @property
    def time(self) -> float:
        """The time it was taken at [s]."""
        return self._native.time

    @property
    def step(self) -> int:
        """Its base step k (time = t0 + k*h)."""
        return self._native.step

    def save(self, path: PathLike) -> None:
        """Writes the master checkpoint to a file: ``shipsim run SYSTEM --resume FILE``
        continues the system from it (the system must be the session's, with the values set
        before the checkpoint as events, else the resume names the difference)."""
        self._native.save(os.fspath(path))

    def __repr__(self) -> str:
        return repr(self._native)


class Session:
    """A run of a system driven from Python, made by :meth:`System.start`.

    The session is at a communication point t_k (:attr:`time`). :meth:`step` and
    :meth:`advance_to` move it on; between them :meth:`get` reads any variable and
    :meth:`set` sets an input or tunable parameter. A session that only reads records,
    bit for bit, what :meth:`System.run` records; a value set at t_k acts exactly as the
    same change written as an event at t_k in the system file (after the file's events of
    that time; on a connected input, the connection drives it again at the next exchange).

    :meth:`checkpoint` and :meth:`restore` rewind the session: the instances' states, the
    values set from outside and the recorded rows go back to the checkpoint. Every value set
    from outside is journaled (:meth:`journal_text`, ``journal=`` of :meth:`System.start`), so
    that :meth:`System.replay` gives the session's rows again, bit for bit.

    Use it as a context manager, or call :meth:`close`; a session that is collected without
    being closed frees its instances and ends its journal then.

    Errors: :class:`VariableError` for a name, type, unit, range or a variable that cannot
    change during a run (a fixed parameter); :class:`SessionError` for a session that is
    closed, failed, at its end, or being stepped by another thread; :class:`SimulationError`
    for an FMU that fails (the session is then failed). The GIL is released while it steps;
    Ctrl-C stops a long :meth:`step` or :meth:`advance_to` at its next communication point
    and raises ``KeyboardInterrupt``, and the session stays usable there.
    """

    def __init__(self, native: "_native.Session"):
        self._native = native

    # -- stepping ---------------------------------------------------------------------
    def step(self, n: int = 1) -> float:
        """Advances ``n`` macro steps (fewer at the stop time or when an FMU ends the run);
        returns the time reached."""
        return self._native.step(n)

    def advance_to(self, t: float) -> float:
        """Advances to time ``t`` [s], a communication point t0 + k*h at or after
        :attr:`time` and at most :attr:`stop_time`; returns it."""
        return self._native.advance_to(t)

    @property
    def time(self) -> float:
        """The communication point the session is at [s]."""
        return self._native.time

    @property
    def step_index(self) -> int:
        """k of :attr:`time` = t0 + k*h."""
        return self._native.step_index

    @property
    def step_size(self) -> float:
        return self._native.step_size

    @property
    def stop_time(self) -> float:
        return self._native.stop_time

    @property
    def state(self) -> str:
        """``"open"``, ``"ended"`` (at the stop time, or ended by an FMU: :attr:`reason`),
        ``"failed"`` or ``"closed"``."""
        return self._native.state[0]

    @property
    def reason(self) -> Optional[str]:
        """Why the session ended early or failed."""
        return self._native.state[1]

    # -- values -----------------------------------------------------------------------
    def get(self, name: str) -> Number:
        """The current value of ``instance.variable`` (any variable), in the FMU's unit. A
        connection source or recorded variable is read as published at :attr:`time` (what the
        rows and the connections see); any other is read from its FMU, which, for an instance
        with a ``step_multiple`` above 1 between its steps, is already at the end of its
        current step."""
        return self._native.get(name)

    def set(self, name: str, value: Number) -> "Session":
        """Sets an input or tunable parameter at :attr:`time`, before the next step, with
        :meth:`System.set`'s values and checks: a str is read by the variable's type and may
        carry a unit (``"5 deg"``), converted to the variable's; the declared range holds.
        Journaled. Returns the session, so calls chain."""
        self._native.set(name, value)
        return self

    def rows(self, as_frame: Optional[bool] = None):
        """The rows recorded so far, as :meth:`System.run` returns them (a DataFrame indexed
        by time, with ``attrs["units"]``)."""
        raw = self._native.rows()
        summary = {"fmu_steps": raw["fmu_steps"], "wall_time": raw["wall_time"]}
        return _frame(raw, as_frame, summary)

    # -- checkpoints, journal, end ----------------------------------------------------
    def checkpoint(self) -> Checkpoint:
        """The session at :attr:`time` (every FMU must support getting and serializing its
        state, as our FMUs do)."""
        return Checkpoint(self._native.checkpoint())

    def restore(self, checkpoint: Checkpoint) -> "Session":
        """Rewinds the session to one of its own checkpoints: instances, values set from
        outside and recorded rows. A session at its end can be rewound; a failed or closed
        one cannot."""
        self._native.restore(checkpoint._native)
        return self

    @property
    def journal_path(self) -> Optional[str]:
        p = self._native.journal_path
        return None if p is None else os.fspath(p)

    def journal_text(self) -> str:
        """The journal so far (JSON Lines: a header naming the system, its FMUs and their
        SHA-256, then one record per value set, checkpoint and restore). A session started
        with ``journal=False`` has none: :class:`SessionError`."""
        return self._native.journal_text()

    def save_journal(self, path: PathLike) -> None:
        """Writes :meth:`journal_text` to a file, for :meth:`System.replay`."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.journal_text())

    def close(self) -> None:
        """Terminates and frees the instances and ends the journal (twice does nothing)."""
        self._native.close()

    def __enter__(self) -> "Session":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"Session(t = {self.time} s of {self.stop_time} s, {self.state})"
