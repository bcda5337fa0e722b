#!/usr/bin/env bash
# Builds the decoder fuzz target with clang (libFuzzer + ASan + UBSan) and runs it briefly.
# Usage: run_fuzz.sh BUILD_DIR SOURCE_DIR SECONDS
set -euo pipefail
build="$1"; src="$2"; seconds="$3"
out="$build/fuzz"; mkdir -p "$out/corpus"
includes=(-I "$src/protocol/include" -I "$build/protocol/generated")
clang++ -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined "${includes[@]}" \
  "$src/tests/fuzz/decoders_fuzz.cpp" "$src/protocol/src/verify.cpp" -o "$out/decoders_fuzz"
# Seeds: one valid payload of every message, checked to decode (the fuzzer mutates from them).
clang++ -std=c++20 -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=undefined "${includes[@]}" \
  "$src/tests/fuzz/seed_corpus.cpp" "$src/protocol/src/verify.cpp" -o "$out/seed_corpus"
rm -rf "$out/seeds"
"$out/seed_corpus" "$out/seeds"

# New inputs go to the first directory; the seeds are read only.
"$out/decoders_fuzz" -max_total_time="$seconds" -print_final_stats=1 "$out/corpus" "$out/seeds" 2>&1 | tail -15
echo "decoders_fuzz: 1 passed, 0 failed"
