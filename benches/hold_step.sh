#!/usr/bin/env bash
# Position-hold benchmark of the Jiles–Atherton valve (jiles-atherton-actuator-model
# §6): the generated UKF on [z, z_prev, φ, H_c] and the generated model-based
# sliding-mode hold of examples/jiles-atherton-valve.toml, f64 and f32, on a record of
# the design's own closed loop: instructions per step (callgrind, 2N − N), the
# floating-point operations among them, ns per step, and a Cortex-M4F estimate.
# See benches/hold_step/run.py.
# Needs: cargo, valgrind (callgrind), llvm-objdump, python3.
set -euo pipefail
exec python3 "$(dirname "$0")/hold_step/run.py" "$@"
