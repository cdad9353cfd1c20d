#!/usr/bin/env bash
# The emitted self-calibration's cost: the control sample (UKF + controller) with θ at
# run time against every parameter folded, the update's instructions (f64, f32) and the
# RAM of the emitted types. See benches/calibration_step/run.py.
# Needs: cargo, valgrind, python3.
set -euo pipefail
exec python3 "$(dirname "$0")/calibration_step/run.py" "$@"
