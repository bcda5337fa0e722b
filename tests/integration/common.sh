# SPDX-License-Identifier: Apache-2.0
# Shared by the integration tests: a scratch folder, the project's Cyclone configuration, a DDS
# domain of the test's own (parallel runs on one machine do not meet) and the liver scene with
# absolute paths. Sets: tmp, domain, scene. Source it after setting build and src.
tmp="$(mktemp -d)"
export CYCLONEDDS_URI="file://$src/deploy/dds/loopback.xml"
domain=$(( (RANDOM % 200) + 1 ))
scene="$tmp/scene.json"
sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$src/data/meshes/#; s#\"../materials/#\"$src/data/materials/#" \
  "$src/data/scenes/liver.json" > "$scene"
failures=0; passed=0; failed_names=
# A CI log keeps only the first lines of a failing test's output: what the script prints goes to a
# file, and show_output (in the script's EXIT trap, and by `finish`, its last command) prints the
# verdict and the failures' reasons first, then the whole output, then the verdict again.
# A test killed at its timeout prints only the line below: its output stays in that file.
echo "$(basename "$0" .sh): output in $tmp/output.log, printed when the script ends"
exec 3>&1 4>&2 > "$tmp/output.log" 2>&1
output_shown=
show_output() {
  [ -n "$output_shown" ] && return 0
  output_shown=1
  exec 1>&3 2>&4
  local name verdict
  name=$(basename "$0" .sh)
  verdict="$name: $passed passed, $failures failed${failed_names:+:$failed_names}"
  echo "$verdict"
  grep -E '^FAIL|Error:' "$tmp/output.log" | head -20 | sed 's/^/  /'
  echo "--- $name: the whole output"
  cat "$tmp/output.log"
  echo "$verdict"
}
# The script's last command: the output as above, and the exit status (0 when no check failed).
finish() { show_output; [ "$failures" -eq 0 ]; }
check() { if eval "$2"; then passed=$((passed+1)); else echo "FAIL $1"; failures=$((failures+1)); failed_names+=" [$1]"; fi; }
# A check written in Python, read from standard input (a here-document): counts one pass or one failure.
pycheck() { if python3 - "$@"; then passed=$((passed+1)); else echo "FAIL the Python check above"; failures=$((failures+1)); failed_names+=" [a Python check]"; fi; }
# The FAIL lines a script wrote to FILE, joined on one line (at most 400 characters), for a check's
# name: the script's own reasons reach the summary line.
fails_in() { grep '^FAIL' "$1" 2>/dev/null | tr '\n' ' ' | cut -c1-400; }
# Waits until PATTERN appears in FILE (at most TENTHS tenths of a second, default 100); says so if it never does.
wait_for() {  # PATTERN FILE [TENTHS]
  for _ in $(seq "${3:-100}"); do grep -q "$1" "$2" && return 0; sleep 0.1; done
  echo "FAIL '$1' never appeared in $2:"; cat "$2"; return 1
}
