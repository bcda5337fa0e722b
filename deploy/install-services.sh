#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs viscera as services on this host (docs/DEPLOY.md): builds what is missing, installs the
# programs, data, console page and DDS configurations under PREFIX (default /opt/viscera), the
# systemd units under UNITS (default /etc/systemd/system), and with --system also the service user
# `viscera`, /etc/viscera (dds.env, console.env, console.token: created once, never overwritten),
# /var/lib/viscera/recordings and /var/log/viscera, then reloads systemd. Enabling the services is
# left to the administrator: systemctl enable --now viscera-server@bay-1 viscera-record@bay-1 ...
# --portable builds for any x86-64 CPU (the default tunes the code to this one: install on the host
# that built it, or build with --portable in a build folder of its own, --build DIR).
# Usage: deploy/install-services.sh [--prefix DIR] [--units DIR] [--system] [--build DIR] [--portable]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
prefix=/opt/viscera; units=/etc/systemd/system; system=0; build="$root/build"; portable=()
while [ $# -gt 0 ]; do
  case "$1" in
    --prefix) prefix="$2"; shift 2 ;;
    --units) units="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --system) system=1; shift ;;
    --portable) portable=(-DVISCERA_NATIVE=OFF); shift ;;
    -h|--help) sed -n '3,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "install-services: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$prefix" in /*) ;; *) echo "install-services: --prefix '$prefix' is not an absolute path" >&2; exit 2 ;; esac
if [ "$system" = 1 ] && [ "$(id -u)" -ne 0 ]; then echo "install-services: --system needs root" >&2; exit 2; fi
log="$(mktemp)"; trap 'rm -f "$log"' EXIT
"$root/deploy/build.sh" "$build" "${portable[@]}" > "$log" 2>&1 || { tail -20 "$log"; exit 1; }
cmake --install "$build" --prefix "$prefix" > /dev/null
install -m 644 "$root/docs/DEPLOY.md" "$prefix/share/viscera/DEPLOY.md"
mkdir -p "$units"
for unit in "$root"/deploy/systemd/*.service; do
  sed "s#@PREFIX@#$prefix#g" "$unit" > "$units/$(basename "$unit")"
  chmod 644 "$units/$(basename "$unit")"
done
echo "install-services: programs in $prefix/bin, units in $units: $(cd "$units" && ls viscera-*.service | xargs)"
[ "$system" = 1 ] || exit 0

id viscera >/dev/null 2>&1 || useradd --system --home-dir /var/lib/viscera --shell /usr/sbin/nologin viscera
install -d -m 755 /etc/viscera
install -d -o viscera -g viscera -m 750 /var/lib/viscera /var/lib/viscera/recordings /var/log/viscera
if [ ! -e /etc/viscera/dds.env ]; then
  cat > /etc/viscera/dds.env <<EOF
# The DDS network of this host (docs/DEPLOY.md). For DDS Security append
# ,file://$prefix/share/viscera/dds/secure.xml to CYCLONEDDS_URI and set VISCERA_PKI.
CYCLONEDDS_URI=file://$prefix/share/viscera/dds/lan.xml
VISCERA_DDS_INTERFACE=auto
VISCERA_DDS_PEERS=localhost
#VISCERA_PKI=/etc/viscera/pki
EOF
fi
if [ ! -e /etc/viscera/console.token ]; then
  (umask 077; openssl rand -hex 16 > /etc/viscera/console.token)
  chown viscera:viscera /etc/viscera/console.token
fi
if command -v systemctl >/dev/null && [ -d /run/systemd/system ]; then systemctl daemon-reload; fi
echo "install-services: user viscera, /etc/viscera, /var/lib/viscera/recordings and /var/log/viscera ready"
