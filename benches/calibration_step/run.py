#!/usr/bin/env python3
"""Benchmark: what the emitted self-calibration costs (issue 35).

Usage: bash benches/calibration_step.sh [--reps R]

The driver (benches/calibration_step/rust, its own workspace, cargo --release,
target dir target/calibration_step) emits examples/self-calibrating-valve.toml
twice in build.rs: as it is (θ, the 10 adapted parameters, read at run time by the
law and the UKF; the update `ukf::…::calibrate`) and with self_calibration = false
(every parameter a const the compiler folds: what a firmware that never adapts
compiles). The record is one run (closing, opening; 1750 samples at 50 µs) of the
design on a plant 15 % more resistive with a 10 % softer spring, simulated by the
designer with the example's noise.

Measures (instructions: valgrind --tool=callgrind, total Ir of a run with 2N calls
minus that of a run with N calls, / N):
1. one control sample (UKF step + controller step), fixed and adaptive, f64 and f32,
   N = 2002 (over the record, cycled), net of the loop without the calls; and the
   record's push of one sample (the firmware's other per-sample addition);
2. one whole update (calibrate on the run's record, from θ_d), f64 and f32, N = 1;
3. wall clock of the update (best of R) on this machine;
4. RAM of the emitted types (size_of);
5. the same for the replay update (examples/self-calibrating-sensor-valve.toml, a
   law on measured states): the controller step folded and with θ, Record::push,
   one update over its closing's record (N = 1), its RAM.
"""
from __future__ import annotations

import argparse
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
TARGET = os.path.join(ROOT, "target", "calibration_step")
BIN = os.path.join(TARGET, "release", "calibration-step-bench")
RUN = 1001
# Cortex-M4F at 168 MHz, one instruction a cycle: a rough scale only (x86-64
# instructions are not Thumb-2 ones; f64 is software on an M4F, so its figure
# there is tens of times this)
MHZ = 168


def per_call(kind: str, n: int, work: str) -> float:
    ir, _ = callgrind.difference(lambda calls: [BIN, kind, str(calls), "1"], n, work, kind)
    return ir


def wall(kind: str, reps: int) -> float:
    out = sh([BIN, kind, "1", str(reps)]).stdout
    return float(re.search(r"best_ns_per_call=([\d.e+-]+)", out).group(1))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    env = dict(os.environ, CARGO_TARGET_DIR=TARGET)
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=os.path.join(HERE, "rust"),
                   env=env, check=True)
    sizes = dict(line.split("=") for line in sh([BIN, "sizes"]).stdout.split())
    with tempfile.TemporaryDirectory() as work:
        base = {f: per_call(f"base{f}", 2 * RUN, work) for f in ("64", "32")}
        print("one control sample (UKF step + controller step), instructions")
        print(f"{'':6} {'fixed':>10} {'adaptive':>10} {'added':>8}")
        for f in ("64", "32"):
            fixed = per_call(f"step{f}fixed", 2 * RUN, work) - base[f]
            adaptive = per_call(f"step{f}adaptive", 2 * RUN, work) - base[f]
            push = per_call(f"push{f}", 2 * RUN, work) - base[f]
            print(f"f{f:4} {fixed:10.0f} {adaptive:10.0f} {adaptive - fixed:+8.0f} "
                  f"({100 * (adaptive / fixed - 1):+.1f} %); Record::push {push:.0f}")
        print()
        print(f"one update over a run of {sizes['run_samples']} samples, "
              f"{sizes['parameters']} parameters")
        for f in ("64", "32"):
            ir = per_call(f"update{f}", 1, work)
            ms = wall(f"update{f}", args.reps) / 1e6
            print(f"f{f:4} {ir / 1e6:8.1f} M instructions, {ms:6.1f} ms here, "
                  f"~{ir / (MHZ * 1e3):6.0f} ms at {MHZ} MHz one instruction a cycle")
        print()
        ops = int(sizes["replay_operation_samples"])
        sbase = {f: per_call(f"sensorbase{f}", 2 * ops, work) for f in ("64", "32")}
        print(f"the replay (self-calibrating-sensor-valve: {sizes['replay_parameters']} parameters, "
              f"a record of {sizes['replay_record_samples']} samples, one every "
              f"{sizes['replay_decimation']})")
        print(f"{'':6} {'law fixed':>10} {'adaptive':>10} {'added':>8}")
        for f in ("64", "32"):
            fixed = per_call(f"law{f}fixed", 2 * ops, work) - sbase[f]
            adaptive = per_call(f"law{f}adaptive", 2 * ops, work) - sbase[f]
            push = per_call(f"replaypush{f}", 2 * ops, work) - sbase[f]
            ir = per_call(f"replay{f}", 1, work)
            ms = wall(f"replay{f}", args.reps) / 1e6
            print(f"f{f:4} {fixed:10.0f} {adaptive:10.0f} {adaptive - fixed:+8.0f} "
                  f"({100 * (adaptive / fixed - 1):+.1f} %); Record::push {push:.0f}; "
                  f"one update {ir / 1e6:.2f} M instructions, {ms:.2f} ms here, "
                  f"~{ir / (MHZ * 1e3):.0f} ms at {MHZ} MHz")
    print()
    print("RAM (bytes): record f32 {record32}, f64 {record64}; calibration f32 {calibration32}; "
          "UKF f32 adaptive {filter32_adaptive} (fixed {filter32_fixed}); controller f32 adaptive "
          "{controller32_adaptive} (fixed {controller32_fixed}); the update's P + 1 filters "
          "f32 {update32}".format(update32=(int(sizes["parameters"]) + 1) * int(sizes["filter32_adaptive"]),
                                  **sizes))
    print("replay RAM (bytes): record f32 {replay_record32}, f64 {replay_record64}; calibration f32 "
          "{replay_calibration32}; controller f32 adaptive {replay_controller32_adaptive} (fixed "
          "{replay_controller32_fixed})".format(**sizes))


if __name__ == "__main__":
    main()
