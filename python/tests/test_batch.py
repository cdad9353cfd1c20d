"""Batch diagnosis: the local thread pool and a Dask LocalCluster (two
worker processes) give the command line's `diagnose --batch` record for record."""

from __future__ import annotations

import json
import subprocess
import sys

import pandas as pd
import pytest

import reldesign
from reldesign.batch import diagnose_many
from conftest import EXAMPLE, QUICK_CAUSES, ROOT, read_record, run_cli


@pytest.fixture(scope="module")
def cli_lines(records, cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli-out")
    run = run_cli(
        cli, "diagnose", EXAMPLE, "--batch", records, "--out", out, "--causes", ",".join(QUICK_CAUSES)
    )
    assert run.returncode == 1, "the broken record fails the batch"
    lines = [json.loads(line) for line in run.stdout.splitlines()]
    assert len(lines) == 5
    return out, lines


def same_as_cli(table: pd.DataFrame, lines) -> None:
    assert list(table["file"]) == [line["file"] for line in lines]
    for (_, row), line in zip(table.iterrows(), lines):
        assert json.loads(row["json"]) == line, row["file"]
        if "error" in line:
            assert row["error"] == line["error"]
        else:
            assert row["error"] is None or pd.isna(row["error"])
            assert row["causes"] == " + ".join(line["causes"])
            assert row["gain"] == line["gain"]
            for path, p in line["parameters"].items():
                assert row[path] == p["value"] and row[f"{path}.std_error"] == p["std_error"]


def test_local_threads_equal_the_cli_batch(records, cli_lines, tmp_path):
    out, lines = cli_lines
    table = diagnose_many(str(EXAMPLE), str(records), out_dir=out, causes=QUICK_CAUSES)
    same_as_cli(table, lines)
    assert "unit-broken.csv:5:" in table["error"].iloc[-1]


def test_dask_local_cluster_equals_the_cli_batch(records, cli_lines):
    distributed = pytest.importorskip("dask.distributed")
    out, lines = cli_lines
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        valve = reldesign.Actuator.from_toml(str(EXAMPLE))
        table = diagnose_many(valve, str(records), client=client, out_dir=out, causes=QUICK_CAUSES)
    same_as_cli(table, lines)


def test_dataframes_and_written_files(records, tmp_path):
    frames = [read_record(records / f"unit-00{k}.csv") for k in (0, 1)]
    table = diagnose_many(str(EXAMPLE), frames, out_dir=tmp_path, causes=QUICK_CAUSES, workers=2)
    assert list(table["file"]) == ["record0.csv", "record1.csv"]
    assert table["error"].isna().all()
    for k in (0, 1):
        assert (tmp_path / f"record{k}.extended.toml").read_text().startswith("# extended by")
        assert (tmp_path / f"record{k}.report.txt").exists()


def test_module_command_writes_parquet(records, tmp_path):
    out = tmp_path / "results.parquet"
    run = subprocess.run(
        [sys.executable, "-m", "reldesign.batch", str(EXAMPLE), str(records / "unit-00[01].csv"),
         "--scheduler", "threads", "--causes", ",".join(QUICK_CAUSES), "--out", str(out)],
        capture_output=True, text=True, cwd=ROOT,
    )
    assert run.returncode == 0, run.stderr
    table = pd.read_parquet(out)
    assert len(table) == 2 and "coil.resistance" in table.columns
