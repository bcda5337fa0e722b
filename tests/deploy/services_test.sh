#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The services as installed (deploy/install-services.sh): programs, data, console page and DDS
# configurations under a scratch prefix, the systemd units under a scratch folder, checked by
# systemd-analyze verify (syntax, and that each ExecStart exists and is executable); the installed
# server runs from there on its installed scene and the installed console finds its page. The
# machine type runs no systemd: the units are verified, not started. Skips by name without
# systemd-analyze.
# Usage: services_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$(cd "$2" && pwd)"
. "$src/tests/integration/common.sh"
trap 'show_output; rm -rf "$tmp"' EXIT
"$src/deploy/install-services.sh" --prefix "$tmp/opt" --units "$tmp/units" --build "$build" > "$tmp/install.log" 2>&1; rc=$?
cat "$tmp/install.log"
check "install-services installed into a scratch prefix (rc $rc)" "[ $rc -eq 0 ] && [ -x '$tmp/opt/bin/viscera-server' ] && [ -f '$tmp/opt/share/viscera/web/index.html' ]"
if command -v systemd-analyze >/dev/null; then
  ln -s viscera-server@.service "$tmp/units/viscera-server@bay-1.service"
  ln -s viscera-record@.service "$tmp/units/viscera-record@bay-1.service"
  systemd-analyze verify "$tmp/units/viscera-server@bay-1.service" "$tmp/units/viscera-record@bay-1.service" "$tmp/units/viscera-console.service" \
    > "$tmp/verify.log" 2>&1; rc_verify=$?
  cat "$tmp/verify.log"
  check "systemd-analyze verify accepts the three units (rc $rc_verify)" "[ $rc_verify -eq 0 ] && [ ! -s '$tmp/verify.log' ]"
  check "the units name the installed programs" "grep -q 'ExecStart=$tmp/opt/bin/viscera-server' '$tmp/units/viscera-server@.service'"
else
  echo "services_test: SKIPPED the units' check: systemd-analyze is not installed"
fi
# The installed server runs its installed scene for a second (no client).
timeout 5 "$tmp/opt/bin/viscera-server" --scene "$tmp/opt/share/viscera/data/scenes/liver.json" --duration 1 --quiet --station svc > "$tmp/server.log" 2>&1; rc_server=$?
check "the installed server ran its installed scene (rc $rc_server)" "[ $rc_server -eq 0 ] && grep -q 'stopped after' '$tmp/server.log'"
openssl rand -hex 16 > "$tmp/token"; chmod 600 "$tmp/token"
timeout 3 "$tmp/opt/bin/viscera-console" --domain "$domain" --stations svc --listen 127.0.0.1:0 --token-file "$tmp/token" \
  --web-root "$tmp/opt/share/viscera/web" > "$tmp/console.log" 2>&1
check "the installed console started on the installed page" "grep -q 'station(s); open' '$tmp/console.log'"
finish
