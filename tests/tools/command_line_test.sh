#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The programs' command lines: --help works, bad arguments and bad files give one clear line on
# stderr and a non-zero exit. PART: "programs" (every program's flags and files), "lab-analysis"
# (viscera-lab analyze and predict on the titin data, and hand-edited model files: a minute under
# the sanitizers, which deploy/test.sh leaves to the Release run as it does the lab's other long
# analyses), or "all" (the default).
# Usage: command_line_test.sh BUILD_DIR SOURCE_DIR [PART]
set -u
build="$1"; src="$2"; part="${3:-all}"
case "$part" in all | programs | lab-analysis) ;; *) echo "command_line_test: PART '$part' is not all, programs or lab-analysis" >&2; exit 2 ;; esac
sim="$build/tools/viscera-sim/viscera-sim"; fig="$build/tools/viscera-figure2/viscera-figure2"; lab="$build/tools/viscera-lab/viscera-lab"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
failures=0; passed=0
expect() {  # expect NAME EXIT_CODE PATTERN -- command...
  local name="$1" code="$2" pattern="$3"; shift 4
  "$@" >"$tmp/out" 2>"$tmp/err"; local rc=$?
  local lines; lines=$(wc -l <"$tmp/err")
  if [ "$rc" -ne "$code" ] || ! grep -q -- "$pattern" "$tmp/err" "$tmp/out" || { [ "$code" -ne 0 ] && [ "$lines" -ne 1 ]; }; then
    echo "FAIL $name: exit $rc (want $code), stderr:"; cat "$tmp/err"; failures=$((failures+1))
  else
    passed=$((passed+1))
  fi
}
if [ "$part" != lab-analysis ]; then
printf '$NOD\n1\n1 0 0 0\n$ENDNOD\n$ELM\n1\n1 4 1 1 4 1 1 1 2\n$ENDELM\n' >"$tmp/bad.msh"
echo '{"density_kg_m3": 1000, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 5000, "poisson_ratio": 0.7}}' >"$tmp/bad.json"
expect sim-help 0 "Usage: viscera-sim" -- "$sim" --help
expect fig-help 0 "Usage: viscera-figure2" -- "$fig" --help
plot="$build/tools/viscera-plot/viscera-plot"
expect plot-help 0 "Usage: viscera-plot" -- "$plot" --help
expect plot-nothing 2 "no REPORT.json to plot" -- "$plot" --svg "$tmp/p.svg"
echo '{"samples": [{"t_s": 0, "tip_z_m": 0.01, "force_n": [0, 0, 1], "in_contact": true}]}' > "$tmp/report.json"
expect plot-over-input 2 "which this program reads" -- "$plot" "$tmp/report.json" --svg "$tmp/report.json"
expect plot-axis 2 "--x: 'speed' is not depth or time" -- "$plot" "$tmp/report.json" --svg "$tmp/p.svg" --x speed
echo '{"samples": [{"t_s": 0, "tip_z_m": 0.01, "force_n": [0, 1], "in_contact": true}]}' > "$tmp/short.json"
expect plot-bad-sample 2 "short.json: samples.0..force_n: .0,1. must be 3 numbers" -- "$plot" "$tmp/short.json" --svg "$tmp/p.svg"
echo '{"samples": [{"t_s": 0, "tip_z_m": 0.01, "force_n": [0, 0, 0], "in_contact": false}]}' > "$tmp/apart.json"
expect plot-no-contact 2 "apart.json: samples: the tool never touched the organ" -- "$plot" "$tmp/apart.json" --svg "$tmp/p.svg"
expect sim-unknown 2 "unknown option --frobnicate" -- "$sim" --frobnicate 3
expect sim-missing-mesh 2 "mesh is required" -- "$sim"
expect sim-no-file 2 "nowhere.msh: cannot open file" -- "$sim" --mesh "$tmp/nowhere.msh"
expect sim-bad-mesh 2 "bad.msh" -- "$sim" --mesh "$tmp/bad.msh"
expect sim-bad-number 2 "'abc' is not a number" -- "$sim" --mesh "$src/data/meshes/liver.msh" --scale abc
expect sim-bad-material 2 "bad.json: elasticity.poisson_ratio: 0.7 is outside" -- "$sim" --mesh "$src/data/meshes/liver.msh" --material "$tmp/bad.json"
expect sim-bad-model 2 "'fem' is not one of" -- "$sim" --mesh "$src/data/meshes/liver.msh" --model fem
expect sim-bad-slab 2 "fix-slab: axis 'w'" -- "$sim" --mesh "$src/data/meshes/liver.msh" --fix-slab w,max,0.1
expect sim-runs 0 "wrote" -- "$sim" --mesh "$src/data/meshes/liver.msh" --scale 0.035 --fix-slab z,max,0.2 --duration 0.05 --out "$tmp/frames"
expect fig-bad-mechanisms 2 "mechanisms" -- "$fig" --mechanisms 9 --csv "$tmp/f.csv" --svg "$tmp/f.svg"
server="$build/server/runtime/viscera-server"; hc="$build/tools/haptic-client/haptic-client"
echo '{"organ": {"mesh": "x.msh"}}' >"$tmp/bad_scene.json"
expect server-help 0 "Usage: viscera-server" -- "$server" --help
expect server-no-scene 2 "viscera-server: --scene is required" -- "$server"
expect server-bad-scene 2 "bad_scene.json: organ.material: missing" -- "$server" --scene "$tmp/bad_scene.json"
echo '{"organ": {"mesh": "x.msh", "material": "m.json", "added_mass_fraction": 2}, "instruments": [{"id": 1}]}' >"$tmp/heavy_scene.json"
expect server-bad-mass-scaling 2 "heavy_scene.json: organ.added_mass_fraction: 2 is outside" -- "$server" --scene "$tmp/heavy_scene.json"
echo '{"organ": {"mesh": "x.msh", "material": "m.json", "physics_threads": 1.5}, "instruments": [{"id": 1}]}' >"$tmp/threads_scene.json"
expect server-bad-threads 2 "threads_scene.json: organ.physics_threads: 1.5 is not a whole number" -- "$server" --scene "$tmp/threads_scene.json"
echo '{"organ": {"mesh": "x.msh", "material": "m.json", "contact_damping_s_per_m": -1}, "instruments": [{"id": 1}]}' >"$tmp/damping_scene.json"
expect server-bad-damping 2 "damping_scene.json: organ.contact_damping_s_per_m: -1 is outside" -- "$server" --scene "$tmp/damping_scene.json"
echo '{"organ": {"mesh": "x.msh", "material": "m.json", "strain_radius_m": 2}, "instruments": [{"id": 1}]}' >"$tmp/radius_scene.json"
expect server-bad-strain-radius 2 "radius_scene.json: organ.strain_radius_m: 2 is outside" -- "$server" --scene "$tmp/radius_scene.json"
echo '{"physics_threads": 2, "organ": {"mesh": "x.msh", "material": "m.json"}, "instruments": [{"id": 1}]}' >"$tmp/misplaced_scene.json"
expect server-unknown-field 2 "misplaced_scene.json: physics_threads: unknown field (known here: name, " -- "$server" --scene "$tmp/misplaced_scene.json"
echo '{"organ": {"mesh": "x.msh", "material": "m.json"}, "instruments": [{"id": 1, "tip_radius": 0.01}]}' >"$tmp/typo_scene.json"
expect server-misspelt-field 2 "typo_scene.json: instruments\[0\].tip_radius: unknown field" -- "$server" --scene "$tmp/typo_scene.json"
expect server-bad-duration 2 "viscera-server: --duration: 'soon' is not a number" -- "$server" --scene x --duration soon
expect server-bad-scene-dir 2 "--scene-dir: '/nonexistent' is not a directory" -- "$server" --scene x --scene-dir /nonexistent
expect server-negative-duration 2 "viscera-server: --duration: -1 is outside" -- "$server" --scene x --duration -1
expect server-unknown 2 "viscera-server: unknown option --sceen" -- "$server" --sceen x
expect hc-help 0 "Usage: haptic-client" -- "$hc" --help
expect hc-bad-rate 2 "--rate: 0 is outside" -- "$hc" --rate 0
printf 'time_s,x_m,y_m,z_m\n0,0,0,0.01\n0.5,0,0,abc\n' >"$tmp/t1.csv"
printf 'time_s,x_m,y_m,z_m\n0,0,0,0.01\n0.5,0,0,0\n0.5,0,0,-0.01\n' >"$tmp/t2.csv"
printf 'time_s,x_m,y_m\n0,0,0\n' >"$tmp/t3.csv"
printf 'time_s,x_m,y_m,z_m\n0,0,0,0\n1,0,0,-20\n' >"$tmp/t4.csv"
printf 'time_s,x_m,y_m,z_m,jaw_rad\n0,0,0,0,0.5\n1,0,0,0,7\n' >"$tmp/t5.csv"
expect hc-traj-missing 2 "nowhere.csv: no such file" -- "$hc" --trajectory "$tmp/nowhere.csv"
expect hc-traj-number 2 "t1.csv:3: column z_m: 'abc' is not a number" -- "$hc" --trajectory "$tmp/t1.csv"
expect hc-traj-time 2 "t2.csv:4: column time_s" -- "$hc" --trajectory "$tmp/t2.csv"
expect hc-traj-header 2 "t3.csv:1: column z_m: missing from the header" -- "$hc" --trajectory "$tmp/t3.csv"
expect hc-traj-units 2 "t4.csv:3: column z_m: .* are the units metres" -- "$hc" --trajectory "$tmp/t4.csv"
expect hc-traj-jaw 2 "t5.csv:3: column jaw_rad" -- "$hc" --trajectory "$tmp/t5.csv"
expect control-help 0 "Usage: viscera-control" -- "$build/tools/viscera-control/viscera-control" --help
expect control-bad-action 2 "ACTION 'explode' is not pause" -- "$build/tools/viscera-control/viscera-control" explode
expect control-two-actions 2 "unexpected argument 'resume'" -- "$build/tools/viscera-control/viscera-control" pause resume
expect control-annotate-no-text 2 "annotate needs its argument" -- "$build/tools/viscera-control/viscera-control" annotate
expect control-load-path 2 "SCENE '../x' is not a scene name" -- "$build/tools/viscera-control/viscera-control" load ../x
expect control-load-no-name 2 "load needs its argument" -- "$build/tools/viscera-control/viscera-control" load
expect control-rate-range 2 "rate: 5 is outside \[10, 10000\] Hz" -- "$build/tools/viscera-control/viscera-control" rate 5
expect control-material-empty 2 "material needs --file or at least one of" -- "$build/tools/viscera-control/viscera-control" material
expect control-material-file-dir 2 "--file: $tmp: is a directory" -- "$build/tools/viscera-control/viscera-control" material --file "$tmp"
printf '{"name": "x",\n "density_kg_m3": }' > "$tmp/half.json"
expect control-material-file-json 2 "--file: $tmp/half.json:2: JSON: parse error" -- "$build/tools/viscera-control/viscera-control" material --file "$tmp/half.json"
head -c 70000 /dev/zero | tr '\0' ' ' > "$tmp/huge.json"
expect control-material-file-size 2 "huge.json: is 70000 bytes, more than the 65536" -- "$build/tools/viscera-control/viscera-control" material --file "$tmp/huge.json"
expect control-material-file-elsewhere 2 "material flags are for the material action" -- "$build/tools/viscera-control/viscera-control" pause --file "$tmp/half.json"
expect control-material-flag-elsewhere 2 "material flags are for the material action" -- "$build/tools/viscera-control/viscera-control" pause --shear-q 3
expect control-material-range 2 "poisson-ratio" -- "$build/tools/viscera-control/viscera-control" material --poisson-ratio 0.7
expect control-health-argument 2 "unexpected argument 'now'" -- "$build/tools/viscera-control/viscera-control" health now
expect control-health-duration 2 "duration" -- "$build/tools/viscera-control/viscera-control" health --duration 0
expect hc-bad-frame 2 "--frame: 'world'" -- "$hc" --frame world
expect bench-thread-cpu-help 0 "Usage: .*thread_cpu.sh" -- "$src/bench/thread_cpu.sh" --help
expect bench-thread-cpu-scene 2 "no scene 'nowhere'" -- "$src/bench/thread_cpu.sh" nowhere
expect bench-thread-cpu-window 2 "SECONDS: '0'" -- "$src/bench/thread_cpu.sh" liver 0
expect bench-palpation-help 0 "Usage: .*palpation.sh" -- "$src/bench/palpation.sh" --help
expect bench-palpation-seeds 2 "SEEDS: 'three' is not a whole number" -- env SEEDS=three "$src/bench/palpation.sh"
mesh="$build/tools/viscera-mesh/viscera-mesh"; labels="$src/data/label-maps/abdomen-totalsegmentator/example_seg.nii.gz"
expect mesh-help 0 "Usage: viscera-mesh LABELMAP" -- "$mesh" --help
expect mesh-no-organ 2 "--organ: which labels" -- "$mesh" "$labels" --material "$src/data/materials/liver.json" --out "$tmp/m"
expect mesh-bad-label 2 "--organ: 'liver' is not a label" -- "$mesh" "$labels" --organ liver --material "$src/data/materials/liver.json" --out "$tmp/m"
expect mesh-bad-region 2 "--region: '4:gallbladder' is not LABEL:NAME:MATERIAL" -- "$mesh" "$labels" --organ 5 --region 4:gallbladder --material x --out "$tmp/m"
expect mesh-region-name 2 "--region: the name '../up'" -- "$mesh" "$labels" --organ 5 --region 4:../up:x.json --material x --out "$tmp/m"
expect mesh-both-sizes 2 "--edge-mm and --tets" -- "$mesh" "$labels" --organ 5 --tets 5000 --edge-mm 5 --material x --out "$tmp/m"
expect mesh-frame 2 "--frame: 'world'" -- "$mesh" "$labels" --organ 5 --frame world --material x --out "$tmp/m"
expect mesh-nodule 2 "--nodule: '90:x.json'" -- "$mesh" "$labels" --organ 5 --nodule 90:x.json --material x --out "$tmp/m"
expect mesh-no-material 2 "nowhere.json: no such file" -- "$mesh" "$labels" --organ 5 --material "$tmp/nowhere.json" --out "$tmp/m"
expect bench-patient-help 0 "Usage: .*patient_organ.sh" -- "$src/bench/patient_organ.sh" --help
expect bench-patient-runs 2 "RUNS: 'x'" -- env RUNS=x "$src/bench/patient_organ.sh"
expect lab-help 0 "Usage: viscera-lab analyze" -- "$lab" --help
expect lab-no-command 2 "missing command" -- "$lab" --out "$tmp/o"
expect lab-no-out 2 "--out OUT_DIR is required" -- "$lab" analyze "$src/data/titin-passive-muscle"
expect lab-no-dataset 2 "nowhere/dataset.json: cannot open file" -- "$lab" analyze "$tmp/nowhere" --out "$tmp/o"
# import: a machine's export (mN, mm, semicolons) into a data set that analyze then reads.
printf 'Time;Force;Disp\n0;0;0\n1;30;0.5\n2;60;1\n3;58;1\n4;57;1\n' > "$tmp/export.txt"
import=(--length-m 0.01 --width-m 0.003 --thickness-m 0.002 --force Force:mN --displacement Disp:mm --time Time)
expect lab-import 0 "export.csv: 5 rows, 4 s, strain 0 to 0.1, stress 0 to 1e+04 Pa" -- "$lab" import "$tmp/export.txt" --out "$tmp/imported" "${import[@]}"
# A preload of 12 mN held for two rows and a displacement zero 0.4 mm away, taken off.
printf 'Time;Force;Disp\n0;12;0.4\n1;12;0.4\n2;42;0.9\n3;72;1.4\n4;70;1.4\n' > "$tmp/preloaded.txt"
expect lab-import-tare 0 "preloaded.csv: 5 rows, 4 s, strain 0 to 0.1, stress 0 to 1e+04 Pa" -- "$lab" import "$tmp/preloaded.txt" --out "$tmp/tared" "${import[@]}" --tare --zero-displacement
expect lab-import-again 2 "imported/dataset.json: already exists" -- "$lab" import "$tmp/export.txt" --out "$tmp/imported" "${import[@]}"
# Decimal commas in a comma-separated export: the row has more cells than the header has columns.
printf 'Time,Force,Disp\n0,0,0\n1,30,0,5\n' > "$tmp/decimal-comma.txt"
expect lab-import-decimal-comma 2 "decimal-comma.txt:3: cell 4: '5' lies beyond the header's 3 columns" -- "$lab" import "$tmp/decimal-comma.txt" --out "$tmp/i12" "${import[@]}"
expect lab-import-unit 2 "--force: unit 'lbf' is not a force unit" -- "$lab" import "$tmp/export.txt" --out "$tmp/i2" "${import[@]}" --force Force:lbf
mkdir -p "$tmp/in" && cp "$tmp/export.txt" "$tmp/in/export.csv"
expect lab-import-over-input 2 "is the same file as" -- "$lab" import "$tmp/in/export.csv" --out "$tmp/in" "${import[@]}"
expect lab-import-mm-as-m 2 "strain: 50 cannot be right" -- "$lab" import "$tmp/export.txt" --out "$tmp/i4" "${import[@]}" --displacement Disp:m
expect lab-import-no-geometry 2 "import needs --length-m" -- "$lab" import "$tmp/export.txt" --out "$tmp/i3" --force Force --displacement Disp
# A compression between platens exported with compression positive: negated, and declared.
expect lab-import-platens 0 "export.csv: 5 rows, 4 s, strain -0.1 to 0, stress -1e+04 to 0 Pa" -- "$lab" import "$tmp/export.txt" --out "$tmp/platens" "${import[@]}" --platens --compression-positive
expect lab-import-platens-declared 0 '"contact": "platens"' -- cat "$tmp/platens/dataset.json"
expect lab-import-history-default 0 '"history": "carried"' -- cat "$tmp/platens/dataset.json"
expect lab-import-history-reset 0 "export.csv: 5 rows" -- "$lab" import "$tmp/export.txt" --out "$tmp/reset" "${import[@]}" --history reset
expect lab-import-history-reset-declared 0 '"history": "reset"' -- cat "$tmp/reset/dataset.json"
expect lab-import-history-bad 2 "--history: 'sometimes' is not carried or reset" -- "$lab" import "$tmp/export.txt" --out "$tmp/i13" "${import[@]}" --history sometimes
# Declared between platens but stretched (the sign not flipped): the file, the row and the strain.
expect lab-import-platens-stretch 2 "export.txt:3: Disp: 0.0005 m is a stretch" -- "$lab" import "$tmp/export.txt" --out "$tmp/i5" "${import[@]}" --platens
# A table of specimens: each export converted with its own length; mistakes named by table, row and column.
printf 'file,length_m\nexport.txt,0.02\n' > "$tmp/specimens.csv"
expect lab-import-table 0 "export.csv: 5 rows, 4 s, strain 0 to 0.05," -- "$lab" import "$tmp/export.txt" --out "$tmp/tabled" "${import[@]}" --specimens "$tmp/specimens.csv"
printf 'file,length_mm\nexport.txt,20\n' > "$tmp/specimens-mm.csv"
expect lab-import-table-column 2 "specimens-mm.csv:1: length_mm: unknown column" -- "$lab" import "$tmp/export.txt" --out "$tmp/i6" "${import[@]}" --specimens "$tmp/specimens-mm.csv"
printf 'file,thickness_m\nexport.txt,-0.002\n' > "$tmp/specimens-neg.csv"
expect lab-import-table-value 2 "specimens-neg.csv:2: thickness_m: -0.002 is outside (0, 10]" -- "$lab" import "$tmp/export.txt" --out "$tmp/i7" "${import[@]}" --specimens "$tmp/specimens-neg.csv"
printf 'file,length_m\nexport.txt,0,02\n' > "$tmp/specimens-comma.csv"
expect lab-import-table-extra-cell 2 "specimens-comma.csv:2: cell 3: '02' lies beyond the header's 2 columns" -- "$lab" import "$tmp/export.txt" --out "$tmp/i9" "${import[@]}" --specimens "$tmp/specimens-comma.csv"
printf 'file,length_m,length_m\nexport.txt,0.02,0.03\n' > "$tmp/specimens-twice.csv"
expect lab-import-table-column-twice 2 "specimens-twice.csv:1: length_m: named twice in the header" -- "$lab" import "$tmp/export.txt" --out "$tmp/i10" "${import[@]}" --specimens "$tmp/specimens-twice.csv"
printf 'file,,length_m\nexport.txt,,0.02\n' > "$tmp/specimens-unnamed.csv"
expect lab-import-table-unnamed 2 "specimens-unnamed.csv:1: column 2: has no name" -- "$lab" import "$tmp/export.txt" --out "$tmp/i11" "${import[@]}" --specimens "$tmp/specimens-unnamed.csv"
printf 'file,length_m,,\nexport.txt,0.02,,\n' > "$tmp/specimens-trailing.csv"
expect lab-import-table-trailing 0 "export.csv: 5 rows, 4 s, strain 0 to 0.05," -- "$lab" import "$tmp/export.txt" --out "$tmp/tabled2" "${import[@]}" --specimens "$tmp/specimens-trailing.csv"
printf 'file,length_m\nexport.txt,0.02\nother.txt,0.02\n' > "$tmp/specimens-other.csv"
expect lab-import-table-other 2 "--specimens: the table names 'other.txt', which is not one of the exports" -- "$lab" import "$tmp/export.txt" --out "$tmp/i8" "${import[@]}" --specimens "$tmp/specimens-other.csv"
mkdir -p "$tmp/glued" && cp "$tmp/imported/export.csv" "$tmp/glued/" && python3 -c "import json; j=json.load(open('$tmp/imported/dataset.json')); j['contact']='glued'; json.dump(j, open('$tmp/glued/dataset.json','w'))"
expect lab-contact-unknown 2 "dataset.json: contact: 'glued' is not one of bonded | platens" -- "$lab" analyze "$tmp/glued" --out "$tmp/o"
fi
if [ "$part" != programs ]; then
expect lab-analyze 0 "causes (confirmed): broadband_relaxation strain_stiffening" -- "$lab" analyze "$src/data/titin-passive-muscle" --out "$tmp/titin" --quiet
cp "$tmp/out" "$tmp/lab-analyze.out"
expect lab-predict 0 "wrote" -- "$lab" predict "$tmp/titin/model.json" "$src/data/titin-passive-muscle" --out "$tmp/predicted"
# A model file edited by hand: each mistake named by file and field.
model_case() {  # model_case NAME PATTERN PYTHON-EDIT
  python3 -c "import json; m=json.load(open('$tmp/titin/model.json')); $3; json.dump(m, open('$tmp/$1.json', 'w'))"
  expect "lab-model-$1" 2 "$2" -- "$lab" predict "$tmp/$1.json" "$src/data/titin-passive-muscle" --out "$tmp/p-$1"
}
model_case misspelt "misspelt.json: modulus: unknown field" "m['modulus'] = m.pop('modulus_pa')"
model_case negative "negative.json: modulus_pa: -5 is outside" "m['modulus_pa'] = -5"
model_case relaxation "relaxation.json: relaxation_time_s\[1\]: 0 is outside" "m['relaxation_time_s'][1] = 0"
model_case text "text.json: viscosity_pa_s: \"a lot\" is not a number" "m['viscosity_pa_s'] = 'a lot'"
model_case softening "softening.json: softening_d: 1.5 is outside" "m['mechanisms'].append('first_load_softening'); m['softening_d'] = 1.5"
grep -q '"rms_pa"' "$tmp/predicted/report.json" || { echo "FAIL lab-predict: no rms_pa"; failures=$((failures+1)); }
grep -q "^adequacy: explained" "$tmp/lab-analyze.out" ||
  { echo "FAIL lab-analyze: no 'adequacy: explained' line"; failures=$((failures+1)); }
for key in baseline.model baseline.heldout_rms_pa causes final.model final.heldout_rms_pa gain adequacy.explained adequacy.residual_to_noise \
  adequacy.findings parameters.method parameters.parameters; do
  python3 -c "import json,sys; r=json.load(open('$tmp/titin/report.json')); v=r
for k in '$key'.split('.'): v=v[k]" || { echo "FAIL report.json lacks $key"; failures=$((failures+1)); }
done
fi
echo "command_line_test: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
