#!/usr/bin/env bash
# clang-tidy with the project's .clang-tidy (its findings are errors) on the C++ sources changed in
# the last COMMITS commits (default 3, the work just landed; "all" for every source, about 15 minutes on two cores).
# Usage: clang_tidy.sh BUILD_DIR SOURCE_DIR [COMMITS|all]
set -u
build="$1"; src="$2"; range="${3:-3}"
cd "$src" || exit 2
[ -f "$build/compile_commands.json" ] || { echo "clang_tidy: $build/compile_commands.json missing (configure first)"; exit 2; }
if [ "$range" = all ] || ! git rev-parse -q --verify "HEAD~$range" > /dev/null; then
  files=$(git ls-files '*.cpp' | grep -v '^tests/fuzz/')
else
  files=$(git diff --name-only --diff-filter=d "HEAD~$range" -- '*.cpp' | grep -v '^tests/fuzz/')
fi
[ -z "$files" ] && { echo "clang_tidy: no C++ source changed"; exit 0; }
count=$(echo "$files" | wc -l)
echo "clang_tidy: $count sources"
if echo "$files" | xargs -P "$(nproc)" -n 4 clang-tidy -p "$build" --quiet 2>/dev/null | grep -E "(warning|error):"; then
  echo "clang_tidy: findings above (fix them, or justify each with a NOLINT comment that says why)"
  exit 1
fi
echo "clang_tidy: $count sources, no findings"
