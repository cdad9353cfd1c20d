#!/usr/bin/env bash
# `reldesign limits` on the bundled valves (issue 11; target: < 2 s for the
# perfect-tracking valve on 2 cores): wall time of each of 5 runs and the
# median, per description. Run from anywhere:
#
#   bash benches/limits.sh [MODEL.toml …]
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p reldesign
models=("$@")
[ ${#models[@]} -gt 0 ] || models=(examples/perfect-tracking-valve.toml examples/sliding-mode-valve.toml examples/semera-valve.toml examples/table-gap-valve.toml)
for m in "${models[@]}"; do
  times=()
  for _ in 1 2 3 4 5; do
    start=$(date +%s.%N)
    ./target/release/reldesign limits "$m" > /dev/null
    end=$(date +%s.%N)
    times+=("$(echo "$end - $start" | bc -l)")
  done
  median=$(printf '%s\n' "${times[@]}" | sort -g | sed -n 3p)
  printf '%-45s median %.2f s  (runs: %s)\n' "$m" "$median" "$(printf '%.2f ' "${times[@]}")"
done
