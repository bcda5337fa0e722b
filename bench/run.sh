#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds and runs the tissue benchmarks in one process (all models, all meshes, bandwidth probe),
# writes bench/results/tissue.json and prints the summary table used in docs/PERFORMANCE.md.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/deploy/build.sh" "$root/build"
mkdir -p "$root/bench/results"
"$root/build/bench/tissue_bench" --benchmark_repetitions="${REPETITIONS:-5}" \
  --benchmark_report_aggregates_only=true --benchmark_min_time="${MIN_TIME:-0.3}" \
  --benchmark_enable_random_interleaving=true \
  --benchmark_out="$root/bench/results/tissue.json" --benchmark_out_format=json "$@"
python3 "$root/bench/summarize.py" "$root/bench/results/tissue.json"
python3 "$root/bench/performance_tables.py" "$root"
