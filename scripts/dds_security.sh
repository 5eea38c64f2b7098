#!/usr/bin/env bash
# DDS Security material for a robodamp cell (OMG DDS Security 1.1 as Fast DDS's builtin plugins read it):
# one certificate authority that signs the identities and the access-control documents, three identities,
# the governance and one permissions document per identity, all signed (S/MIME).
#
#   loop       the controller (robodamp run): publishes telemetry, status and replies, reads requests
#   operator   robodamp request / monitor: may write parameter requests and read everything else
#   observer   a dashboard: may read telemetry and status, nothing else
#
# Governance: joining needs no authentication (allow_unauthenticated_participants), so an
# unauthenticated monitor still reads telemetry and status, which are not protected; the parameter
# request and reply topics need authenticated, authorised participants and are encrypted (AES-GCM).
#
#   bash scripts/dds_security.sh DIR             # writes DIR/{ca,loop,operator,observer}.{pem,key},
#                                                  DIR/governance.smime, DIR/*_permissions.smime
# Then, in a configuration:  dds: {security: {identity_ca: DIR/ca.pem, identity_certificate: DIR/loop.pem,
#   private_key: DIR/loop.key, permissions_ca: DIR/ca.pem, governance: DIR/governance.smime,
#   permissions: DIR/loop_permissions.smime}}
# A real cell keeps ca.key offline and issues keys on the devices themselves; this script is for a
# first set-up and for the tests.
set -euo pipefail
dir="${1:?usage: dds_security.sh DIR}"
mkdir -p "$dir"
cd "$dir"
days=3650
ossl() { openssl "$@" 2>/dev/null; }

ossl ecparam -name prime256v1 -genkey -noout -out ca.key
ossl req -x509 -new -key ca.key -sha256 -days "$days" -subj "/CN=robodamp cell CA" -out ca.pem \
  -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,keyCertSign,cRLSign,digitalSignature"

for who in loop operator observer; do
  ossl ecparam -name prime256v1 -genkey -noout -out "$who.key"
  ossl req -new -key "$who.key" -sha256 -subj "/CN=robodamp $who" -out "$who.csr"
  ossl x509 -req -in "$who.csr" -CA ca.pem -CAkey ca.key -CAcreateserial -sha256 -days "$days" -out "$who.pem"
  rm -f "$who.csr"
done

cat > governance.xml <<'XML'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>232</max></id_range></domains>
      <allow_unauthenticated_participants>true</allow_unauthenticated_participants>
      <enable_join_access_control>false</enable_join_access_control>
      <discovery_protection_kind>NONE</discovery_protection_kind>
      <liveliness_protection_kind>NONE</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>rt/robodamp/parameter_*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>false</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>false</enable_discovery_protection>
          <enable_liveliness_protection>false</enable_liveliness_protection>
          <enable_read_access_control>false</enable_read_access_control>
          <enable_write_access_control>false</enable_write_access_control>
          <metadata_protection_kind>NONE</metadata_protection_kind>
          <data_protection_kind>NONE</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
XML

permissions() {  # name, publish topics, subscribe topics
  local topic_list
  {
    echo '<?xml version="1.0" encoding="UTF-8"?>'
    echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">'
    echo '  <permissions>'
    echo "    <grant name=\"robodamp_$1\">"
    echo "      <subject_name>CN=robodamp $1</subject_name>"
    echo '      <validity><not_before>2020-01-01T00:00:00</not_before><not_after>2099-12-31T23:59:59</not_after></validity>'
    echo '      <allow_rule>'
    echo '        <domains><id_range><min>0</min><max>232</max></id_range></domains>'
    topic_list=""; for t in $2; do topic_list+="<topic>$t</topic>"; done
    [[ -n "$2" ]] && echo "        <publish><topics>$topic_list</topics></publish>"
    topic_list=""; for t in $3; do topic_list+="<topic>$t</topic>"; done
    [[ -n "$3" ]] && echo "        <subscribe><topics>$topic_list</topics></subscribe>"
    echo '      </allow_rule>'
    echo '      <default>DENY</default>'
    echo '    </grant>'
    echo '  </permissions>'
    echo '</dds>'
  } > "$1_permissions.xml"
}
permissions loop "rt/robodamp/telemetry rt/robodamp/status rt/robodamp/machining rt/robodamp/advice rt/robodamp/spectrum rt/robodamp/lobes rt/robodamp/parameter_reply" "rt/robodamp/parameter_request"
permissions operator "rt/robodamp/parameter_request" "rt/robodamp/telemetry rt/robodamp/status rt/robodamp/machining rt/robodamp/advice rt/robodamp/spectrum rt/robodamp/lobes rt/robodamp/parameter_reply"
permissions observer "" "rt/robodamp/telemetry rt/robodamp/status rt/robodamp/machining rt/robodamp/advice rt/robodamp/spectrum rt/robodamp/lobes"

for doc in governance loop_permissions operator_permissions observer_permissions; do
  ossl smime -sign -in "$doc.xml" -text -out "$doc.smime" -signer ca.pem -inkey ca.key
done
rm -f ca.srl
echo "DDS Security material in $(pwd)"
