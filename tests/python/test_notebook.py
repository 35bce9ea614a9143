"""examples/rrs_campaign.ipynb runs from top to bottom (nbclient, a fresh kernel of this venv):
the RRS polar campaign from Python, its plot, and its own assertion that the table equals the
CLI's runs.parquet."""
import os
import pathlib

import nbformat
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_rrs_campaign_notebook(tmp_path, monkeypatch):
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(ROOT / "examples" / "rrs_campaign.ipynb", as_version=4)
    monkeypatch.setenv("SHIPSIM_NOTEBOOK_OUT", str(tmp_path))
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(ROOT / "examples")}})
    client.execute()
    last = nb.cells[-1]["outputs"]
    text = "".join(o.get("text", "") for o in last)
    assert "the Python table equals the CLI's runs.parquet: 540 runs" in text
    assert (tmp_path / "rrs_polar.png").stat().st_size > 10_000
