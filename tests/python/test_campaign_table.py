"""The campaign run table's files (master/src/campaign/table) load straight into pandas and polars,
with every value exact.

The files come from the Rust test `write_fixture` (master/tests/campaign_table.rs), which this
module runs once through cargo into a temporary folder; it writes the table of that file's
`table()`: the float, integer, bool and text columns listed below as literals. Floats are
compared by their IEEE bits (tolerance 0).
"""
import math
import os
import struct
import subprocess

import pandas as pd
import polars as pl
import pytest

from conftest import ROOT

X = [0.1, -0.0, 0.0, 1e-300, 3.0, math.nan, math.inf, -math.inf, 1e16, 5e-324,
     1.7976931348623157e308, -1.2345678901234567e-7]
WHOLE = [3.0, -0.0, 0.0, 1e15, -2.0, 42.0, 7.0, 8.0, 9.0, 10.0, 2.0**53, -1.0]
N = [0, -1, 2**63 - 1, -(2**63), 42, 7, 8, 9, 10, 11, 12, -13]
OK = [True, False, True, True, False, False, True, False, True, False, True, False]
TEXT = ["plain", "comma, here", 'quote "q" inside', "line\nbreak", "unicode: ø ψ 🚢", "",
        "  spaces  ", "crlf\r\nend", '"', "true", "12", "x;y\tz"]
NAMES = ["x", "whole", "n", "ok", 'message, "quoted"']
EMPTY = TEXT.index("")


def bits(values):
    return [struct.unpack("<Q", struct.pack("<d", v))[0] for v in values]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    out = tmp_path_factory.mktemp("campaign-table")
    cargo = os.environ.get("CARGO", "cargo")
    run = subprocess.run(
        [cargo, "test", "--release", "-p", "shipsim", "--test", "campaign_table",
         "write_fixture", "--", "--exact"],
        cwd=ROOT, env={**os.environ, "SHIPSIM_TABLE_FIXTURE_DIR": str(out)},
        capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "1 passed" in run.stdout, run.stdout
    return out


def check_numbers(x, whole, n, ok):
    assert bits(x) == bits(X)
    assert bits(whole) == bits(WHOLE)
    assert list(n) == N
    assert list(ok) == OK


def test_pandas_reads_the_csv(files):
    df = pd.read_csv(files / "table.csv")
    assert list(df.columns) == NAMES
    assert [str(t) for t in df.dtypes[:4]] == ["float64", "float64", "int64", "bool"]
    check_numbers(*(df[c].to_list() for c in NAMES[:4]))
    text = df[NAMES[4]].to_list()
    # pandas reads an empty cell as missing by default.
    assert pd.isna(text[EMPTY])
    assert text[:EMPTY] + text[EMPTY + 1:] == TEXT[:EMPTY] + TEXT[EMPTY + 1:]
    # With only NaN as missing, every text comes back as written.
    df = pd.read_csv(files / "table.csv", keep_default_na=False, na_values={"x": ["NaN"]})
    assert bits(df["x"].to_list()) == bits(X)
    assert df[NAMES[4]].to_list() == TEXT


def test_pandas_reads_the_parquet(files):
    df = pd.read_parquet(files / "table.parquet")
    assert list(df.columns) == NAMES
    assert [str(t) for t in df.dtypes[:4]] == ["float64", "float64", "int64", "bool"]
    check_numbers(*(df[c].to_list() for c in NAMES[:4]))
    assert df[NAMES[4]].to_list() == TEXT
    empty = pd.read_parquet(files / "rows0.parquet")
    assert list(empty.columns) == NAMES and len(empty) == 0
    assert [str(t) for t in empty.dtypes[:4]] == ["float64", "float64", "int64", "bool"]


def test_polars_reads_the_csv(files):
    df = pl.read_csv(files / "table.csv", empty_string_is_null=False)
    # polars keeps a header's doubled quotes (pola-rs/polars#20294), its cells' it undoes.
    assert [c.replace('""', '"') for c in df.columns] == NAMES
    assert df.dtypes == [pl.Float64, pl.Float64, pl.Int64, pl.Boolean, pl.String]
    check_numbers(*(df.to_series(i).to_list() for i in range(4)))
    assert df.to_series(4).to_list() == TEXT


def test_polars_reads_the_parquet(files):
    df = pl.read_parquet(files / "table.parquet")
    assert df.columns == NAMES
    assert df.dtypes == [pl.Float64, pl.Float64, pl.Int64, pl.Boolean, pl.String]
    check_numbers(*(df[c].to_list() for c in NAMES[:4]))
    assert df[NAMES[4]].to_list() == TEXT
    empty = pl.read_parquet(files / "rows0.parquet")
    assert empty.columns == NAMES and empty.height == 0
    assert empty.dtypes == [pl.Float64, pl.Float64, pl.Int64, pl.Boolean, pl.String]
