"""Batch diagnosis: many records of one description, on the local cores or
on a Dask cluster.

>>> from reldesign.batch import diagnose_many
>>> table = diagnose_many("valve.toml", "records/")            # local cores
>>> table = diagnose_many(valve, "records/*.csv", client=client)  # a Dask cluster

One row per record, in the order ``reldesign diagnose --batch DIR`` prints
them (file-name order for a directory): ``file``, ``cause``, ``causes``,
``gain``, each fitted parameter's value and ``<path>.std_error``, ``error``
(a record that cannot be read or diagnosed: the others go on) and ``json``
(the command line's JSON line for the record, ``file`` included).

The actuator travels to the workers as its TOML text, never as a pickled
Rust object; records travel as paths (on a shared filesystem) or as
DataFrames.

From the shell::

    python -m reldesign.batch MODEL.toml DIR --scheduler ADDRESS|local|threads --out RESULTS.parquet
"""

from __future__ import annotations

import argparse
import functools
import glob
import json
import os
import sys
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import pandas as pd

from . import Actuator, PathLike, _actuator, diagnose

__all__ = ["diagnose_many", "records_of", "main"]

Records = Union[PathLike, Sequence[Union[PathLike, pd.DataFrame]], Dict[str, pd.DataFrame]]


def records_of(records: Records) -> List[Tuple[str, Union[str, pd.DataFrame]]]:
    """``(name, record)`` pairs: a directory's ``*.csv`` (sorted, as
    ``--batch DIR`` takes them), a glob's matches (sorted), a list of paths
    or DataFrames (``record<k>.csv`` for the k-th DataFrame), or a dict of
    named DataFrames."""
    if isinstance(records, (str, os.PathLike)):
        path = os.fspath(records)
        if os.path.isdir(path):
            names = sorted(
                os.path.join(path, f) for f in os.listdir(path) if f.endswith(".csv")
            )
            if not names:
                raise FileNotFoundError(f"{path}: no *.csv record in the directory")
            return [(n, n) for n in names]
        if glob.has_magic(path):
            names = sorted(glob.glob(path))
            if not names:
                raise FileNotFoundError(f"{path}: no record matches")
            return [(n, n) for n in names]
        return [(path, path)]
    if isinstance(records, dict):
        return list(records.items())
    out: List[Tuple[str, Union[str, pd.DataFrame]]] = []
    for k, r in enumerate(records):
        if isinstance(r, pd.DataFrame):
            out.append((f"record{k}.csv", r))
        else:
            out.append((os.fspath(r), os.fspath(r)))
    return out


@functools.lru_cache(maxsize=8)
def _parsed(text: str, file_name: str) -> Actuator:
    # one parse per worker process and description
    return Actuator.from_str(text, file_name)


def _one(
    text: str,
    file_name: str,
    name: str,
    record: Union[str, pd.DataFrame],
    out_dir: Optional[str],
    holdout: float,
    causes: Optional[List[str]],
) -> Dict[str, Any]:
    """One record's row (runs on a worker); a failure becomes its row's ``error``."""
    try:
        actuator = _parsed(text, file_name)
        d = diagnose(
            actuator,
            record,
            out_dir=out_dir,
            holdout=holdout,
            causes=causes,
            name=name,
        )
    except Exception as e:  # a broken record never stops the batch
        return {"file": name, "error": str(e), "json": json.dumps({"file": name, "error": str(e)})}
    line = d.to_dict()
    line["file"] = name
    row: Dict[str, Any] = {
        "file": name,
        "cause": d.causes[0] if d.causes else line.get("cause"),
        "causes": " + ".join(d.causes),
        "gain": d.gain,
        "error": None,
    }
    for path, p in d.parameters.items():
        row[path] = p["value"]
        row[f"{path}.std_error"] = p["std_error"]
    row["json"] = json.dumps(line)
    return row


def _table(rows: List[Dict[str, Any]]) -> pd.DataFrame:
    table = pd.DataFrame(rows)
    first = ["file", "cause", "causes", "gain", "error"]
    rest = sorted(c for c in table.columns if c not in first and c != "json")
    return table.reindex(columns=first + rest + ["json"])


def diagnose_many(
    actuator: Union[Actuator, PathLike],
    records: Records,
    client: Any = None,
    *,
    out_dir: Optional[PathLike] = None,
    holdout: float = 0.25,
    causes: Optional[Sequence[str]] = None,
    workers: Optional[int] = None,
    progress: bool = False,
) -> pd.DataFrame:
    """Diagnoses every record against one description; a DataFrame, one row per record.

    With a ``dask.distributed.Client`` the records are mapped over its
    cluster (the description sent as its text; paths must be readable from
    the workers, ``out_dir`` writable from them). Without one they run on
    a thread pool of ``workers`` threads (default: the cores), each call
    releasing the GIL. ``out_dir``: each record's extended model, report
    and JSON are written there as ``<stem>.extended.toml``,
    ``<stem>.report.txt``, ``<stem>.json``.
    """
    actuator = _actuator(actuator)
    items = records_of(records)
    text, file_name = actuator.text, actuator.file_name
    out = None if out_dir is None else os.fspath(out_dir)
    if out is not None:
        os.makedirs(out, exist_ok=True)
    cause_list = None if causes is None else list(causes)
    args = [(text, file_name, name, r, out, holdout, cause_list) for name, r in items]
    if client is not None:
        futures = client.map(_one, *zip(*args), pure=False)
        if progress:
            from dask.distributed import progress as dask_progress

            dask_progress(futures)
        rows = client.gather(futures)
    else:
        n = workers or os.cpu_count() or 1
        with ThreadPoolExecutor(max_workers=n) as pool:
            jobs = [pool.submit(_one, *a) for a in args]
            if progress:
                _bar(jobs)
            rows = [j.result() for j in jobs]
    return _table(rows)


def _bar(jobs: List[Any]) -> None:
    """A tqdm bar over futures (``concurrent.futures`` or Dask's), when tqdm is installed."""
    try:
        from tqdm import tqdm
    except ImportError:
        return
    import concurrent.futures

    with tqdm(total=len(jobs), unit="record", file=sys.stderr) as bar:
        for _ in concurrent.futures.as_completed(jobs):
            bar.update(1)


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``python -m reldesign.batch MODEL.toml DIR --scheduler ADDRESS|local|threads --out RESULTS.parquet``."""
    parser = argparse.ArgumentParser(
        prog="python -m reldesign.batch",
        description="Diagnose every *.csv record of DIR against MODEL.toml; one row per record.",
    )
    parser.add_argument("model", help="the actuator description (valve.toml)")
    parser.add_argument("records", help="a directory of *.csv records, or a glob")
    parser.add_argument(
        "--scheduler",
        default="threads",
        help="a Dask scheduler's address (tcp://host:8786), `local` for a LocalCluster "
        "on this machine, or `threads` for no Dask (default)",
    )
    parser.add_argument("--workers", type=int, default=None, help="local workers (default: the cores)")
    parser.add_argument("--out", required=True, help="results table (.parquet or .csv)")
    parser.add_argument("--out-dir", default=None, help="write each record's extended model and report here")
    parser.add_argument("--holdout", type=float, default=0.25)
    parser.add_argument(
        "--causes", default=None, help="try only these causes (comma-separated, as the CLI's --causes)"
    )
    args = parser.parse_args(argv)
    actuator = Actuator.from_toml(args.model)
    client = cluster = None
    if args.scheduler not in ("threads", "none"):
        from dask.distributed import Client, LocalCluster

        if args.scheduler == "local":
            cluster = LocalCluster(
                n_workers=args.workers or os.cpu_count() or 1,
                threads_per_worker=1,
                processes=True,
            )
            client = Client(cluster)
        else:
            client = Client(args.scheduler)
    try:
        table = _run_with_bar(actuator, args, client)
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    if args.out.endswith(".csv"):
        table.to_csv(args.out, index=False)
    else:
        table.to_parquet(args.out, index=False)
    failed = int(table["error"].notna().sum())
    print(
        f"{len(table)} records, {failed} failed; causes: "
        + ", ".join(f"{c} {n}" for c, n in table["cause"].value_counts().items())
        + f"; written to {args.out}",
        file=sys.stderr,
    )
    return 1 if failed else 0


def _run_with_bar(actuator: Actuator, args: argparse.Namespace, client: Any) -> pd.DataFrame:
    items = records_of(args.records)
    causes = args.causes.split(",") if args.causes else None
    if client is None:
        return diagnose_many(
            actuator, [r for _, r in items], out_dir=args.out_dir, holdout=args.holdout,
            causes=causes, workers=args.workers, progress=True,
        )
    out = args.out_dir
    if out is not None:
        os.makedirs(out, exist_ok=True)
    futures = client.map(
        _one,
        *zip(*[(actuator.text, actuator.file_name, n, r, out, args.holdout, causes) for n, r in items]),
        pure=False,
    )
    try:
        from tqdm import tqdm
        from dask.distributed import as_completed

        with tqdm(total=len(futures), unit="record", file=sys.stderr) as bar:
            for _ in as_completed(futures):
                bar.update(1)
    except ImportError:
        from dask.distributed import progress

        progress(futures)
    return _table(client.gather(futures))


if __name__ == "__main__":
    sys.exit(main())
