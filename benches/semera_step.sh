#!/usr/bin/env bash
# Estimator step benchmark: the generated SEMERA (semera Algorithm 1) and integral
# estimator (Algorithm 2) of examples/semera-valve.toml, f64 and f32: instructions per
# step (callgrind) and ns per step. See benches/semera_step/run.py.
# Needs: cargo, valgrind (callgrind_annotate), python3.
set -euo pipefail
exec python3 "$(dirname "$0")/semera_step/run.py" "$@"
