"""Shared fixtures for the Python cross-checks run by `cargo xtask test`.

Environment (set by xtask): SHIPSIM_FMU_DIR (built FMUs), SHIPSIM_BIN (the master),
SHIPSIM_REFERENCE_BIN (the Rust-model reference generator).
"""
import csv
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def fmu_dir() -> pathlib.Path:
    return pathlib.Path(os.environ.get("SHIPSIM_FMU_DIR", ROOT / "target" / "fmu"))


def all_fmus():
    d = fmu_dir()
    fmus = sorted(d.glob("*.fmu"))
    if not fmus:
        raise RuntimeError(f"no FMUs in {d}: run `cargo xtask build-fmus` first")
    return fmus


@pytest.fixture(scope="session")
def fmu_path():
    def get(model_identifier: str) -> pathlib.Path:
        p = fmu_dir() / f"{model_identifier}.fmu"
        if not p.exists():
            raise RuntimeError(f"{p} is missing: run `cargo xtask build-fmus` first")
        return p

    return get


@pytest.fixture(scope="session")
def reference():
    """Runs the Rust-model reference generator for a case and returns the rows as dicts of floats.

    Each case runs once per session (several tests use the same case); every call gets its own copy
    of the rows."""
    cache = {}

    def run(case: str):
        if case not in cache:
            exe = os.environ.get("SHIPSIM_REFERENCE_BIN", str(ROOT / "target" / "release" / "model-reference"))
            if not pathlib.Path(exe).exists():
                raise RuntimeError(f"{exe} is missing: run `cargo xtask test`")
            out = subprocess.run([exe, case], check=True, capture_output=True, text=True).stdout
            rows = list(csv.DictReader(out.splitlines()))
            cache[case] = [{k: float(v) for k, v in r.items()} for r in rows]
        return [dict(r) for r in cache[case]]

    return run
