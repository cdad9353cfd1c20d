#!/usr/bin/env python3
"""Records per second of a batch diagnosis on this machine, three ways, on
the same generated records:

1. the command line, `reldesign diagnose MODEL --batch DIR` (rayon across records);
2. the Python package on the local cores, `reldesign.batch.diagnose_many`
   (a thread pool; each call releases the GIL);
3. the same call on a Dask `LocalCluster` (2 worker processes, 1 thread
   each), the cluster's start timed apart; and the round trip of 40 empty
   tasks on it (what Dask adds per record, apart from the work).

The records: `reldesign simulate` of examples/semera-valve.toml under pulse
trains (amplitude, width and resistance varied per record; eddy currents
hidden in every other one), σ_v = 15 mV and σ_i = 1 mA of noise added,
3 000 samples at 40 µs.

    python benches/python_batch.py [--records 40] [--causes all|quick] [--rounds 2]

Each round runs the three on the records, each writing into the same
directory so that the JSON (which names the written files) compares equal;
the figures printed last are the best of the rounds.

Needs the wheel installed (`pip install ./python`) and a release binary
(`cargo build --release -p reldesign`; RELDESIGN_BIN or CARGO_TARGET_DIR to find it).
"""

from __future__ import annotations

import argparse
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

import reldesign
from reldesign.batch import diagnose_many
from reldesign.synthetic import with_values

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "examples" / "semera-valve.toml"
QUICK = "eddy-currents,saturation,resistance-drift"


def binary() -> Path:
    if os.environ.get("RELDESIGN_BIN"):
        return Path(os.environ["RELDESIGN_BIN"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "release" / "reldesign"


def generate(bin_: Path, directory: Path, n: int, samples: int, dt: float, seed: int = 7) -> None:
    """n records by `reldesign simulate --pulse …` plus noise."""
    rng = np.random.default_rng(seed)
    text = MODEL.read_text()
    t_end = (samples - 1) * dt
    for k in range(n):
        values = {"resistance": round(75.0 * (1 + 0.04 * rng.uniform(-1, 1)), 3)}
        if k % 2 == 1:
            values["eddy"] = 1500.0
        variant = directory / f"truth-{k:03d}.toml.txt"
        variant.write_text(with_values(text, values))
        amplitude = rng.choice([18.0, 24.0, 30.0])
        width = rng.uniform(3e-3, 6e-3)
        pulses = [f"{amplitude}:{s:.6f}:{s + width:.6f}" for s in np.arange(1e-3, t_end - width, 10e-3)]
        args = [str(bin_), "simulate", str(variant), "--dt", repr(dt), "--t-end", repr(t_end)]
        for p in pulses:
            args += ["--pulse", p]
        run = subprocess.run(args, capture_output=True, text=True, check=True)
        frame = pd.read_csv(io.StringIO(run.stdout))
        record = pd.DataFrame(
            {
                "t": frame["t"],
                "v": frame["v"] + 15e-3 * rng.standard_normal(len(frame)),
                "i": frame["i"] + 1e-3 * rng.standard_normal(len(frame)),
            }
        )
        record.to_csv(directory / f"unit-{k:03d}.csv", index=False, float_format="%.10g")
        variant.unlink()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=40)
    parser.add_argument("--samples", type=int, default=3000)
    parser.add_argument("--causes", choices=["all", "quick"], default="all")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--keep", default=None, help="keep the records in this directory")
    args = parser.parse_args()
    bin_ = binary()
    work = Path(args.keep or tempfile.mkdtemp(prefix="python-batch-"))
    records = work / "records"
    records.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    generate(bin_, records, args.records, args.samples, 40e-6)
    print(f"generated {args.records} records of {args.samples} samples in {time.perf_counter() - start:.1f} s")
    causes = None if args.causes == "all" else QUICK.split(",")
    cause_args = [] if causes is None else ["--causes", QUICK]
    n = args.records
    out = work / "out"  # every run writes here: the JSON names the same paths
    out.mkdir(exist_ok=True)
    from dask.distributed import Client, LocalCluster

    rounds = []
    for r in range(args.rounds):
        figures = {}
        start = time.perf_counter()
        run = subprocess.run(
            [str(bin_), "diagnose", str(MODEL), "--batch", str(records), "--out", str(out), *cause_args],
            capture_output=True, text=True,
        )
        figures["CLI diagnose --batch"] = time.perf_counter() - start
        cli_lines = [line for line in run.stdout.splitlines() if line]
        assert len(cli_lines) == n, run.stderr[-2000:]

        start = time.perf_counter()
        local = diagnose_many(str(MODEL), str(records), out_dir=out, causes=causes, workers=os.cpu_count())
        figures["Python diagnose_many, threads"] = time.perf_counter() - start

        start = time.perf_counter()
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
        startup = time.perf_counter() - start
        try:
            start = time.perf_counter()
            client.gather(client.map(lambda k: k, range(n), pure=False))
            empty = time.perf_counter() - start
            start = time.perf_counter()
            distributed = diagnose_many(str(MODEL), str(records), client=client, out_dir=out, causes=causes)
            figures["Python diagnose_many, Dask LocalCluster (2 processes)"] = time.perf_counter() - start
        finally:
            client.close()
            cluster.close()
        same = all(
            json.loads(a) == json.loads(b) == json.loads(c)
            for a, b, c in zip(cli_lines, local["json"], distributed["json"])
        )
        print(f"round {r + 1}: answers identical across the three: {same}; load average {os.getloadavg()}")
        for name, seconds in figures.items():
            print(f"  {name:<56} {seconds:7.1f} s  {n / seconds:6.2f} records/s")
        print(f"  Dask cluster start (not in the figure above)             {startup:7.1f} s")
        print(f"  Dask round trip of {n} empty tasks                         {empty:7.3f} s  ({1e3 * empty / n:.1f} ms per task)")
        rounds.append((figures, startup, empty, same))

    causes_found = local["causes"].replace("", "none").value_counts().to_dict()
    print(f"{n} records of {args.samples} samples, causes {args.causes}; found: {causes_found}")
    print(f"best of {args.rounds} round(s):")
    for name in rounds[0][0]:
        seconds = min(f[name] for f, _, _, _ in rounds)
        print(f"  {name:<56} {seconds:7.1f} s  {n / seconds:6.2f} records/s")
    empty = min(e for _, _, e, _ in rounds)
    print(f"  Dask per task, empty (what Dask adds per record)         {1e3 * empty / n:7.1f} ms")
    same = all(s for _, _, _, s in rounds)
    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
