#!/usr/bin/env python3
"""Benchmark: one step of the generated EKF and UKF (jiles-atherton-actuator-model §6.1).

Usage: bash benches/kalman_step.sh [--n N] [--time-n N] [--runs R] [--reps R]

The driver (benches/kalman_step/rust, its own workspace, cargo --release, target dir
target/kalman_step) generates its filters in build.rs with reldesign_build::emit_ekf and
reldesign_build::emit_ukf (the runtime's reldesign_runtime::observe::{Ekf, Ukf} on the emitted
model functions) from examples/perfect-tracking-valve.toml (T_s = 50 µs, σ_v = 15 mV,
σ_i = 1 mA, the process noise of the observer tests) and a 400-sample noisy record of
the valve driven open loop (closing with 24 V, opening with 0 V and a −24 V pulse,
rest), simulated by the designer. Each kind runs `Filter::step` over the record,
cycled (rest, strokes and bounces in the proportions of the record):

- ekf64, ekf32: the extended Kalman filter (x = [z, z_prev, φ]: model, Jacobians,
  Joseph update);
- ukf64, ukf32: the unscented Kalman filter (7 sigma points, two Cholesky
  factorisations per step);
- base64, base32: the loop without the call.

Measures:
1. instructions per step: valgrind --tool=callgrind total Ir of a run with 2N steps
   minus that of a run with N steps, / N (startup and record setup cancel; N is a
   multiple of the record's 400 samples, so both halves see the same samples).
   "net" subtracts the loop without the call.
2. ns per step: wall clock, best over R processes × R' in-process repetitions of
   --time-n steps (the kinds take turns, so machine load hits all alike).
3. sanity: the estimates of every filter over one record are finite, and f32 stays
   within 1e-4 of the stroke (0.1 µm, ten times below the
   estimation error) of f64 (exit 1 otherwise).
"""
from __future__ import annotations

import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import callgrind  # noqa: E402  (benches/callgrind.py)
from callgrind import sh  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
TARGET = os.path.join(ROOT, "target", "kalman_step")
BIN = os.path.join(TARGET, "release", "kalman-step-bench")
RECORD = 400

ROWS = [
    ("ekf64", "EKF f64 Filter::step"),
    ("ekf32", "EKF f32 Filter::step"),
    ("ukf64", "UKF f64 Filter::step"),
    ("ukf32", "UKF f32 Filter::step"),
    ("base64", "loop without call (f64)"),
    ("base32", "loop without call (f32)"),
]


def build():
    print("== build (the first build compiles the designer for build.rs: minutes)")
    r = subprocess.run(["cargo", "build", "--release", "--quiet", "--manifest-path",
                        os.path.join(HERE, "rust", "Cargo.toml"), "--target-dir", TARGET])
    if r.returncode:
        sys.exit("cargo build failed")
    print(f"  {sh(['rustc', '--version']).stdout.strip()}")


def check():
    rows = list(csv.DictReader(sh([BIN, "dump"]).stdout.splitlines()))
    assert len(rows) == RECORD
    ok = True
    for k in ("ekf64_z", "ekf32_z", "ukf64_z", "ukf32_z", "ekf64_phi", "ukf64_phi"):
        if not all(abs(float(r[k])) < float("inf") for r in rows):
            print(f"  {k}: not finite")
            ok = False
    stroke = 1e-3
    for a, b in (("ekf64_z", "ekf32_z"), ("ukf64_z", "ukf32_z")):
        d = max(abs(float(r[a]) - float(r[b])) for r in rows) / stroke
        good = d <= 1e-4
        ok &= good
        print(f"  max |{b} − {a}| / stroke = {d:.1e}  {'ok' if good else 'FAIL (> 1e-4)'}")
    return ok


def instructions(kind, n, work):
    """(Ir per step, {function: self Ir per step}) from the 2N − N difference."""
    per_call, files = callgrind.difference(lambda calls: [BIN, kind, str(calls), "1"], n, work, kind)
    # the bench's and the runtime's paths left out of the names
    strip = r"kalman_step_bench::valve::|reldesign_runtime::observe::|reldesign_runtime::"
    return per_call, callgrind.self_costs_per_call(files, n, strip)


def nanoseconds(n, runs, reps):
    best = {kind: float("inf") for kind, _ in ROWS}
    for _ in range(runs):
        for kind, _ in ROWS:
            out = sh([BIN, kind, str(n), str(reps)]).stdout
            ns = float(re.search(r"best_ns_per_call=([0-9.eE+-]+)", out).group(1))
            best[kind] = min(best[kind], ns)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=8000, help="steps under callgrind (runs N and 2N; a multiple of 400)")
    ap.add_argument("--time-n", type=int, default=400000, help="steps per timed repetition")
    ap.add_argument("--runs", type=int, default=5, help="timed processes per kind")
    ap.add_argument("--reps", type=int, default=5, help="timed repetitions per process")
    a = ap.parse_args()
    if a.n % RECORD:
        sys.exit(f"--n must be a multiple of {RECORD}")
    work = tempfile.mkdtemp(prefix="kalman_step_")
    build()
    print("\n== sanity of the estimates over the record")
    ok = check()

    print(f"\n== measuring: callgrind N = {a.n} vs 2N; wall clock best of {a.runs}×{a.reps} × {a.time_n} steps")
    ns = nanoseconds(a.time_n, a.runs, a.reps)
    res, breakdown = {}, {}
    for kind, _ in ROWS:
        ir, breakdown[kind] = instructions(kind, a.n, work)
        res[kind] = (ir, ns[kind])

    print(f"\n{'':<30}{'instr/step':>11}{'net instr':>11}{'ns/step':>9}")
    for kind, desc in ROWS:
        ir, t = res[kind]
        base = "base32" if kind.endswith("32") else "base64"
        net = f"{ir - res[base][0]:11.1f}" if kind != base else f"{'':>11}"
        print(f"{desc:<30}{ir:11.1f}{net}{t:9.2f}")

    print("\n== where the instructions go (self Ir per step by function, from the 2N − N difference)")
    for kind in ("ekf64", "ekf32", "ukf64", "ukf32"):
        parts = sorted(breakdown[kind].items(), key=lambda kv: -kv[1])
        print(f"  {kind}: " + "; ".join(f"{c:.1f} {f}" for f, c in parts[:8]))
    print(f"\n(work files in {work})")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
