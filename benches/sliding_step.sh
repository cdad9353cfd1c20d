#!/usr/bin/env bash
# Controller step benchmark of the sliding-mode issue: the generated model-free
# sliding-mode controller of examples/sliding-mode-valve.toml, f64 and f32, on its
# own closed loop's record: instructions per step (callgrind) and ns per step, the
# reference lookup alone beside it. See benches/sliding_step/run.py.
# Needs: cargo, valgrind (callgrind_annotate), python3.
set -euo pipefail
exec python3 "$(dirname "$0")/sliding_step/run.py" "$@"
