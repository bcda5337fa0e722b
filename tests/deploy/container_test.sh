#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The runtime image, checked quickly: the programs this build has just made, installed (cmake
# --install) into an image on the runtime-base stage of deploy/Dockerfile (Debian 12 with only the
# programs' run-time packages, a user of their own), start there and serve clients outside it: the
# server runs in a container on the host's network, a haptic client and a recorder on the host claim,
# press and record over loopback, and the server stops cleanly when podman stops the container.
# The Debian 12 base is made once from Debian's archive (mmdebstrap) and kept in podman's store, as
# is the runtime-base stage; the whole recipe, build stage included, is in docs/DEPLOY.md. Where
# podman cannot run, the test says so by name, with the reason, and skips.
# Usage: container_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$(cd "$2" && pwd)"
. "$src/tests/integration/common.sh"
name="viscera-test-$$"
trap 'podman rm -f "$name" >/dev/null 2>&1 || true; podman rmi -f "localhost/$name" >/dev/null 2>&1 || true; show_output; rm -rf "$tmp"' EXIT
# A skip is exit 77, which ctest reports as "Skipped" (SKIP_RETURN_CODE), with this line.
skip() { echo "container_test: SKIPPED (the runtime image under podman): $*"; exit 77; }
# Podman's defaults that this machine type needs (docs/DEPLOY.md): runc (crun refuses hybrid
# cgroups) and ulimits within the sandbox's hard limits.
limits=(--ulimit nofile=20000:20000 --ulimit nproc=4096:4096)
command -v podman >/dev/null || skip "podman is not installed (deploy/install-deps.sh installs podman, runc and mmdebstrap)"
base=localhost/viscera-debian-base:12
if ! podman image exists "$base"; then
  command -v mmdebstrap >/dev/null || skip "mmdebstrap is not installed, and podman has no $base"
  echo "container_test: making $base from Debian's archive (mmdebstrap, once)"
  mmdebstrap --variant=minbase --quiet bookworm "$tmp/base.tar" > "$tmp/mmdebstrap.log" 2>&1 \
    || skip "mmdebstrap could not make a Debian 12 base: $(tail -2 "$tmp/mmdebstrap.log" | tr '\n' ' ')"
  podman import "$tmp/base.tar" "$base" > /dev/null 2>&1 || skip "podman could not import the base image"
  rm -f "$tmp/base.tar"
fi
podman run --runtime runc --rm "${limits[@]}" --network host "$base" true > "$tmp/podman-run.log" 2>&1 \
  || skip "podman cannot run a container here: $(tail -2 "$tmp/podman-run.log" | tr '\n' ' ')"
t0=$SECONDS
podman build --runtime runc "${limits[@]}" --network host --build-arg "BASE=$base" --target runtime-base -t localhost/viscera-runtime-base \
  -f "$src/deploy/Dockerfile" "$src" > "$tmp/build-base.log" 2>&1
rc_base=$?
check "the runtime-base stage of deploy/Dockerfile builds (rc $rc_base; $((SECONDS - t0)) s)" "[ $rc_base -eq 0 ]"
if [ $rc_base -ne 0 ]; then tail -20 "$tmp/build-base.log"; finish; exit; fi
# The programs of this build, installed as the image's build stage installs them.
cmake --install "$build" --prefix "$tmp/image/opt/viscera" > "$tmp/install.log" 2>&1
printf 'FROM localhost/viscera-runtime-base\nCOPY opt/viscera /opt/viscera\n' > "$tmp/image/Containerfile"
podman build --runtime runc "${limits[@]}" -t "localhost/$name" "$tmp/image" > "$tmp/build.log" 2>&1
rc_build=$?
check "the image of this build's programs builds (rc $rc_build)" "[ $rc_build -eq 0 ]"
if [ $rc_build -ne 0 ]; then tail -20 "$tmp/build.log"; finish; exit; fi
echo "image: $(podman image inspect --format '{{.Size}}' "localhost/$name" | awk '{printf "%.0f MB", $1 / 1e6}')"

started=$(date +%s.%N)
podman run --runtime runc "${limits[@]}" --network host --name "$name" -d \
  -e CYCLONEDDS_URI=file:///opt/viscera/share/viscera/dds/loopback.xml "localhost/$name" \
  viscera-server --scene /opt/viscera/share/viscera/data/scenes/liver.json --domain "$domain" > /dev/null
for _ in $(seq 200); do podman logs "$name" 2>&1 | grep -q "scene liver" && break; sleep 0.05; done
ready=$(date +%s.%N)
echo "the server in the container was ready $(python3 -c "print(f'{$ready - $started:.2f}')") s after podman run"
export CYCLONEDDS_URI="file://$src/deploy/dds/loopback.xml"
"$build/tools/viscera-record/viscera-record" --out "$tmp/container.mcap" --domain "$domain" --quiet > "$tmp/record.log" 2>&1 &
recorder=$!
sleep 1
"$build/tools/haptic-client/haptic-client" --domain "$domain" --client-id 11 --duration 3 --depth 0.02 --quiet --report "$tmp/hc.json" > "$tmp/hc.log" 2>&1
rc_hc=$?
kill -INT "$recorder"; wait "$recorder"; rc_rec=$?
podman stop -t 10 "$name" > /dev/null 2>&1
rc_server=$(podman inspect --format '{{.State.ExitCode}}' "$name")
podman logs "$name" > "$tmp/server.log" 2>&1
cat "$tmp/hc.log" "$tmp/record.log"; tail -3 "$tmp/server.log"
check "a haptic client outside the container claimed and pressed (rc $rc_hc)" "[ $rc_hc -eq 0 ]"
check "the server in the container stopped cleanly on podman stop (exit $rc_server)" "[ '$rc_server' = 0 ] && grep -q 'stopped after' '$tmp/server.log'"
check "the recorder outside recorded the session (rc $rc_rec)" "[ $rc_rec -eq 0 ] && [ -s '$tmp/container.mcap' ]"
pycheck "$tmp/hc.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
pressed = [x for x in r["samples"] if x["in_contact"]]
assert len(pressed) > 500, f"only {len(pressed)} samples in contact"
up = sum(1 for x in pressed if x["force_n"][2] > 0) / len(pressed)
peak = max(x["force_n"][2] for x in pressed)
assert up > 0.95 and peak > 0.2, f"the organ in the container pushes back in {100 * up:.0f}% of the contact, peak {peak:.2f} N"
print(f"[ figure ] through the container: {len(pressed)} samples in contact, pushed back in {100 * up:.0f}%, peak {peak:.2f} N, "
      f"round trip p50 {r['round_trip_us']['p50']:.0f} us")
PY
finish
