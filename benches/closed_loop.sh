#!/usr/bin/env bash
# The closed-loop commands of the sliding-mode issue on examples/sliding-mode-valve.toml,
# release CLI, best of 3 wall-clock runs each (targets on 2 cores):
#   robustness: 4 parameters varied, 1000 Monte-Carlo draws (rayon), --json   < 5 s
#   sweep:      the 7 default sample periods, closed loop each (rayon), --json < 5 s
# Prints each run's time, the best, the target and MET/NOT MET. Run from anywhere
# (builds `cargo build --release -p reldesign` into $CARGO_TARGET_DIR, default target/):
#
#   bash benches/closed_loop.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p reldesign
bin="${CARGO_TARGET_DIR:-target}/release/reldesign"
model=examples/sliding-mode-valve.toml
target=5
status=0

# best of 3 wall-clock runs of "$@" (stdout must be valid JSON)
bench() {
  local name=$1
  shift
  local times=() out
  out=$(mktemp)
  for _ in 1 2 3; do
    local start end
    start=$(date +%s.%N)
    "$bin" "$@" > "$out"
    end=$(date +%s.%N)
    python3 -c 'import json, sys; json.load(open(sys.argv[1]))' "$out"
    times+=("$(echo "$end - $start" | bc -l)")
  done
  rm -f "$out"
  local best verdict
  best=$(printf '%s\n' "${times[@]}" | sort -g | head -1)
  if (( $(echo "$best < $target" | bc -l) )); then verdict=MET; else verdict="NOT MET"; status=1; fi
  printf '%-11s best %.2f s  (runs: %s)  target < %s s: %s\n' \
    "$name" "$best" "$(printf '%.2f ' "${times[@]}")" "$target" "$verdict"
}

echo "== $("$bin" --version), $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
bench robustness robustness "$model" \
  --vary coil.resistance=±10% --vary mechanics.mass=±10% \
  --vary gap.r0_prime=±5% --vary mechanics.stiffness=±10% --draws 1000 --json
bench sweep sweep "$model" --json
exit $status
