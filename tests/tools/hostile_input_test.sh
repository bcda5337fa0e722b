#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# What a hostile new user hands the programs without a session running (issue 31): JSON nested
# 100,000 deep, numbers that are not whole, names that are paths or carry control bytes, an output
# that is one of the inputs under another name (a hard link, a symbolic link, the same folder),
# DDS wildcards as partitions. Each gets exit 2 and one line naming the file or flag, and no file
# that was read is changed. Usage: hostile_input_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$(cd "$2" && pwd)"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
export CYCLONEDDS_URI="file://$src/deploy/dds/loopback.xml"
server="$build/server/runtime/viscera-server"; trainer="$build/tools/viscera-trainer/viscera-trainer"
rec="$build/tools/viscera-record/viscera-record"; replay="$build/tools/viscera-replay/viscera-replay"
ctl="$build/tools/viscera-control/viscera-control"; lab="$build/tools/viscera-lab/viscera-lab"; hc="$build/tools/haptic-client/haptic-client"
failures=0; passed=0
fail() { echo "FAIL $*"; failures=$((failures+1)); }
expect() {  # NAME EXIT_CODE PATTERN -- command...: that exit, PATTERN on stderr or stdout, one stderr line when failing
  local name="$1" code="$2" pattern="$3"; shift 4
  timeout 20 "$@" >"$tmp/out" 2>"$tmp/err"; local rc=$?
  if [ "$rc" -ne "$code" ] || ! grep -qF -- "$pattern" "$tmp/err" "$tmp/out" || { [ "$code" -ne 0 ] && [ "$(wc -l <"$tmp/err")" -ne 1 ]; }; then
    fail "$name: exit $rc (want $code and '$pattern'), stderr:"; head -c 2000 "$tmp/err"; echo
  else
    passed=$((passed+1))
  fi
}
unchanged() {  # NAME FILE COPY: FILE still has COPY's bytes
  if cmp -s "$2" "$3"; then passed=$((passed+1)); else fail "$1: $2 was changed"; fi
}

# 1. Nesting: every JSON reader bounds it (a recursion per level crashed the server and the trainer).
python3 -c "print('['*100000 + ']'*100000)" > "$tmp/deep.json"
mkdir -p "$tmp/deep-ds"; cp "$tmp/deep.json" "$tmp/deep-ds/dataset.json"
expect server-deep-scene 2 "deep.json: JSON: objects and arrays nested deeper than 64 levels" -- "$server" --scene "$tmp/deep.json"
expect trainer-deep-exercise 2 "deep.json: JSON: objects and arrays nested deeper than 64 levels" -- "$trainer" run "$tmp/deep.json"
expect lab-deep-dataset 2 "dataset.json: JSON: objects and arrays nested deeper than 64 levels" -- "$lab" analyze "$tmp/deep-ds" --out "$tmp/lab-out"
# A deep file among the scenes a server offers: it starts, lists it as unreadable, and stops cleanly.
mkdir -p "$tmp/scenes"
sed "s/\"domain_id\": 0/\"domain_id\": $(( (RANDOM % 200) + 1 ))/; s#\"../meshes/#\"$src/data/meshes/#; s#\"../materials/#\"$src/data/materials/#" \
  "$src/data/scenes/liver.json" > "$tmp/scenes/liver.json"
cp "$tmp/deep.json" "$tmp/scenes/deep.json"
timeout 60 "$server" --scene "$tmp/scenes/liver.json" --duration 0.5 --quiet > "$tmp/server.out" 2>&1; rc=$?
[ $rc -eq 0 ] && passed=$((passed+1)) || { fail "server with a deep scene beside it: exit $rc"; cat "$tmp/server.out"; }

# 2. Whole numbers are whole: 1.5 is refused, never truncated to 1.
expect control-domain 2 "--domain: '1.5' is not a whole number" -- "$ctl" pause --domain 1.5
expect hc-client-id 2 "--client-id: '7.5' is not a whole number" -- "$hc" --client-id 7.5
expect trainer-seed 2 "--seed: '1.5' is not a whole number" -- "$trainer" run "$src/data/exercises/palpation.json" --seed 1.5
expect record-depth 2 "--depth: '2.5' is not a whole number" -- "$rec" --out "$tmp/x.mcap" --depth 2.5

# 3. Names that become paths: plain names only, refused at once (not after a 60 s wait).
exercise() {  # FILE NAME SCENE
  printf '{"name": %s, "kind": "force_drill", "scene": %s, "instrument": 1, "time_limit_s": 60}\n' "$2" "$3" > "$1"
}
exercise "$tmp/escape.json" '"../../escaped"' '"liver"'
exercise "$tmp/nul.json" '"a\u0000b"' '"liver"'
exercise "$tmp/tty.json" '"\u001b]0;owned\u0007"' '"liver"'
exercise "$tmp/path.json" '"drill"' '"../../etc/passwd"'
expect exercise-name-path 2 "escape.json: name: '../../escaped' is not a plain name" -- "$trainer" score "$tmp/escape.json" x.mcap --report-dir "$tmp/r"
expect exercise-name-nul 2 "nul.json: name: 'a\\x00b' holds a control character" -- "$trainer" score "$tmp/nul.json" x.mcap --report-dir "$tmp/r"
expect exercise-name-tty 2 "tty.json: name: '\\x1B]0;owned\\x07' holds a control character" -- "$trainer" score "$tmp/tty.json" x.mcap
expect exercise-scene-path 2 "path.json: scene: '../../etc/passwd' is not a scene" -- "$trainer" run "$tmp/path.json"
[ ! -e "$tmp/escaped.json" ] && [ ! -e "$tmp/../escaped.json" ] && passed=$((passed+1)) || fail "a report escaped its folder"

# Text from files that programs print holds no control characters (an escape sequence would reach
# the terminal of whoever runs viscera-control show or the server).
sed 's/"name": "liver"/"name": "\\u001b]0;owned\\u0007liver"/' "$tmp/scenes/liver.json" > "$tmp/tty-scene.json"
expect scene-name-escape 2 "tty-scene.json: name: '\x1B]0;owned\x07liver' holds a control character" -- "$server" --scene "$tmp/tty-scene.json"

# 4. No program writes over a file it reads, whatever the name it is given by.
mkdir -p "$tmp/ex"; cp "$src/data/exercises/force-drill.json" "$tmp/ex/force-drill.json"; cp "$tmp/ex/force-drill.json" "$tmp/drill.copy"
expect trainer-report-over-exercise 2 "is the same file as" -- "$trainer" score "$tmp/ex/force-drill.json" "$tmp/x.mcap" --report-dir "$tmp/ex"
unchanged trainer-report-over-exercise "$tmp/ex/force-drill.json" "$tmp/drill.copy"
head -c 700000 /dev/urandom > "$tmp/in.mcap"; cp "$tmp/in.mcap" "$tmp/in.copy"
ln "$tmp/in.mcap" "$tmp/hard.mcap"; ln -s "$tmp/in.mcap" "$tmp/soft.mcap"
expect recover-hard-link 2 "another file" -- "$rec" recover "$tmp/in.mcap" "$tmp/hard.mcap"
expect recover-symlink 2 "another file" -- "$rec" recover "$tmp/in.mcap" "$tmp/soft.mcap"
unchanged recover "$tmp/in.mcap" "$tmp/in.copy"
expect resimulate-report-over-recording 2 "is the same file as" -- "$replay" resimulate "$tmp/in.mcap" --report "$tmp/hard.mcap"
unchanged resimulate "$tmp/in.mcap" "$tmp/in.copy"
mkdir -p "$tmp/ds"; cp "$src/data/titin-passive-muscle/"*.csv "$src/data/titin-passive-muscle/dataset.json" "$tmp/ds/"; cp -r "$tmp/ds" "$tmp/ds.copy"
expect lab-out-is-data 2 "is the same file as" -- "$lab" analyze "$tmp/ds" --out "$tmp/ds/."
diff -r "$tmp/ds" "$tmp/ds.copy" >/dev/null && passed=$((passed+1)) || fail "the lab wrote into its data set"
printf 'time_s,x_m,y_m,z_m\n0,0,0,0.01\n1,0,0,0\n' > "$tmp/t.csv"; cp "$tmp/t.csv" "$tmp/t.copy"
expect hc-report-over-trajectory 2 "is the same file as" -- "$hc" --trajectory "$tmp/t.csv" --report "$tmp/t.csv"
unchanged hc-report "$tmp/t.csv" "$tmp/t.copy"
# A trajectory is a regular file of bounded size: a FIFO blocked the client for ever, /dev/zero
# grew it to 735 MB in 5 s.
mkfifo "$tmp/traj-fifo"
expect hc-trajectory-fifo 2 "traj-fifo: is not a regular file" -- "$hc" --trajectory "$tmp/traj-fifo"
expect hc-trajectory-zero 2 "/dev/zero: is not a regular file" -- "$hc" --trajectory /dev/zero

# 4b. Outputs are never written through a symbolic link planted at their path (a shared folder,
#     /tmp): the one way every program writes a file (common::write_file_text) refuses it, and the
#     link's target is left as it was.
echo mine > "$tmp/victim"; cp "$tmp/victim" "$tmp/victim.copy"
ln -s "$tmp/victim" "$tmp/planted.csv"; ln -s "$tmp/victim" "$tmp/planted.svg"
f2="$build/tools/viscera-figure2/viscera-figure2"
expect figure2-csv-link 2 "planted.csv: is a symbolic link" -- "$f2" --csv "$tmp/planted.csv" --svg "$tmp/f2.svg" --replace
expect figure2-svg-link 2 "planted.svg: is a symbolic link" -- "$f2" --csv "$tmp/f2.csv" --svg "$tmp/planted.svg" --replace
mkdir -p "$tmp/sim"; ln -s "$tmp/victim" "$tmp/sim/frames.pvd"
expect sim-pvd-link 2 "frames.pvd: is a symbolic link" -- "$build/tools/viscera-sim/viscera-sim" --mesh "$src/data/meshes/liver.msh" \
  --scale 0.01 --duration 0.01 --frame-rate 100 --out "$tmp/sim" --replace
unchanged outputs-through-links "$tmp/victim" "$tmp/victim.copy"
# An --out that cannot be a folder is refused before the analysis, in one line (it aborted after it).
touch "$tmp/plain-file"
expect lab-out-under-a-file 2 "--out: cannot create the folder" -- "$lab" analyze "$src/data/titin-passive-muscle" --out "$tmp/plain-file/sub"
expect lab-out-too-long 2 "--out: cannot create the folder" -- "$lab" analyze "$src/data/titin-passive-muscle" --out "$tmp/$(printf 'x%.0s' $(seq 300))"
expect figure2-csv-fifo 2 "is not a regular file" -- "$f2" --csv "$tmp/traj-fifo" --svg "$tmp/f2.svg" --replace

# 4c. An output that exists already is replaced only when asked (--replace), else refused in one
#     line before the work, naming the file and the flag; the file is left as it was.
plot="$build/tools/viscera-plot/viscera-plot"
echo earlier > "$tmp/earlier"; cp "$tmp/earlier" "$tmp/earlier.copy"
expect hc-report-exists 2 "earlier: --report: exists already: pass --replace" -- "$hc" --report "$tmp/earlier" --duration 1
expect plot-svg-exists 2 "earlier: --svg: exists already: pass --replace" -- "$plot" "$tmp/t.csv" --svg "$tmp/earlier"
expect figure2-exists 2 "earlier: --csv: exists already: pass --replace" -- "$f2" --csv "$tmp/earlier" --svg "$tmp/f2-new.svg"
expect resimulate-report-exists 2 "earlier: --report: exists already: pass --replace" -- "$replay" resimulate "$tmp/in.mcap" --report "$tmp/earlier"
unchanged existing-outputs "$tmp/earlier" "$tmp/earlier.copy"
mkdir -p "$tmp/full"; cp "$tmp/earlier" "$tmp/full/report.json"
expect lab-out-holds-files 2 "full: --out: holds files already: pass --replace" -- "$lab" analyze "$src/data/titin-passive-muscle" --out "$tmp/full"
expect sim-out-holds-files 2 "full: --out: holds files already: pass --replace" -- "$build/tools/viscera-sim/viscera-sim" --mesh "$src/data/meshes/liver.msh" --out "$tmp/full"
ln -s "$tmp/full" "$tmp/full-link"
expect lab-out-link 2 "full-link: --out: is a symbolic link: pass --replace" -- "$lab" analyze "$src/data/titin-passive-muscle" --out "$tmp/full-link"
unchanged existing-folder "$tmp/full/report.json" "$tmp/earlier.copy"
mkdir -p "$tmp/reports"; cp "$tmp/earlier" "$tmp/reports/force-drill.json"
expect trainer-report-exists 2 "force-drill.json: --report-dir: exists already: pass --replace" -- "$trainer" score "$tmp/ex/force-drill.json" "$tmp/x.mcap" --report-dir "$tmp/reports"

# 5. Station names are DDS partitions: a wildcard would reach other stations' live sessions, and
#    every program that joins a station checks the name before it touches the network.
expect replay-wildcard 2 "holds a DDS wildcard" -- "$replay" play "$tmp/in.mcap" --station '*' --no-keys
expect replay-wildcard-q 2 "holds a DDS wildcard" -- "$replay" play "$tmp/in.mcap" --station 'viscera-?eplay' --no-keys
expect server-wildcard 2 "holds a DDS wildcard" -- "$server" --scene "$tmp/scenes/liver.json" --station '*'
expect hc-wildcard 2 "--station: '*' holds a DDS wildcard" -- "$hc" --station '*'
expect trainer-wildcard 2 "--station: 'bay?' holds a DDS wildcard" -- "$trainer" run "$src/data/exercises/palpation.json" --station 'bay?'
expect record-space 2 "--station: 'bay 1' holds a character other than" -- "$rec" --out "$tmp/s.mcap" --station 'bay 1'
expect control-long 2 "is longer than 64 characters" -- "$ctl" show --station "$(printf 'b%.0s' $(seq 65))"
openssl rand -hex 16 > "$tmp/token"; chmod 600 "$tmp/token"
expect console-wildcard 2 "--stations: 'b*' holds a DDS wildcard" -- "$build/tools/viscera-console/viscera-console" --stations 'bay-1,b*' --token-file "$tmp/token"
# The console's TLS files: a device, a folder, a FIFO are refused at once, never read without end.
mkfifo "$tmp/tls-fifo"
for f in /dev/zero "$tmp" "$tmp/tls-fifo"; do
  expect "console-tls-key-$(basename "$f")" 2 "$f: " -- "$build/tools/viscera-console/viscera-console" --token-file "$tmp/token" --tls-cert "$f" --tls-key "$f"
done
expect server-slash 2 "--station: 'a/b' holds a character other than" -- "$server" --scene "$tmp/scenes/liver.json" --station 'a/b'

echo "hostile_input_test: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
