"""Campaigns: many runs of one system, one KPI row per run, on every core or on Dask."""

from __future__ import annotations

import math
import os
import sys
from typing import Any, Dict, Optional, Union

import numpy as np

from . import _native

PathLike = Union[str, "os.PathLike[str]"]


def _table(raw: Dict[str, Any], as_frame: Optional[bool]):
    """A native table (names, kinds, columns) as a DataFrame, or a dict of numpy arrays."""
    cols = {}
    for name, kind, data in zip(raw["names"], raw["kinds"], raw["columns"]):
        if kind == "Float":
            cols[name] = np.frombuffer(data, dtype="<f8")
        elif kind == "Int":
            cols[name] = np.frombuffer(data, dtype="<i8")
        elif kind == "Bool":
            cols[name] = np.asarray(data, dtype=bool)
        else:
            cols[name] = np.asarray(data, dtype=object)
    if as_frame is None:
        try:
            import pandas  # noqa: F401

            as_frame = True
        except ImportError:
            as_frame = False
    if not as_frame:
        return cols
    import pandas as pd

    return pd.DataFrame(cols)


class _Progress:
    """A tqdm bar (tqdm.auto: a widget in notebooks, text in terminals), or nothing."""

    def __init__(self, total: int, enabled: Optional[bool], desc: str):
        self.bar = None
        if enabled is None:
            enabled = sys.stderr.isatty() or "ipykernel" in sys.modules
        if not enabled or total == 0:
            return
        try:
            import ipywidgets  # noqa: F401  (tqdm's notebook widget needs it)

            from tqdm.auto import tqdm
        except ImportError:
            try:
                from tqdm import tqdm
            except ImportError:
                return
        self.bar = tqdm(total=total, desc=desc, unit="run")

    def to(self, done: int, failed: int = 0) -> None:
        if self.bar is not None and done != self.bar.n:
            self.bar.update(done - self.bar.n)
            self.bar.set_postfix(failed=failed, refresh=False)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


class Campaign:
    """A campaign file (see docs/campaigns.md): a base system, the factors, seeds and arms to
    vary, and the KPIs to compute; each run gives one row."""

    def __init__(self, native: "_native.Campaign"):
        self._native = native

    @classmethod
    def load(cls, path: PathLike) -> "Campaign":
        """Reads a campaign file and its base system and expands the runs. Raises
        :class:`SystemFileError` for a campaign or system file that cannot be used."""
        return cls(_native.Campaign.load(os.path.abspath(os.fspath(path))))

    @property
    def name(self) -> str:
        return self._native.name

    @property
    def description(self) -> Optional[str]:
        return self._native.description

    @property
    def source(self) -> str:
        return os.fspath(self._native.source)

    @property
    def fork_at(self) -> Optional[float]:
        return self._native.fork_at

    def __len__(self) -> int:
        return len(self._native)

    def runs(self):
        """Every run's values (``instance.variable`` -> value text), in run order."""
        return [dict(r) for r in self._native.run_values()]

    def default_output(self) -> str:
        """``results/<campaign name>``, as for ``shipsim campaign run``."""
        return os.path.join("results", self.name)

    def run(
        self,
        output: Optional[PathLike] = None,
        *,
        jobs: Optional[int] = None,
        client: Any = None,
        retry_failed: bool = False,
        progress: Optional[bool] = None,
        chunk_size: Optional[int] = None,
        as_frame: Optional[bool] = None,
    ):
        """Runs every run not done yet and returns the run table: one row per finished run
        (``run, point, replication, [arm,]`` factors, seeds, KPIs, ``status, message,
        wall_time, key``), the table ``runs.parquet`` holds.

        ``output``: the output folder (default ``results/<name>``); running again resumes
        it. ``jobs``: threads on this machine (default: every core). ``client``: a
        ``dask.distributed.Client``: the runs go to its workers in chunks (``chunk_size``
        runs, default about four chunks per worker; a warm-up group stays whole), and this
        process records them, so that resume works as on one machine; ``"local"``: a
        ``LocalCluster`` of ``jobs`` worker processes for this call. Anything else raises
        ``TypeError`` before the output folder is touched. ``progress``: a tqdm
        bar (default: in terminals and notebooks, when tqdm is installed).

        Ctrl-C stops cleanly: finished runs are kept, and ``KeyboardInterrupt`` is raised.

        Threads: one output folder takes one run at a time (a lock on its journal, across
        threads and processes); a second ``run`` into a folder in use raises
        :class:`ShipsimError` saying so, before it writes anything. Runs into different
        folders may go on at the same time.
        """
        out = os.fspath(output) if output is not None else self.default_output()
        _check_client(client)
        if isinstance(client, str) and client == "local":
            from ._dask import local_client

            with local_client(jobs) as local:
                return self.run(output, client=local, retry_failed=retry_failed,
                                progress=progress, chunk_size=chunk_size, as_frame=as_frame)
        if client is not None:
            from ._dask import run_on_dask

            raw = run_on_dask(self, client, out, retry_failed, chunk_size, progress)
            return _table(raw, as_frame)
        bar = _Progress(len(self), progress, self.name)
        try:
            _, raw = self._native.run(
                out, jobs=jobs, retry_failed=retry_failed, progress=bar.to
            )
        finally:
            bar.close()
        return _table(raw, as_frame)

    def table(self, output: Optional[PathLike] = None, *, as_frame: Optional[bool] = None):
        """The run table of an output folder of this campaign (what is done so far)."""
        out = os.fspath(output) if output is not None else self.default_output()
        return _table(self._native.table(out), as_frame)

    def derived_table(self, output: Optional[PathLike] = None, *, as_frame: Optional[bool] = None):
        """The derived table of an output folder of this campaign (what is done so far): one row
        per design point and replication (``point, replication,`` factors, seeds, the
        ``[[derived]]`` KPIs, ``status``), the table ``derived.parquet`` holds; a row whose
        runs are not all done or failed has NaN and says so in ``status``. ``output`` and
        ``as_frame`` as for :meth:`table`. None when the campaign has no ``[[derived]]`` KPIs."""
        out = os.fspath(output) if output is not None else self.default_output()
        raw = self._native.derived_table(out)
        return None if raw is None else _table(raw, as_frame)

    def __repr__(self) -> str:
        return f"Campaign({self.name!r}: {len(self)} runs, {self.source!r})"


def _check_client(client: Any) -> None:
    """``client`` is None, ``"local"`` or a ``dask.distributed.Client``; else a TypeError that
    says so (it failed deep in the Dask code with an AttributeError, after the output folder
    was opened)."""
    if client is None or (isinstance(client, str) and client == "local"):
        return
    try:
        from distributed import Client
    except ImportError:
        raise TypeError(
            f"client={client!r}: a client must be a dask.distributed.Client (or \"local\" for a "
            "LocalCluster on this machine), and dask.distributed is not installed: "
            "pip install distributed"
        ) from None
    if not isinstance(client, Client):
        raise TypeError(
            f"client={client!r} ({type(client).__name__}): a client must be a "
            "dask.distributed.Client, e.g. Client(\"tcp://HEAD:8786\"), or \"local\" for a "
            "LocalCluster on this machine; None runs on this machine's threads"
        )


def _chunk_size(pending: int, workers: int) -> int:
    """About four chunks per worker, so that a slow or lost chunk costs little."""
    return max(1, math.ceil(pending / max(1, 4 * workers)))
