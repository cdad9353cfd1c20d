#!/usr/bin/env bash
# Controller step benchmark: generated perfect-tracking law (Rust, f64/f32) vs
# CasADi-generated C (gcc -O2) of the same law; instructions per call (callgrind),
# ns per call, trajectory lookup cost. See benches/controller_step/run.py.
# Needs: cargo, gcc, valgrind, python3 with casadi and numpy.
set -euo pipefail
exec python3 "$(dirname "$0")/controller_step/run.py" "$@"
