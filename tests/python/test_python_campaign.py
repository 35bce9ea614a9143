"""Campaigns from the `shipsim` Python package: locally and on Dask.

- Campaign.run equals `shipsim campaign run`'s runs.parquet, row for row (every column but
  wall_time, which is a measurement);
- a campaign through a LocalCluster of 2 worker processes gives the local table row for row,
  with its series files, and each worker loads each FMU once (load counter);
- a worker killed at its k-th completed chunk: Dask runs the chunk again, and every run is
  recorded exactly once (journal lines and table);
- resume: a second run of the same folder runs nothing and returns the same table;
- Campaign.derived_table equals the CLI's derived.parquet (None without [[derived]]);
- the worker processes of a LocalCluster remove their FMU unpack folders when it closes."""
import json
import os
import pathlib
import subprocess
import sys

import pandas as pd
import pytest

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))

# A forked campaign: 2 directions x 2 wave heights x 2 seeds x 2 arms = 16 runs in 4 warm-up
# groups, with series files for two runs.
FORKED = f"""
name = "py_forked"
system = "{ROOT / 'systems' / 'rrs.toml'}"
stop_time = 400.0
seed = 5
fork_at = 100.0
[[factors]]
name = "direction_deg"
variable = "waves.wave_direction"
values = [60, 120]
scale = 0.017453292519943295
[[factors]]
name = "hs"
variable = "waves.significant_wave_height"
values = [2.0, 4.0]
[replications]
count = 2
seeds = ["waves.seed", "wind.seed", "sensors.seed"]
[[arms]]
name = "off"
set = {{ "autopilot.roll_mode" = 0 }}
[[arms]]
name = "on"
set = {{ "autopilot.roll_mode" = 1 }}
[[kpis]]
name = "roll_var"
variable = "ship.roll"
stat = "variance"
window = [150, 400]
[[kpis]]
name = "rudder_rms"
variable = "gear.rudder_angle"
stat = "rms"
window = [150, 400]
[series]
runs = [0, 5]
variables = ["ship.roll"]
decimation = 10
"""


def same_table(a: pd.DataFrame, b: pd.DataFrame):
    cols = [c for c in a.columns if c != "wall_time"]
    assert list(a.columns) == list(b.columns)
    a = a.sort_values("run").reset_index(drop=True)[cols]
    b = b.sort_values("run").reset_index(drop=True)[cols]
    pd.testing.assert_frame_equal(a, b, check_exact=True, check_dtype=False)


@pytest.fixture(scope="module")
def forked(tmp_path_factory):
    d = tmp_path_factory.mktemp("campaign")
    path = d / "forked.toml"
    path.write_text(FORKED)
    return path


@pytest.fixture(scope="module")
def local(forked, tmp_path_factory):
    """The forked campaign run locally (2 threads) from Python."""
    out = tmp_path_factory.mktemp("local") / "out"
    table = shipsim.Campaign.load(forked).run(out, jobs=2, progress=False)
    return out, table


def test_local_run_equals_the_cli(local, forked, tmp_path):
    out, table = local
    assert len(table) == 16 and sorted(table["run"]) == list(range(16))
    assert set(table["status"]) == {"ok"}
    cli_out = tmp_path / "cli"
    subprocess.run([BIN, "campaign", "run", str(forked), "-o", str(cli_out), "-q", "-j", "2"], check=True)
    same_table(table, pd.read_parquet(cli_out / "runs.parquet"))
    # the Python run wrote the same files as the CLI
    same_table(table, pd.read_parquet(out / "runs.parquet"))
    for run in (0, 5):
        name = f"run-{run:06d}.csv"
        assert (out / "series" / name).read_bytes() == (cli_out / "series" / name).read_bytes()


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    """The reduced RRS polar (one derived KPI) run from Python and by the CLI."""
    tmp_path = tmp_path_factory.mktemp("reduced")
    c = shipsim.Campaign.load(ROOT / "campaigns" / "rrs_polar_reduced.toml")
    table = c.run(tmp_path / "py", progress=False)
    subprocess.run([BIN, "campaign", "run", str(c.source), "-o", str(tmp_path / "cli"), "-q"], check=True)
    return c, tmp_path, table


def test_reduced_polar_equals_the_cli(reduced):
    c, tmp_path, table = reduced
    assert len(c) == 12 and c.name == "rrs_polar_reduced"
    same_table(table, pd.read_parquet(tmp_path / "cli" / "runs.parquet"))
    # resume: nothing left to run, the same table
    again = c.run(tmp_path / "py", progress=False)
    pd.testing.assert_frame_equal(table, again, check_exact=True)


def test_derived_table_equals_the_cli(reduced, local, forked):
    """Campaign.derived_table: the derived KPIs of an output folder, equal to the CLI's
    derived.parquet (and to the one the Python run wrote); None for a campaign without
    [[derived]]."""
    c, tmp_path, _ = reduced
    derived = c.derived_table(tmp_path / "py")
    assert isinstance(derived, pd.DataFrame)
    assert list(derived.columns) == ["point", "replication", "direction_deg", "waves.seed",
                                     "wind.seed", "sensors.seed", "roll_reduction", "status"]
    # 12 runs in 2 arms: 6 rows, every one complete
    assert len(derived) == len(c) // 2 and set(derived["status"]) == {"ok"}
    assert derived["roll_reduction"].notna().all()
    for folder in ("cli", "py"):
        expected = pd.read_parquet(tmp_path / folder / "derived.parquet")
        pd.testing.assert_frame_equal(derived, expected, check_exact=True, check_dtype=False)
    # the CLI's folder read from Python gives the same table
    pd.testing.assert_frame_equal(derived, c.derived_table(tmp_path / "cli"), check_exact=True)
    # as_frame=False: a dict of numpy arrays, as table() gives
    raw = c.derived_table(tmp_path / "py", as_frame=False)
    assert list(raw) == list(derived.columns)
    assert (raw["roll_reduction"] == derived["roll_reduction"].to_numpy()).all()
    # a campaign without [[derived]]
    out, _ = local
    assert shipsim.Campaign.load(forked).derived_table(out) is None


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0", silence_logs=40) as cluster:
        yield cluster


def test_dask_equals_local_and_loads_each_fmu_once(cluster, local, forked, tmp_path):
    from distributed import Client

    _, table = local
    c = shipsim.Campaign.load(forked)
    out = tmp_path / "dask"
    with Client(cluster) as client:
        client.restart()
        got = c.run(out, client=client, chunk_size=4, progress=False)
        loads = client.run(shipsim.fmu_load_count)
    same_table(table, got)
    same_table(table, pd.read_parquet(out / "runs.parquet"))
    fmus = set(shipsim.System.load(ROOT / "systems" / "rrs.toml").instances.values())
    # each of the 2 workers loaded each FMU once, however many chunks it ran
    assert sorted(loads.values()) == [len(fmus), len(fmus)], loads
    lines = (out / "runs.jsonl").read_text().splitlines()
    assert sorted(json.loads(x)["index"] for x in lines) == list(range(16))
    local_out, _ = local
    for run in (0, 5):
        name = f"run-{run:06d}.csv"
        assert (out / "series" / name).read_bytes() == (local_out / "series" / name).read_bytes()


try:
    from distributed.diagnostics.plugin import WorkerPlugin
except ImportError:  # the Dask tests are skipped then
    WorkerPlugin = object


class KillAtChunk(WorkerPlugin):
    """A worker plugin that kills its worker process when the k-th chunk completes there, once
    in the cluster (a marker file says it happened)."""

    name = "kill-at-chunk"

    def __init__(self, k: int, marker: str):
        self.k, self.marker, self.done = k, marker, 0

    def setup(self, worker):
        self.done = 0

    def transition(self, key, start, finish, **kwargs):
        if finish == "memory" and str(key).startswith("shipsim-"):
            self.done += 1
            if self.done == self.k and not os.path.exists(self.marker):
                open(self.marker, "w").close()
                os._exit(1)


def test_dask_worker_loss_records_every_run_once(cluster, local, forked, tmp_path):
    from distributed import Client

    _, table = local
    c = shipsim.Campaign.load(forked)
    marker = tmp_path / "killed"
    out = tmp_path / "dask"
    with Client(cluster) as client:
        client.restart()
        # The plugin travels by value: workers cannot import this test module.
        import sys

        import cloudpickle

        cloudpickle.register_pickle_by_value(sys.modules[__name__])
        client.register_plugin(KillAtChunk(2, str(marker)))
        try:
            got = c.run(out, client=client, chunk_size=4, progress=False)
        finally:
            client.unregister_worker_plugin(KillAtChunk.name)
    assert marker.exists(), "no worker was killed"
    same_table(table, got)
    lines = (out / "runs.jsonl").read_text().splitlines()
    indices = sorted(json.loads(x)["index"] for x in lines)
    assert indices == list(range(16)), indices


def test_dask_resume_and_errors(cluster, local, forked, tmp_path):
    from distributed import Client

    _, table = local
    c = shipsim.Campaign.load(forked)
    out = tmp_path / "resume"
    # half the runs on one machine, the rest on Dask: the journal carries over
    (out).mkdir()
    c.run(out, jobs=1, progress=False)
    lines = (out / "runs.jsonl").read_text().splitlines()
    (out / "runs.jsonl").write_text("\n".join(lines[:7]) + "\n")
    with Client(cluster) as client:
        got = c.run(out, client=client, progress=False)
    same_table(table, got)
    assert len((out / "runs.jsonl").read_text().splitlines()) == 16
    with pytest.raises(shipsim.SystemFileError):
        shipsim.Campaign.load(tmp_path / "missing.toml")


def test_embedded_local_cluster(local, forked, tmp_path):
    pytest.importorskip("distributed")
    _, table = local
    got = shipsim.Campaign.load(forked).run(tmp_path / "embedded", client="local", jobs=2,
                                            progress=False)
    same_table(table, got)


def test_a_failing_progress_callback_stops_the_campaign(forked, tmp_path):
    """An exception in the progress callback stops the runs cleanly and is raised; the runs
    finished before it are kept and a second run resumes them."""
    c = shipsim.Campaign.load(forked)

    def boom(done, failed):
        raise RuntimeError("progress display failed")

    with pytest.raises(RuntimeError, match="progress display failed"):
        c._native.run(str(tmp_path / "out"), jobs=1, progress=boom)
    table = c.run(tmp_path / "out", jobs=2, progress=False)
    assert sorted(table["run"]) == list(range(16))


@pytest.mark.parametrize("jobs", [0, -1])
def test_jobs_below_one_are_a_clear_error(forked, tmp_path, jobs):
    """jobs=-1 raised a bare OverflowError, jobs=0 ran on a default; both say what is wrong,
    before anything is written."""
    c = shipsim.Campaign.load(forked)
    with pytest.raises(ValueError, match=f"jobs = {jobs}: a campaign needs at least one job"):
        c.run(tmp_path / "out", jobs=jobs, progress=False)
    assert not (tmp_path / "out" / "campaign.json").exists()


SMALL = f"""
name = "py_small"
system = "{ROOT / 'systems' / 'rrs.toml'}"
stop_time = 20.0
[[factors]]
name = "hs"
variable = "waves.significant_wave_height"
values = [2.0, 3.0, 4.0, 5.0]
[[kpis]]
name = "roll_var"
variable = "ship.roll"
stat = "variance"
"""

CLEANUP_SCRIPT = """
import gc, json, os, sys
from distributed import Client, LocalCluster
import shipsim

def unpacked():
    return sorted(p for p in os.listdir(os.environ["TMPDIR"]) if p.startswith("shipsim"))

if __name__ == "__main__":
    campaign, out = sys.argv[1:]
    c = shipsim.Campaign.load(campaign)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0", silence_logs=40) as cluster, Client(cluster) as client:
        table = c.run(out, client=client, chunk_size=1, progress=False)
        during = max(len(v) for v in client.run(unpacked).values())
        workers = len(client.run(os.getpid))
    del c
    gc.collect()
    print(json.dumps({"runs": len(table), "workers": workers, "during": during,
                      "left": unpacked()}), flush=True)
"""


def test_dask_workers_remove_their_fmu_folders_at_exit(tmp_path):
    """Each worker process unpacks the FMUs once and keeps them; a normal LocalCluster close
    used to leave every worker's folders in $TMPDIR (issue 38, item 13: 15 folders, 11 MB per
    session). Now the workers free them at exit."""
    pytest.importorskip("distributed")
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    campaign = tmp_path / "small.toml"
    campaign.write_text(SMALL)
    script = tmp_path / "cleanup.py"
    script.write_text(CLEANUP_SCRIPT)
    env = dict(os.environ, TMPDIR=str(tmp))
    p = subprocess.run([sys.executable, str(script), str(campaign), str(tmp_path / "out")],
                       capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 0, p.stderr
    got = json.loads(p.stdout.splitlines()[-1])
    assert got["runs"] == 4 and got["workers"] == 2, got
    # the workers did unpack their FMUs into this TMPDIR (one folder per FMU and process)
    fmus = len(set(shipsim.System.load(ROOT / "systems" / "rrs.toml").instances.values()))
    assert got["during"] >= fmus, got
    assert got["left"] == [], got
    assert [x.name for x in tmp.iterdir() if x.name.startswith("shipsim")] == []
