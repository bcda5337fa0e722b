#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds the fuzz targets with clang (libFuzzer + ASan + UBSan; tests/fuzz/CMakeLists.txt) and runs
# each briefly from a seed corpus: the decoders from one valid payload of every message, the
# readers from the shipped scenes, materials, meshes, data set and a fitted model.
# Usage: run_fuzz.sh BUILD_DIR SOURCE_DIR SECONDS   (SECONDS per target)
set -euo pipefail
build="$1"; src="$2"; seconds="$3"
out="$build/fuzz"
launcher=()
if command -v ccache >/dev/null; then  # as deploy/build.sh: objects kept between runs and clones
  export CCACHE_BASEDIR="$src" CCACHE_NOHASHDIR=true
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S "$src/tests/fuzz" -B "$out" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=None "${launcher[@]}" \
  -DVISCERA_SOURCE="$src" -DVISCERA_BUILD="$build" > /dev/null
cmake --build "$out" -j "$(nproc)"

# Decoders: each seed must decode as its own type (seed_corpus checks), then the fuzzer mutates them.
rm -rf "$out/seeds-decoders"; mkdir -p "$out/corpus-decoders"
"$out/seed_corpus" "$out/seeds-decoders"
"$out/decoders_fuzz" -max_total_time="$seconds" -print_final_stats=1 "$out/corpus-decoders" "$out/seeds-decoders" 2>&1 | tail -8

# Readers: the first byte picks the reader (readers_fuzz.cpp), the rest is the shipped file.
seeds="$out/seeds-readers"; rm -rf "$seeds" "$out/seeds-mcap"; mkdir -p "$seeds" "$out/corpus-readers"
seed() {  # selector file
  { printf "\\$(printf '%03o' "$1")"; head -c 200000 "$2"; } > "$seeds/$1-$(basename "$2")"
}
for f in "$src"/data/scenes/*.json; do seed 0 "$f"; seed 8 "$f"; done
for f in "$src"/data/materials/*.json; do seed 1 "$f"; done
for f in "$src"/data/exercises/*.json; do seed 10 "$f"; done
seed 3 "$src/data/meshes/liver.msh"
seed 4 "$src/data/meshes/heart_imstk-unity.vtk"
seed 5 "$src/data/meshes/volumetricTongue0.vtu"
seed 6 "$src/data/titin-passive-muscle/dataset.json"
for f in "$src"/data/titin-passive-muscle/*.csv; do seed 7 "$f"; done
"$out/mcap_seeds" "$out/seeds-mcap"
for f in "$out"/seeds-mcap/*.mcap; do seed 9 "$f"; done
# Nesting far past the bound, for every JSON reader (a recursion per level crashed them).
python3 -c "print('['*100000 + ']'*100000)" > "$out/deep.json"
for k in 0 1 6 8 10; do seed "$k" "$out/deep.json"; done
# Names that become paths.
for n in force-drill ../../escaped .hidden 'a/b' "$(printf 'a\033b')" liver.json; do printf '\013%s' "$n" > "$seeds/11-$(echo "$n" | tr -c 'a-z' _)"; done
printf '\002{"model": "m", "fitted_to": "d", "units": "SI", "mechanisms": ["broadband_relaxation", "strain_stiffening"], "modulus_pa": 1000, "viscosity_pa_s": 10, "relaxation_time_s": [0.1, 10], "relaxation_modulus_pa": [100, 50], "stiffening_b": 3}' > "$seeds/2-model.json"
"$out/readers_fuzz" -max_total_time="$seconds" -max_len=262144 -timeout=10 -rss_limit_mb=4096 -print_final_stats=1 \
  "$out/corpus-readers" "$seeds" 2>&1 | tail -8
# Cutting: random sweeps (up to 32 per input) through a box, from seeds of 32 sweeps each; the
# target counts the sweeps it applied. At least 10,000 are required: it runs in rounds of twice
# the others' time, each going on from the corpus the last one grew, until they are reached (a
# slow or busy machine takes more rounds, at most six).
seeds="$out/seeds-cutting"; rm -rf "$seeds"; mkdir -p "$seeds" "$out/corpus-cutting"
python3 -c "
import random, sys
r = random.Random(35)
for i in range(32):
    open(sys.argv[1] + '/seed-%02d' % i, 'wb').write(bytes(r.randrange(256) for _ in range(1 + 32 * 10)))
" "$seeds"
applied=0; rounds=0
while [ "$applied" -lt 10000 ] && [ "$rounds" -lt 6 ]; do
  "$out/cutting_fuzz" -max_total_time="$((2 * seconds))" -max_len=400 -timeout=10 -print_final_stats=1 "$out/corpus-cutting" "$seeds" 2>&1 \
    | tail -8 | tee "$out/cutting.log"
  round=$(sed -n 's/^cutting_fuzz: \([0-9]*\) sweeps applied.*$/\1/p' "$out/cutting.log" | tail -1)
  [ -n "$round" ] || { echo "fuzz: cutting_fuzz did not report its sweeps"; exit 1; }
  applied=$((applied + round)); rounds=$((rounds + 1))
done
echo "fuzz: cutting_fuzz applied $applied sweeps in $rounds round(s) of $((2 * seconds)) s"
if [ "$applied" -lt 10000 ]; then echo "fuzz: fewer than 10,000 sweeps"; exit 1; fi
echo "fuzz: decoders_fuzz, readers_fuzz and cutting_fuzz: 3 passed, 0 failed"
