# Shared by the integration tests: a scratch folder, the project's Cyclone configuration, a DDS
# domain of the test's own (parallel runs on one machine do not meet) and the liver scene with
# absolute paths. Sets: tmp, domain, scene. Source it after setting build and src.
tmp="$(mktemp -d)"
export CYCLONEDDS_URI="file://$src/deploy/cyclonedds.xml"
domain=$(( (RANDOM % 200) + 1 ))
scene="$tmp/scene.json"
sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$src/data/meshes/#; s#\"../materials/#\"$src/data/materials/#" \
  "$src/data/scenes/liver.json" > "$scene"
failures=0; passed=0
check() { if eval "$2"; then passed=$((passed+1)); else echo "FAIL $1"; failures=$((failures+1)); fi; }
# A check written in Python, read from standard input (a here-document): counts one pass or one failure.
pycheck() { if python3 - "$@"; then passed=$((passed+1)); else echo "FAIL the Python check above"; failures=$((failures+1)); fi; }
