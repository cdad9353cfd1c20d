#!/usr/bin/env bash
# Kalman filter step benchmark: the EKF and UKF emitted for the perfect-tracking
# valve (reldesign_build::emit_ekf / emit_ukf, f64 and f32, T_s = 50 µs); instructions per
# step (callgrind, 2N − N difference) and ns per step. See benches/kalman_step/run.py.
# Needs: cargo, valgrind (callgrind_annotate), python3.
set -euo pipefail
exec python3 "$(dirname "$0")/kalman_step/run.py" "$@"
