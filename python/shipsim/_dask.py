"""Campaigns on a Dask cluster (``Campaign.run(client=...)``).

The client (this process) opens the output folder, splits the runs not done yet into chunks
(a warm-up group of a forked campaign stays in one chunk) and submits one task per chunk.
Each task runs :func:`run_chunk` on a worker: the worker process loads the campaign and its
FMUs on its first chunk and keeps them (``shipsim.fmu_load_count()`` counts the loads), runs
the chunk with the GIL released, and returns one JSON record per run. The client records each
chunk's runs in the journal as the chunk completes (synced, a run recorded twice is kept
once) and writes the tables at the end, as on one machine, so that running again resumes.

Temporary files: each worker process unpacks the FMUs once into ``$TMPDIR`` and removes the
folders when it exits (also on a normal ``LocalCluster`` close).

Files: workers read the campaign file, its base system and the FMUs at the same absolute
paths as the client (a shared file system, or the same checkout on every machine). A worker
that sees other files (a different hash of the system and FMUs) fails its chunk with an
error that says so.

A lost worker: Dask runs the chunk again on another worker (its ``allowed-failures`` limit
applies); the runs of a chunk are recorded only when the chunk completes, so every run is
recorded once.
"""

from __future__ import annotations

import atexit
import contextlib
import os
from typing import Any, Dict, Iterator, List, Optional, Tuple

from . import _native

# A worker process keeps the campaigns and FMUs of its chunks loaded (one load per process); at
# exit they are freed, which removes their unpack folders from $TMPDIR (a Dask worker left them
# all behind). Workers import this module to run `run_chunk`; in the client it frees nothing.
atexit.register(_native.release_workers)


@contextlib.contextmanager
def local_client(workers: Optional[int]) -> Iterator[Any]:
    """An embedded Dask cluster on this machine: ``workers`` processes (default: every core)
    of one thread each, closed on exit."""
    from distributed import Client, LocalCluster

    n = workers or os.cpu_count() or 1
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:
        yield client


def run_chunk(campaign: str, base_hash: str, runs: List[int]) -> List[Tuple[str, Optional[bytes]]]:
    """A Dask task: runs the given runs of a campaign in this worker process."""
    return _native.worker_run(campaign, base_hash, runs)


def run_on_dask(campaign, client, output: str, retry_failed: bool,
                chunk_size: Optional[int], progress: Optional[bool]) -> Dict[str, Any]:
    from distributed import as_completed

    from ._campaign import _chunk_size, _Progress

    native = campaign._native
    collector = native.collector(output, retry_failed)
    futures = []
    try:
        pending = collector.pending()
        workers = len(client.scheduler_info().get("workers", {})) or 1
        per = chunk_size or _chunk_size(pending, workers)
        chunks = collector.chunks(per)
        source, base_hash = str(native.source), native.base_hash
        futures = [
            client.submit(run_chunk, source, base_hash, chunk, pure=False,
                          key=f"shipsim-{campaign.name}-chunk-{i}-{id(collector):x}")
            for i, chunk in enumerate(chunks)
        ]
        bar = _Progress(pending, progress, campaign.name)
        done = failed = 0
        try:
            for future in as_completed(futures):
                for record, series in future.result():
                    recorded, run_failed = collector.record(record, series)
                    done += recorded
                    failed += recorded and run_failed
                bar.to(done, failed)
        finally:
            bar.close()
        _, table = collector.finish()
        return table
    except BaseException:
        client.cancel(futures)
        try:
            collector.finish()  # the tables of the runs recorded so far
        except Exception:
            pass
        raise
    finally:
        collector.close()


# -- loop analysis on Dask (System.loop_margins(client=...)) ------------------------------------
# A worker process keeps the systems of its loop tasks loaded, keyed by what makes them.
_LOOP_SYSTEMS: Dict[Tuple[str, Tuple[Tuple[str, str], ...], bool], Any] = {}


def loop_points(source: str, values: Tuple[Tuple[str, str], ...], strict_units: bool,
                connection: str, chunk: List[float], options: Dict[str, Any]) -> List[tuple]:
    """A Dask task: the loop's points at `chunk` of the grid, measured in this worker process
    on the system of `source` with `values` set (loaded once per process)."""
    key = (source, values, strict_units)
    system = _LOOP_SYSTEMS.get(key)
    if system is None:
        system = _native.System.load(source)
        for name, value in values:
            system.set(name, value)
        system.strict_units = strict_units
        _LOOP_SYSTEMS[key] = system
    return _native.loop_points(system, connection, chunk, jobs=1, **options)


def loop_on_dask(system, connection: str, options: Dict[str, Any], client) -> List[tuple]:
    """The grid of a loop analysis measured on the workers of `client`, in chunks of about
    four per worker; returns the points in grid order (the crossings are refined by the
    caller). The workers read the system file and FMUs at the client's absolute paths."""
    from ._campaign import _chunk_size

    grid = _native.loop_grid(system._native, frequencies=options.get("frequencies"))
    options = dict(options, frequencies=grid)
    workers = max(1, len(client.scheduler_info().get("workers", {})))
    size = _chunk_size(len(grid), workers)
    chunks = [grid[i:i + size] for i in range(0, len(grid), size)]
    source = os.path.abspath(system.source)
    values = tuple(sorted(system.values.items()))
    futures = [client.submit(loop_points, source, values, system.strict_units, connection, c,
                             options, pure=False) for c in chunks]
    return [p for f in futures for p in f.result()]
