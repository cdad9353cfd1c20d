#!/usr/bin/env bash
# The five-parameter Jiles–Atherton fit of issue 5 on a 40 000-sample record
# (JA valve, ±24 V square wave, 10 µs, σ_v = 15 mV, σ_i = 1 mA; M_sat, b, c,
# κ, α perturbed by 20–40 %). Prints the wall time, iterations, replays and
# the recovered values (issue 5: < 30 s on 2 cores; issue 36: <= 3 s). The test lives in
# identify/tests/fit.rs (the fit moved to reldesign-identify).
#
#   bash benches/fit.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release -p reldesign-identify --test fit \
    jiles_atherton_parameters_are_recovered_from_40000_samples \
    -- --ignored --nocapture 2>&1 | grep -E "JA fit|core\.|test result"
