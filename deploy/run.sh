#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The main job: installs and builds what is missing, then runs viscera as it is used: the
# simulation server on the bundled liver (liver2, 1,493 tetrahedra, constant-Q viscoelastic GPS
# at 1 kHz) and, as a separate process over Cyclone DDS, a scripted haptic client that presses a
# probe into the liver and then grasps and pulls it; then an instructor's console (another
# process) makes the liver twice as stiff while the server runs, and the probe presses again. All
# print live: the server its physics rate, step times, jitter, late ticks, missed slots and the force on the
# tools; the client the force it feels, the command-to-force round trip and the surface frames it
# receives; the console what the server did, and the server's health reports while the probe presses again.
# Then the liver takes the tissue viscera-lab fitted to the bundled titin data, and the lab's linear
# baseline for it, one after the other (viscera-control material --file); the probe presses each,
# and viscera-plot draws both force curves in out/titin-vs-linear.svg. Last, a scalpel cuts an
# incision along the organ's top and a probe presses on it (the cut is on the console, and in the
# recording, whose re-simulation reproduces it bit for bit).
# viscera-record records the whole session to out/demo.mcap (the last demo's, replaced); at the end the demo prints the
# recording's summary and re-runs the session on a fresh server in lockstep, bit for bit, and the
# Python package reads it into DataFrames (examples/python/analyse_session.py, out/demo-session.png).
# The instructor's console (viscera-console) runs beside it all: open the address it prints in a
# browser to watch the liver deform, the forces rise, and to pause, bookmark or take over.
#   SCENE=data/scenes/liver-12k.json ./deploy/run.sh    another scene
#   SCENE=patient ./deploy/run.sh                         a patient's liver, meshed first from the bundled CT label map (docs/MESHING.md)
#   DURATION=20 ./deploy/run.sh                           a longer press (seconds)
#   KEEP=1 ./deploy/run.sh                                leave the server and the console running after the demo (Ctrl-C ends them)
#   LISTEN=0.0.0.0:8080 ./deploy/run.sh                   the console reachable from other hosts (default: this one only)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# Only what the demo runs is installed and built (the tests are built by deploy/test.sh).
targets="viscera-server viscera-record viscera-console haptic-client viscera-control viscera-plot viscera-replay"
[ "${SCENE:-}" = patient ] && targets+=" viscera-mesh"
DEPS=demo TARGETS="$targets" "$root/deploy/build.sh" "$root/build"
mkdir -p "$root/out"
if [ "${SCENE:-}" = patient ]; then
  # The patient's liver with its gallbladder (a region of its own material), held where it touches
  # the vena cava (label 63) and where the CT's field of view cut it; about 12,000 tetrahedra.
  "$root/build/tools/viscera-mesh/viscera-mesh" "$root/data/label-maps/abdomen-totalsegmentator/example_seg.nii.gz" --organ 5 --organ-name liver \
    --region "4:gallbladder:$root/data/materials/gallbladder.json" --material "$root/data/materials/liver-viscoelastic.json" \
    --hold-touching 63 --hold-crop --tets 12000 --out "$root/out/patient-liver" --name patient-liver --replace 2>&1 | sed -u 's/^/[mesh] /'
  SCENE="$root/out/patient-liver/patient-liver.json"
fi
# The Python package is needed only at the end: it compiles while the session runs, on one core at
# the lowest priority (the physics runs at 1 kHz beside it), and the demo waits for it there.
CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=true nice -n 19 cmake --build "$root/build" -j 1 --target _viscera > "$root/out/python-build.log" 2>&1 &
python_build=$!
scene="${SCENE:-$root/data/scenes/liver.json}"
duration="${DURATION:-8}"
export CYCLONEDDS_URI="${CYCLONEDDS_URI:-file://$root/deploy/dds/loopback.xml}"
domain=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1])).get('domain_id', 0))" "$scene")
bin="$root/build"
recording="$root/out/demo.mcap"
"$bin/tools/viscera-record/viscera-record" --out "$recording" --replace --domain "$domain" --quiet > >(sed -u 's/^/[record] /') 2>&1 &
recorder=$!
"$bin/server/runtime/viscera-server" --scene "$scene" > >(sed -u 's/^/[server] /') 2>&1 &
server=$!
# The console's access token: made once, readable by this user only.
token="$root/out/console-token"
[ -s "$token" ] || (umask 077 && openssl rand -hex 16 > "$token")
"$bin/tools/viscera-console/viscera-console" --domain "$domain" --token-file "$token" --listen "${LISTEN:-127.0.0.1:8080}" --recordings "$root/out" \
  > >(sed -u 's/^/[console] /') 2>&1 &
console_pid=$!
# The console never logs its token; the demo, on this terminal, prints the address with it.
echo "[demo] the instructor's console: open http://${LISTEN:-127.0.0.1:8080}/?token=$(cat "$token")"
trap 'kill -INT "$server" "$recorder" "$console_pid" "$python_build" 2>/dev/null || true; wait "$server" "$recorder" "$console_pid" 2>/dev/null || true; sleep 0.2' EXIT
sleep 1  # the recorder discovers the server before the first command
echo "[demo] probe 1 presses 3 cm into the liver and comes back (${duration} s)"
"$bin/tools/haptic-client/haptic-client" --domain "$domain" --client-id 1 --instrument 1 --script press --depth 0.03 \
  --duration "$duration" --watch-mesh 2>&1 | sed -u 's/^/[haptic] /'
echo "[demo] grasper 3 closes its jaws on the liver, pulls it up 2 cm, lets go (6 s)"
"$bin/tools/haptic-client/haptic-client" --domain "$domain" --client-id 2 --instrument 3 --script grasp --depth 0 --pull 0.02 \
  --duration 6 2>&1 | sed -u 's/^/[haptic] /'
echo "[demo] an instructor's console doubles the liver's Young's modulus while the server runs"
"$bin/tools/viscera-control/viscera-control" material --youngs-modulus-pa 10000 --domain "$domain" 2>&1 | sed -u 's/^/[console] /'
echo "[demo] probe 1 presses 3 cm again: the stiffer liver pushes back harder (${duration} s); the console watches the server's health"
"$bin/tools/viscera-control/viscera-control" health --duration 3.5 --domain "$domain" 2>&1 | sed -u 's/^/[console] /' &
console=$!
"$bin/tools/haptic-client/haptic-client" --domain "$domain" --client-id 1 --instrument 1 --script press --depth 0.03 \
  --duration "$duration" 2>&1 | sed -u 's/^/[haptic] /'
wait "$console" || true
echo "[demo] the tissue viscera-lab fitted to the titin data set (docs/lab/titin) replaces the liver's, then the lab's linear baseline"
echo "[demo] for the same data; probe 1 presses 2 cm into each (6 s), and viscera-plot draws both force curves in one plot"
titin=1
for tissue in titin-fitted titin-linear; do
  # A finer organ may not step the fitted tissue's stiffening within a tick on this machine: the
  # server refuses it (one line says why) and the demo goes on without the comparison.
  if ! "$bin/tools/viscera-control/viscera-control" material --file "$root/data/materials/$tissue.json" --domain "$domain" \
      > "$root/out/material-$tissue.log" 2>&1; then
    head -1 "$root/out/material-$tissue.log" | sed 's/^/[console] /'
    echo "[demo] the server refused $tissue for this organ (above); the titin comparison is left out"
    titin=0
    break
  fi
  head -1 "$root/out/material-$tissue.log" | sed 's/^/[console] /'
  "$bin/tools/haptic-client/haptic-client" --domain "$domain" --client-id 1 --instrument 1 --script press --depth 0.02 --duration 6 \
    --report "$root/out/press-$tissue.json" --replace 2>&1 | sed -u 's/^/[haptic] /'
done
[ "$titin" = 0 ] || "$bin/tools/viscera-plot/viscera-plot" "$root/out/press-titin-fitted.json=titin as fitted (spectrum, stiffening)" \
  "$root/out/press-titin-linear.json=its linear baseline (Kelvin-Voigt)" --svg "$root/out/titin-vs-linear.svg" --replace \
  --title "The same 2 cm press on the liver's shape: titin as fitted against its linear baseline" 2>&1 | sed -u 's/^/[plot] /'
echo "[demo] scalpel 4 cuts a 6 cm incision 1.5 cm deep along the top of the organ (4 s; the console shows it open), then probe 2"
echo "[demo] presses 1 cm on the incision's line (3 s): the cut's lips part under it (docs/CUTTING.md)"
"$bin/tools/haptic-client/haptic-client" --domain "$domain" --client-id 3 --instrument 4 --script incise --depth 0.015 --length 0.06 \
  --duration 4 --watch-mesh 2>&1 | sed -u 's/^/[haptic] /'
"$bin/tools/haptic-client/haptic-client" --domain "$domain" --client-id 4 --instrument 2 --script press --depth 0.01 --duration 3 \
  --watch-mesh 2>&1 | sed -u 's/^/[haptic] /'
if [ -n "${KEEP:-}" ]; then
  echo "[demo] done; the server and the console keep running (KEEP=1): open the console's address above; Ctrl-C ends them"
  wait "$server" || true
fi
echo "[demo] done; the server, the console and the recorder stop"
kill -INT "$server" "$recorder" "$console_pid" 2>/dev/null; wait "$server" "$recorder" "$console_pid" || true
trap - EXIT
sleep 0.2
echo "[demo] the recording ($recording):"
"$bin/tools/viscera-record/viscera-record" info "$recording" --verify 2>&1 | sed -u 's/^/[record] /'
echo "[demo] the session re-run on a fresh server in lockstep, compared bit for bit with the recording"
"$bin/tools/viscera-replay/viscera-replay" resimulate "$recording" --report "$root/out/demo-resimulation.json" --replace --domain "$domain" 2>&1 \
  | sed -u 's/^/[replay] /' || echo "[demo] the re-simulation did not reproduce the session: see the first divergence above"
echo "[demo] the same recording in Python (numpy, pandas, matplotlib): examples/python/analyse_session.py"
wait "$python_build" || { echo "[demo] the Python package did not build: out/python-build.log"; tail -5 "$root/out/python-build.log"; }
python="$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' "$bin/CMakeCache.txt")"
PYTHONPATH="$bin/python" "${python:-python3}" "$root/examples/python/analyse_session.py" "$recording" --plot "$root/out/demo-session.png" 2>&1 \
  | sed -u 's/^/[python] /' || true
echo "[demo] the Python package (docs/PYTHON.md): PYTHONPATH=$bin/python ${python:-python3} -c 'import viscera'"
echo "[demo] replay it: $bin/tools/viscera-replay/viscera-replay play $recording"
