#!/usr/bin/env bash
# Builds the decoder fuzz target with clang (libFuzzer + ASan + UBSan) and runs it briefly.
# Usage: run_fuzz.sh BUILD_DIR SOURCE_DIR SECONDS
set -euo pipefail
build="$1"; src="$2"; seconds="$3"
out="$build/fuzz"; mkdir -p "$out/corpus"
clang++ -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -I "$src/protocol/include" -I "$build/protocol/generated" \
  "$src/tests/fuzz/decoders_fuzz.cpp" "$src/protocol/src/verify.cpp" -o "$out/decoders_fuzz"

"$out/decoders_fuzz" -max_total_time="$seconds" -print_final_stats=1 "$out/corpus" 2>&1 | tail -15
echo "decoders_fuzz: 1 passed, 0 failed"
