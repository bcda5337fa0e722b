#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Creates a TEST public-key infrastructure for viscera's DDS Security (deploy/dds/secure.xml):
#   ca.pem, ca.key                   the test certificate authority (EC prime256v1, 10 years)
#   IDENTITY.pem, IDENTITY.key       one certificate and key per identity, signed by the CA
#   governance.xml / .p7s            the domain's rules, signed: no unauthenticated participant,
#                                    every viscera_* topic access-controlled and encrypted
#   IDENTITY-permissions.xml / .p7s  what each identity may publish and subscribe, signed
# Identities, per station S given (default: bay-1 bay-2), and for the whole site:
#   server-S    publishes the server's streams in S; reads commands, session requests, lockstep steps
#   haptic-S    publishes instrument commands and session requests in S only; reads S
#   trainer-S   publishes session requests and annotations (events) in S; reads S
#   console     publishes session requests, instrument commands (take-over) and annotations in
#               every station; reads every station
#   recorder    reads every station; publishes nothing
#   replay      publishes every stream, in replay and re-simulation stations only (viscera-replay*)
# And for the console's web page (HTTPS and WSS; a TLS server certificate, not a DDS identity):
#   console-web.pem, console-web.key  for localhost, 127.0.0.1, ::1 and the host names or addresses
#                                     in VISCERA_CONSOLE_HOSTS (space-separated)
# A real site keeps its CA key offline and issues identities from its own CA (docs/DEPLOY.md).
# Usage: [VISCERA_CONSOLE_HOSTS="console.lab 10.1.2.3"] deploy/dds/make-test-pki.sh OUT_DIR [STATION...]
set -euo pipefail
if [ $# -lt 1 ] || [ "$1" = "--help" ] || [ "$1" = "-h" ]; then
  sed -n '3,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'
  [ $# -ge 1 ]; exit $?
fi
out="$1"; shift
stations=("$@"); [ ${#stations[@]} -gt 0 ] || stations=(bay-1 bay-2)
for s in "${stations[@]}"; do
  if ! [[ "$s" =~ ^[A-Za-z0-9._-]{1,64}$ ]]; then
    echo "make-test-pki: station '$s': only letters, digits, '-', '_' and '.' (at most 64), as viscera --station" >&2; exit 2
  fi
done
read -ra console_hosts <<< "${VISCERA_CONSOLE_HOSTS:-}"
for h in "${console_hosts[@]}"; do
  if ! [[ "$h" =~ ^[A-Za-z0-9.:-]{1,253}$ ]]; then
    echo "make-test-pki: VISCERA_CONSOLE_HOSTS: '$h' is not a host name or an IP address" >&2; exit 2
  fi
done
if [ -e "$out/ca.key" ]; then echo "make-test-pki: $out/ca.key exists: a PKI is there already (remove the folder to make a new one)" >&2; exit 2; fi
command -v openssl >/dev/null || { echo "make-test-pki: openssl not found (apt-get install openssl)" >&2; exit 2; }
mkdir -p "$out"; chmod 700 "$out"
cd "$out"
org="viscera test site"
quiet() { "$@" >/dev/null 2>openssl.err || { echo "make-test-pki: $* failed:" >&2; cat openssl.err >&2; exit 1; }; }

# The CA.
quiet openssl ecparam -name prime256v1 -genkey -noout -out ca.key
quiet openssl req -x509 -new -key ca.key -sha256 -days 3650 -subj "/C=CH/O=$org/CN=viscera test CA" -out ca.pem
chmod 600 ca.key

identity() {  # NAME: key, request, certificate signed by the CA; prints the subject as permissions name it
  quiet openssl ecparam -name prime256v1 -genkey -noout -out "$1.key"
  chmod 600 "$1.key"
  quiet openssl req -new -key "$1.key" -subj "/C=CH/O=$org/CN=$1" -out "$1.csr"
  quiet openssl x509 -req -in "$1.csr" -CA ca.pem -CAkey ca.key -CAcreateserial -days 3650 -sha256 -out "$1.pem"
  rm "$1.csr"
}
subject() { openssl x509 -in "$1.pem" -noout -subject -nameopt RFC2253 | sed 's/^subject=//'; }
sign() {  # FILE.xml -> FILE.p7s (S/MIME, signed by the CA, as DDS Security reads it)
  quiet openssl smime -sign -in "$1.xml" -text -out "$1.p7s" -signer ca.pem -inkey ca.key
}

cat > governance.xml <<'EOF'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>230</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
sign governance

not_before=$(date -u -d '-1 hour' +%Y-%m-%dT%H:%M:%S)
not_after=$(date -u -d '+10 years' +%Y-%m-%dT%H:%M:%S)
topics() { for t in "$@"; do printf '<topic>viscera_%s</topic>' "$t"; done; }
partitions() { for p in "$@"; do printf '<partition>%s</partition>' "$p"; done; }
rule() {  # publish|subscribe "TOPICS" "PARTITIONS" (words; '*' is a DDS wildcard, never a file name)
  local -a t p
  read -ra t <<< "$2"; read -ra p <<< "$3"
  printf '        <%s><topics>%s</topics><partitions>%s</partitions></%s>\n' "$1" "$(topics "${t[@]}")" "$(partitions "${p[@]}")" "$1"
}
permissions() {  # NAME RULES...: the identity's permissions document, signed
  local name="$1"; shift
  {
    cat <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$name">
      <subject_name>$(subject "$name")</subject_name>
      <validity><not_before>$not_before</not_before><not_after>$not_after</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>230</max></id_range></domains>
EOF
    printf '%s\n' "$@"
    cat <<EOF
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
EOF
  } > "$name-permissions.xml"
  sign "$name-permissions"
}

server_writes="force_feedback scene_state telemetry surface_topology mesh_frame event scene_files lockstep_result"
server_reads="instrument_command session_request lockstep_step"
for s in "${stations[@]}"; do
  identity "server-$s"
  permissions "server-$s" "$(rule publish "$server_writes" "$s")" "$(rule subscribe "$server_reads" "$s")"
  identity "haptic-$s"
  permissions "haptic-$s" "$(rule publish "instrument_command session_request" "$s")" "$(rule subscribe "*" "$s")"
  identity "trainer-$s"
  permissions "trainer-$s" "$(rule publish "session_request event" "$s")" "$(rule subscribe "*" "$s")"
done
identity console
permissions console "$(rule publish "session_request instrument_command event" "${stations[*]}")" "$(rule subscribe "*" "${stations[*]}")"
identity recorder
permissions recorder "$(rule subscribe "*" "${stations[*]}")"
identity replay
permissions replay "$(rule publish "*" "viscera-replay* viscera-resimulate-*")" "$(rule subscribe "*" "viscera-replay* viscera-resimulate-*")"
# The console's HTTPS certificate: names in subjectAltName (browsers ignore the common name).
san="DNS:localhost,IP:127.0.0.1,IP:::1"
for h in "${console_hosts[@]}"; do
  if [[ "$h" =~ ^[0-9.]+$ || "$h" == *:* ]]; then san+=",IP:$h"; else san+=",DNS:$h"; fi
done
printf 'basicConstraints=critical,CA:FALSE\nkeyUsage=critical,digitalSignature\nextendedKeyUsage=serverAuth\nsubjectAltName=%s\n' "$san" > console-web.ext
quiet openssl ecparam -name prime256v1 -genkey -noout -out console-web.key
chmod 600 console-web.key
quiet openssl req -new -key console-web.key -subj "/C=CH/O=$org/CN=viscera console" -out console-web.csr
quiet openssl x509 -req -in console-web.csr -CA ca.pem -CAkey ca.key -CAcreateserial -days 825 -sha256 -extfile console-web.ext -out console-web.pem
rm -f console-web.csr console-web.ext openssl.err ca.srl
echo "make-test-pki: a TEST CA and ${#stations[@]} station(s) (${stations[*]}) in $out: $(ls "$out"/*.pem | wc -l) certificates; use with VISCERA_PKI=$out VISCERA_IDENTITY=NAME (deploy/dds/secure.xml)"
