#!/usr/bin/env bash
# `reldesign diagnose` on records nobody timed it on (issue 36 §2): 40 records
# drawn fresh from the device generator (unseen devices; the four blind
# classes, every single cause, `none`, effects outside the vocabulary;
# 2 000–50 000 samples), each diagnosed as the CLI does. Prints per record the
# rows, the wall time, the time per 10 000 samples and the answer, then the
# distribution (median, 90 %, slowest) per record, per 10 000 samples and
# scaled to 40 000 samples.
# Target (issue 36): median <= 0.5 s and slowest <= 1.5 s for 40 000 samples.
#
#   bash benches/diagnose_fresh.sh            # seed 1
#   SPEED_SEED=7 bash benches/diagnose_fresh.sh
#   SPEED_RECORDS=80 bash benches/diagnose_fresh.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release -p reldesign-tests --test diagnose_speed -- --ignored --nocapture \
    </dev/null 2>&1 | grep -E "^(record|per|scaled|[0-9]+ records)|panicked|error"
