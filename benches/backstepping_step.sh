#!/usr/bin/env bash
# Backstepping benchmark of the valve of examples/backstepping-valve.toml
# (switched-force-backstepping [SB 19], certified region [SB Theorem 3], hybrid
# switching [SB 31–33], T_s = 10 µs): the generated `Controller::step` and the law alone,
# f64 and f32, on a record of the design's own closed loop: instructions per call
# (callgrind, 2N − N), the floating-point operations among them, ns per call, a
# Cortex-M4F estimate at 100 kHz and 20 kHz; then the design's cost: the release CLI's
# `reldesign build` of the example (wall, best of 5) and the certified region's conic
# solves alone (`design_region`, median µs). See benches/backstepping_step/run.py.
# Needs: cargo, valgrind (callgrind), llvm-objdump, python3.
set -euo pipefail
exec python3 "$(dirname "$0")/backstepping_step/run.py" "$@"
