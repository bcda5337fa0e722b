#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# One physics tick of each bundled scene as the server builds it, forces on one and two threads
# (build/bench/tick_bench, Google Benchmark; 3 repetitions, medians), into bench/results/tick.json,
# and the tables of docs/PERFORMANCE.md regenerated. Usage: bench/tick.sh [benchmark flags]
set -euo pipefail
if [ "${1:-}" = "--help" ]; then sed -n '3,5p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/deploy/build.sh" "$root/build" > /dev/null
mkdir -p "$root/bench/results"
"$root/build/bench/tick_bench" --benchmark_repetitions="${REPETITIONS:-3}" --benchmark_report_aggregates_only=true \
  --benchmark_out="$root/bench/results/tick.json" --benchmark_out_format=json "$@"
python3 "$root/bench/performance_tables.py" "$root"
