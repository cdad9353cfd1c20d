#!/usr/bin/env python3
"""Benchmark: reldesign's simulator against scipy's solve_ivp, at equal accuracy.

Usage:
  benches/simulate_vs_scipy.py RELDESIGN [--model MODEL.toml] [--input IN.csv] [--repeat N]
                               [--accuracy 1e-6] [--methods DOP853,RK45] [--rust-rtol RTOL]
                               [--rust-processes K]
  benches/simulate_vs_scipy.py --scipy-only [...]

Defaults: examples/jiles-atherton-valve.toml on tests/data/ja-three-pulses.csv,
N = 20.  RELDESIGN is the binary's path or a quoted command (split like a shell).

1. Reference: the scipy hybrid automaton (tests/oracle/hybrid.py) with DOP853 at
   rtol 1e-12 (atol = rtol·state scale).
2. scipy: for each method, the loosest rtol of 1e-4 … 1e-11 such that it and
   every tighter one give max|Δi| ≤ --accuracy [A] against the reference; that
   run is timed N times (median wall time of `hybrid.simulate`, file reading
   excluded).
3. reldesign: the same rtol search with
       RELDESIGN simulate MODEL --input IN --out OUT.csv --rtol RTOL --repeat 1
   (or --rust-rtol), then --rust-processes times (default 5)
       RELDESIGN simulate MODEL --input IN --out OUT.csv --rtol RTOL --repeat N
   which must print `elapsed_per_run_s=<float>` on stderr (median time per
   simulation over the N runs of that process, parsing and output excluded)
   and write the trajectory (t,v,i,z,vz,phi[,Hc],mode); the time reported is
   the median over the processes (like scipy's median over its runs, it
   resists a busy machine). Its accuracy is checked on the last output:
   max|Δi| ≤ --accuracy [A].
Prints a table and the ratio (fastest scipy) / reldesign.  Exit 1 when a side
cannot reach the accuracy, a command fails, or `elapsed_per_run_s` is missing.
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "oracle"))

import hybrid  # noqa: E402
from desc import load  # noqa: E402

RTOLS = [1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4]  # tight -> loose


def errors(ref: hybrid.Result, i, phi):
    di = float(np.max(np.abs(np.asarray(i) - ref.i)))
    dphi = float(np.max(np.abs(np.asarray(phi) - ref.x[:, 2])) / np.max(np.abs(ref.x[:, 2])))
    return di, dphi


def scipy_side(p, t, v, ref, method, accuracy, repeat):
    chosen = None
    for rtol in RTOLS:
        try:
            r = hybrid.simulate(p, t, v, rtol=rtol, method=method)
        except Exception as e:  # a too-loose run may fail outright
            print(f"    scipy {method} rtol {rtol:g}: failed ({e})")
            break
        di, dphi = errors(ref, r.i, r.x[:, 2])
        print(f"    scipy {method} rtol {rtol:g}: max|Δi| = {di:.2e} A, max|Δφ|/max|φ| = {dphi:.2e}, "
              f"{r.nfev} RHS evaluations")
        if di > accuracy:
            break
        chosen = (rtol, di, dphi, r.nfev)
    if chosen is None:
        return None
    rtol = chosen[0]
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        hybrid.simulate(p, t, v, rtol=rtol, method=method)
        times.append(time.perf_counter() - t0)
    return {"side": "scipy", "method": method, "rtol": rtol, "di": chosen[1], "dphi": chosen[2],
            "time": statistics.median(times), "runs": repeat, "nfev": chosen[3]}


def run_rust(cmd, model, inp, out, rtol, repeat):
    argv = [*shlex.split(cmd), "simulate", model, "--input", inp, "--out", out, "--rtol", repr(rtol),
            "--repeat", str(repeat)]
    r = subprocess.run(argv, capture_output=True, text=True, timeout=3600)
    if r.returncode != 0:
        raise RuntimeError(f"`{shlex.join(argv)}` exited with {r.returncode}:\n{r.stderr.strip()}")
    m = re.search(r"elapsed_per_run_s=([0-9.eE+\-]+|nan|inf)", r.stderr)
    el = float(m.group(1)) if m else None
    d = hybrid.read_csv(out)
    return el, d, shlex.join(argv)


def rust_side(cmd, model, inp, ref, accuracy, repeat, fixed_rtol, workdir, processes=5):
    out = os.path.join(workdir, "reldesign.csv")
    rtols = [fixed_rtol] if fixed_rtol else RTOLS
    chosen = None
    for rtol in rtols:
        try:
            _, d, _ = run_rust(cmd, model, inp, out, rtol, 1)
        except RuntimeError as e:
            print(f"    reldesign rtol {rtol:g}: {e}")
            break
        if len(d.get("t", [])) != len(ref.t):
            raise RuntimeError(f"reldesign output has {len(d.get('t', []))} rows, expected {len(ref.t)}")
        di, dphi = errors(ref, d["i"], d["phi"])
        print(f"    reldesign rtol {rtol:g}: max|Δi| = {di:.2e} A, max|Δφ|/max|φ| = {dphi:.2e}")
        if di > accuracy:
            break
        chosen = rtol
    if chosen is None:
        return None
    times = []
    for _ in range(max(1, processes)):
        el, d, argv = run_rust(cmd, model, inp, out, chosen, repeat)
        if el is None:
            raise RuntimeError(f"`{argv}` did not print elapsed_per_run_s=<float> on stderr")
        times.append(el)
    di, dphi = errors(ref, d["i"], d["phi"])
    return {"side": "reldesign", "method": "reldesign", "rtol": chosen, "di": di, "dphi": dphi,
            "time": statistics.median(times), "runs": repeat * len(times), "nfev": None, "argv": argv}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("reldesign", nargs="?")
    ap.add_argument("--model", default=os.path.join(ROOT, "examples", "jiles-atherton-valve.toml"))
    ap.add_argument("--input", default=os.path.join(ROOT, "tests", "data", "ja-three-pulses.csv"))
    ap.add_argument("--repeat", type=int, default=20, help="timed runs per side (median; default 20)")
    ap.add_argument("--accuracy", type=float, default=1e-6, help="max |Δi| [A] vs the reference (default 1e-6)")
    ap.add_argument("--methods", default="DOP853,RK45", help="scipy methods (default DOP853,RK45)")
    ap.add_argument("--rust-rtol", type=float, help="use this rtol for reldesign instead of searching")
    ap.add_argument("--rust-processes", type=int, default=5,
                    help="timed reldesign processes of --repeat runs each (median; default 5)")
    ap.add_argument("--scipy-only", action="store_true")
    ap.add_argument("--keep", metavar="DIR")
    a = ap.parse_args(argv)
    if not a.scipy_only and not a.reldesign:
        ap.error("give RELDESIGN (or --scipy-only)")
    for path in (a.model, a.input):
        if not os.path.exists(path):
            ap.error(f"{path} does not exist")

    p = load(a.model)
    t, v = hybrid.read_input(a.input)
    print(f"== {a.model} on {a.input}: {len(t)} samples, {t[-1] - t[0]:g} s")
    t0 = time.perf_counter()
    ref = hybrid.simulate(p, t, v, rtol=1e-12, method="DOP853")
    print(f"  reference: scipy DOP853 rtol 1e-12, {ref.nfev} RHS evaluations, {time.perf_counter() - t0:.2f} s; "
          f"max|i| = {np.max(np.abs(ref.i)):.4f} A, {len(ref.events)} events")

    rows, ok = [], True
    for method in [m.strip() for m in a.methods.split(",") if m.strip()]:
        print(f"  scipy {method}: rtol search (accuracy {a.accuracy:g} A)")
        row = scipy_side(p, t, v, ref, method, a.accuracy, a.repeat)
        if row is None:
            print(f"  FAIL: scipy {method} does not reach {a.accuracy:g} A at any rtol")
            ok = False
        else:
            rows.append(row)
    if not a.scipy_only:
        workdir = a.keep or tempfile.mkdtemp(prefix="bench_sim_")
        os.makedirs(workdir, exist_ok=True)
        print("  reldesign: rtol search")
        try:
            row = rust_side(a.reldesign, a.model, a.input, ref, a.accuracy, a.repeat, a.rust_rtol, workdir,
                            a.rust_processes)
        except (RuntimeError, OSError, KeyError, ValueError) as e:
            print(f"  FAIL: {e}")
            row, ok = None, False
        if row is None:
            if ok:
                print(f"  FAIL: reldesign does not reach {a.accuracy:g} A at any rtol")
            ok = False
        else:
            if row["di"] > a.accuracy:
                print(f"  FAIL: the timed reldesign run has max|Δi| = {row['di']:.2e} A > {a.accuracy:g}")
                ok = False
            rows.append(row)

    print(f"\n  {'side':<10} {'method':<10} {'rtol':>7} {'max|Δi| [A]':>12} {'max|Δφ|/|φ|':>12} "
          f"{'time/run':>12} {'runs':>5}")
    for r in rows:
        print(f"  {r['side']:<10} {r['method']:<10} {r['rtol']:7.0e} {r['di']:12.2e} {r['dphi']:12.2e} "
              f"{r['time'] * 1e3:9.3f} ms {r['runs']:5d}")
    sc = [r for r in rows if r["side"] == "scipy"]
    rs = [r for r in rows if r["side"] == "reldesign"]
    if sc and rs and rs[0]["time"] > 0:
        best = min(sc, key=lambda r: r["time"])
        print(f"\n  speed-up (scipy {best['method']} / reldesign): {best['time'] / rs[0]['time']:.1f}x")
    print("\nbench: " + ("OK" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
