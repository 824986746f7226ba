#!/usr/bin/env bash
# Makes the DDS Security material for drivegate (Fast DDS builtin plugins PKI-DH,
# Access-Permissions, AES-GCM-GMAC) with openssl only. See usage() for what it writes.
set -euo pipefail

usage() {
  cat <<'EOF'
usage: scripts/make-pki.sh OUTDIR [options]

Creates an identity CA and a permissions CA, one signed governance document and one identity
directory per participant:

  OUTDIR/<name>/identity_ca.pem cert.pem key.pem permissions_ca.pem governance.p7s permissions.p7s

which is what drivegate's security settings point at (idl/dds_security.hpp, security_files_in()).
OUTDIR/ca/ keeps the CA keys and the unsigned XML documents: never ship it to a participant.

options:
  --domain N | N-M      DDS domain id or range the governance and grants cover (repeatable;
                        default 0)
  --namespace NS        governance rules and grants name the topics of namespace NS only
                        ("NS/axis_command", ...; "" for no namespace). Default: any namespace
                        ("*/axis_command" and "axis_command").
  --days N              validity of participant certificates and grants (default 365)
  --ca-days N           validity of the two CA certificates (default 3650)
  --gateway NAME        a gateway identity (repeatable; default: one named "gateway", made with or
                        without --client)
  --client NAME:ROLE[:expired]
                        a participant with ROLE = observer | operator | engineer | gateway
                        (repeatable). ":expired" makes a certificate whose validity ended
                        yesterday (for tests). Without --client: observer, operator, engineer,
                        each named after its role.
  --other-ca NAME:ROLE  a participant whose certificate comes from a second, unrelated identity CA
                        (OUTDIR/other-ca/). Its permissions are genuine and its identity_ca.pem
                        trusts both CAs, so the only thing wrong is its certificate and the
                        refusal comes from the others' check of it. For tests.
  --force               re-issue every participant key and certificate (the CAs are kept; delete
                        OUTDIR/ca to replace them)
  -h, --help            this text

Run it again with the same OUTDIR to add participants or change domains/namespace/days: the CAs
and still valid participant keys and certificates are kept, governance and permissions are
re-signed.
EOF
}

die() { echo "make-pki.sh: $*" >&2; exit 2; }

# ---------------------------------------------------------------------------------------------
# Arguments
outdir=""
domains=()
namespace_set=0
namespace=""
days=365
ca_days=3650
gateways=()
clients=()
others=()
force=0

need_value() { [[ $# -ge 2 ]] || die "$1 needs a value (see --help)"; }
while [[ $# -gt 0 ]]; do
  case $1 in
    -h|--help) usage; exit 0 ;;
    --domain) need_value "$@"; domains+=("$2"); shift 2 ;;
    --namespace) need_value "$@"; namespace=$2; namespace_set=1; shift 2 ;;
    --days) need_value "$@"; days=$2; shift 2 ;;
    --ca-days) need_value "$@"; ca_days=$2; shift 2 ;;
    --gateway) need_value "$@"; gateways+=("$2"); shift 2 ;;
    --client) need_value "$@"; clients+=("$2"); shift 2 ;;
    --other-ca) need_value "$@"; others+=("$2"); shift 2 ;;
    --force) force=1; shift ;;
    -*) die "unknown option $1 (see --help)" ;;
    *) [[ -z $outdir ]] || die "only one OUTDIR, got '$outdir' and '$1'"; outdir=$1; shift ;;
  esac
done
[[ -n $outdir ]] || { usage >&2; exit 2; }
command -v openssl >/dev/null || die "openssl is not installed"

[[ $days =~ ^[1-9][0-9]*$ ]] || die "--days must be a positive number, got '$days'"
[[ $ca_days =~ ^[1-9][0-9]*$ ]] || die "--ca-days must be a positive number, got '$ca_days'"
[[ ${#domains[@]} -gt 0 ]] || domains=(0)
for d in "${domains[@]}"; do
  # 232 is the largest id the default RTPS port mapping allows.
  if [[ $d =~ ^([0-9]+)-([0-9]+)$ ]]; then
    ((10#${BASH_REMATCH[1]} <= 10#${BASH_REMATCH[2]} && 10#${BASH_REMATCH[2]} <= 232)) ||
      die "bad domain range '$d' (want N-M with N <= M <= 232)"
  elif [[ $d =~ ^[0-9]+$ ]]; then
    ((10#$d <= 232)) || die "domain id $d is out of range 0..232"
  else
    die "bad --domain '$d' (want N or N-M)"
  fi
done
# Fast DDS matches topic names with fnmatch() without FNM_PATHNAME and with FNM_NOESCAPE, so a
# pattern character in the namespace cannot be escaped and would widen the grant; XML specials
# would break the documents.
if ((namespace_set)); then
  [[ $namespace != *[][*?\\\<\>\&\"\']* ]] ||
    die "--namespace '$namespace' must not contain * ? [ ] \\ < > & \" '"
fi

valid_name() { [[ $1 =~ ^[A-Za-z0-9][A-Za-z0-9_.-]*$ && $1 != ca && $1 != other-ca ]]; }
valid_role() { [[ $1 == observer || $1 == operator || $1 == engineer || $1 == gateway ]]; }

# Participant list: name role expired(0/1) ca(main/other), one entry per participant.
p_names=(); p_roles=(); p_expired=(); p_cas=()
add_participant() {
  local name=$1 role=$2 expired=$3 ca=$4 n
  valid_name "$name" || die "bad participant name '$name' (letters, digits, _ . -; not 'ca' or 'other-ca')"
  valid_role "$role" || die "bad role '$role' for '$name' (observer, operator, engineer, gateway)"
  for n in "${p_names[@]}"; do [[ $n != "$name" ]] || die "participant '$name' given twice"; done
  p_names+=("$name"); p_roles+=("$role"); p_expired+=("$expired"); p_cas+=("$ca")
}
[[ ${#gateways[@]} -gt 0 ]] || gateways=(gateway)
for g in "${gateways[@]}"; do add_participant "$g" gateway 0 main; done
if [[ ${#clients[@]} -eq 0 ]]; then
  for r in observer operator engineer; do add_participant "$r" "$r" 0 main; done
fi
for c in "${clients[@]}"; do
  IFS=: read -r name role flag extra <<<"$c"
  [[ -z ${extra:-} && ( -z ${flag:-} || $flag == expired ) && -n ${role:-} ]] ||
    die "bad --client '$c' (want NAME:ROLE or NAME:ROLE:expired)"
  add_participant "$name" "$role" "$([[ ${flag:-} == expired ]] && echo 1 || echo 0)" main
done
for c in "${others[@]}"; do
  IFS=: read -r name role extra <<<"$c"
  [[ -z ${extra:-} && -n ${role:-} ]] || die "bad --other-ca '$c' (want NAME:ROLE)"
  add_participant "$name" "$role" 0 other
done

# ---------------------------------------------------------------------------------------------
# Time. Certificates start an hour back so a peer whose clock is a little behind still accepts
# them. Grants start a day back: Fast DDS 2.9 reads the grant times with mktime(), i.e. as local
# time although the spec says UTC, so the window has to absorb any timezone offset.
now=$(date -u +%s)
cert_time() { date -u -d "@$1" +%Y%m%d%H%M%SZ; }    # openssl ca -startdate/-enddate format
xml_time() { date -u -d "@$1" +%Y-%m-%dT%H:%M:%S; }  # permissions <validity> format

created_outdir=0
[[ -d $outdir ]] || created_outdir=1
umask 077
mkdir -p "$outdir/ca"
outdir=$(cd "$outdir" && pwd)
# Participants' directories must be listable by the account that runs them; OUTDIR/ca stays 0700.
((created_outdir)) && chmod 755 "$outdir"
cadir=$outdir/ca
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# prime256v1 keys and ECDSA-SHA256 signatures: one of the two combinations PKI-DH and
# Access-Permissions accept (the other is RSA-2048/SHA-256); keys are small and signing is fast.
new_key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:prime256v1 \
  -pkeyopt ec_param_enc:named_curve -out "$1" 2>/dev/null; }

# new_ca KEY CERT SUBJECT: self-signed CA. digitalSignature is in the key usage because the
# permissions CA signs governance/permissions itself (S/MIME) and OpenSSL's S/MIME verification
# checks the signer's key usage.
new_ca() {
  local key=$1 cert=$2 subject=$3
  if [[ -s $key && -s $cert ]]; then return; fi
  new_key "$key"
  openssl req -x509 -new -key "$key" -sha256 -days "$ca_days" -subj "$subject" \
    -addext "basicConstraints=critical,CA:TRUE" \
    -addext "keyUsage=critical,keyCertSign,cRLSign,digitalSignature" \
    -addext "subjectKeyIdentifier=hash" -out "$cert"
  echo "created CA $subject in $cert"
}

# sign_cert CA_DIR CA_NAME CSR OUT START END: `openssl ca` rather than `openssl x509 -req`
# because OpenSSL 3.0's x509 cannot set a start date in the past (needed for :expired).
sign_cert() {
  local dir=$1 ca=$2 csr=$3 out=$4 start=$5 end=$6
  mkdir -p "$dir/db/certs"
  touch "$dir/db/index.txt"
  cat >"$work/ca.cnf" <<EOF
[ ca ]
default_ca = dg
[ dg ]
database = $dir/db/index.txt
new_certs_dir = $dir/db/certs
certificate = $dir/$ca.pem
private_key = $dir/$ca.key
rand_serial = yes
unique_subject = no
default_md = sha256
policy = dg_policy
email_in_dn = no
preserve = yes
copy_extensions = none
[ dg_policy ]
organizationName = supplied
organizationalUnitName = optional
commonName = supplied
[ leaf ]
basicConstraints = critical,CA:FALSE
keyUsage = critical,digitalSignature,keyAgreement
subjectKeyIdentifier = hash
authorityKeyIdentifier = keyid
EOF
  openssl ca -batch -config "$work/ca.cnf" -extensions leaf -notext \
    -startdate "$start" -enddate "$end" -in "$csr" -out "$out" 2>"$work/ca.log" ||
    { cat "$work/ca.log" >&2; die "signing $csr failed"; }
}

# sign_doc IN OUT: S/MIME clear-signed by the permissions CA, the form Access-Permissions reads
# (-text: it verifies with PKCS7_TEXT, which expects the text/plain MIME header).
sign_doc() {
  openssl smime -sign -text -in "$1" -out "$2" \
    -signer "$cadir/permissions_ca.pem" -inkey "$cadir/permissions_ca.key"
}

new_ca "$cadir/identity_ca.key" "$cadir/identity_ca.pem" "/O=drivegate/CN=drivegate identity CA"
new_ca "$cadir/permissions_ca.key" "$cadir/permissions_ca.pem" "/O=drivegate/CN=drivegate permissions CA"
if [[ ${#others[@]} -gt 0 ]]; then
  mkdir -p "$outdir/other-ca"
  new_ca "$outdir/other-ca/identity_ca.key" "$outdir/other-ca/identity_ca.pem" \
    "/O=unrelated/CN=unrelated identity CA"
fi

# ---------------------------------------------------------------------------------------------
# Topics per role (the part after "<namespace>/").
topics_publish() {
  case $1 in
    observer) ;;
    operator) echo axis_command setpoint io_write ;;
    engineer) echo axis_command setpoint param_request io_write ;;
    gateway) echo axis_state command_reply axis_event bus_status param_reply gateway_info axis_link io_state io_write_reply ;;
  esac
}
topics_subscribe() {
  case $1 in
    observer) echo axis_state axis_event bus_status gateway_info axis_link io_state ;;
    operator) echo axis_state axis_event bus_status gateway_info axis_link command_reply io_state io_write_reply ;;
    engineer) echo axis_state axis_event bus_status gateway_info axis_link command_reply param_reply io_state io_write_reply ;;
    gateway) echo axis_command setpoint param_request gateway_info io_write ;;
  esac
}
# The <topic> patterns for one topic. Fast DDS 2.9 matches with fnmatch(pattern, name,
# FNM_NOESCAPE): no FNM_PATHNAME, so '*' also matches '/', and "*/axis_command" covers every
# namespace (even "a/b"); the bare name covers the empty namespace, where the topic has no '/'.
topic_patterns() {
  if ((namespace_set)); then
    if [[ -n $namespace ]]; then echo "$namespace/$1"; else echo "$1"; fi
  else
    echo "*/$1" "$1"
  fi
}

domains_xml() {
  local indent=$1 d
  echo "$indent<domains>"
  for d in "${domains[@]}"; do
    if [[ $d =~ ^([0-9]+)-([0-9]+)$ ]]; then
      echo "$indent  <id_range><min>$((10#${BASH_REMATCH[1]}))</min><max>$((10#${BASH_REMATCH[2]}))</max></id_range>"
    else
      echo "$indent  <id>$((10#$d))</id>"
    fi
  done
  echo "$indent</domains>"
}

# One topic_rule. Element order is fixed: Fast DDS's parser rejects any other order.
topic_rule() {
  local suffix=$1 metadata=$2 data=$3 p
  for p in $(topic_patterns "$suffix"); do
    cat <<EOF
        <topic_rule>
          <topic_expression>$p</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>$metadata</metadata_protection_kind>
          <data_protection_kind>$data</data_protection_kind>
        </topic_rule>
EOF
  done
}

# Governance. There is deliberately no catch-all "*" rule: a topic not listed here has no rule, and
# Fast DDS then refuses to create any endpoint on it, so a new topic needs a conscious decision.
{
  cat <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<!-- drivegate DDS Security governance, made by scripts/make-pki.sh. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
EOF
  domains_xml "      "
  cat <<EOF
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>SIGN</rtps_protection_kind>
      <topic_access_rules>
EOF
  # Commands, set-points, parameters and their replies move machines and change drives:
  # confidential and tamper-proof, data and metadata; so do the output bytes of I/O slaves.
  for t in axis_command setpoint command_reply param_request param_reply io_write io_write_reply; do
    topic_rule "$t" ENCRYPT ENCRYPT
  done
  # State, events, bus status, gateway info, link details, I/O bytes: nothing secret, but nobody may forge
  # them. Signing the submessage covers its serialized payload too, so data protection on top adds
  # nothing.
  for t in axis_state axis_event bus_status gateway_info axis_link io_state; do
    topic_rule "$t" SIGN NONE
  done
  cat <<EOF
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
} >"$cadir/governance.xml"
sign_doc "$cadir/governance.xml" "$cadir/governance.p7s"

criteria_xml() {
  local kind=$1 t p
  shift
  [[ $# -gt 0 ]] || return 0
  echo "        <$kind>"
  echo "          <topics>"
  for t in "$@"; do
    for p in $(topic_patterns "$t"); do echo "            <topic>$p</topic>"; done
  done
  echo "          </topics>"
  echo "        </$kind>"
}

# ---------------------------------------------------------------------------------------------
# Participants
mkdir -p "$cadir/participants"
for i in "${!p_names[@]}"; do
  name=${p_names[$i]} role=${p_roles[$i]} expired=${p_expired[$i]} which=${p_cas[$i]}
  dir=$outdir/$name
  mkdir -p "$dir"
  if [[ $which == other ]]; then idca_dir=$outdir/other-ca; else idca_dir=$cadir; fi
  subject="/O=drivegate/OU=$role/CN=$name"

  # Keep a key and certificate that are still right: same CA, subject and expiry kind.
  reuse=0
  if ((!force)) && [[ -s $dir/key.pem && -s $dir/cert.pem ]] &&
     openssl verify -no_check_time -CAfile "$idca_dir/identity_ca.pem" "$dir/cert.pem" >/dev/null 2>&1 &&
     [[ $(openssl x509 -in "$dir/cert.pem" -noout -subject -nameopt compat) == "subject=$subject" ]] &&
     [[ $(openssl x509 -in "$dir/cert.pem" -noout -pubkey) == $(openssl pkey -in "$dir/key.pem" -pubout) ]]; then
    if ((expired)); then
      openssl x509 -in "$dir/cert.pem" -noout -checkend 0 >/dev/null || reuse=1
    else
      openssl x509 -in "$dir/cert.pem" -noout -checkend 86400 >/dev/null && reuse=1
    fi
  fi
  if ((!reuse)); then
    new_key "$dir/key.pem"
    openssl req -new -key "$dir/key.pem" -subj "$subject" -out "$work/$name.csr"
    if ((expired)); then
      start=$(cert_time $((now - 30 * 86400))) end=$(cert_time $((now - 86400)))
    else
      start=$(cert_time $((now - 3600))) end=$(cert_time $((now + days * 86400)))
    fi
    sign_cert "$idca_dir" identity_ca "$work/$name.csr" "$dir/cert.pem" "$start" "$end"
  fi

  # The grant's subject is read back from the certificate in RFC 2253 form ("CN=..,OU=..,O=..",
  # most specific first), the form Fast DDS compares against.
  sn=$(openssl x509 -in "$dir/cert.pem" -noout -subject -nameopt RFC2253)
  sn=${sn#subject=}
  {
    cat <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<!-- drivegate DDS Security permissions for $name (role $role), made by scripts/make-pki.sh. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$name">
      <subject_name>$sn</subject_name>
      <validity>
        <not_before>$(xml_time $((now - 86400)))</not_before>
        <not_after>$(xml_time $((now + days * 86400)))</not_after>
      </validity>
      <allow_rule>
EOF
    domains_xml "        "
    # shellcheck disable=SC2046  # word splitting of the topic lists is intended
    criteria_xml publish $(topics_publish "$role")
    # shellcheck disable=SC2046
    criteria_xml subscribe $(topics_subscribe "$role")
    cat <<EOF
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
EOF
  } >"$cadir/participants/$name.xml"
  sign_doc "$cadir/participants/$name.xml" "$dir/permissions.p7s"

  if [[ $which == other ]]; then
    # It trusts both CAs, so it accepts our participants' certificates and the refusal that a test
    # sees is our participants' own check of its certificate, not its check of ours.
    cat "$idca_dir/identity_ca.pem" "$cadir/identity_ca.pem" >"$dir/identity_ca.pem"
  else
    cp "$idca_dir/identity_ca.pem" "$dir/identity_ca.pem"
  fi
  cp "$cadir/permissions_ca.pem" "$dir/permissions_ca.pem"
  cp "$cadir/governance.p7s" "$dir/governance.p7s"
  chmod 600 "$dir/key.pem"
  chmod 644 "$dir/identity_ca.pem" "$dir/cert.pem" "$dir/permissions_ca.pem" \
    "$dir/governance.p7s" "$dir/permissions.p7s"
  chmod 755 "$dir"

  note=""
  ((expired)) && note=" (certificate expired)"
  [[ $which == other ]] && note=" (certificate from the unrelated CA in other-ca/)"
  ((reuse)) && note+=" [kept key and certificate]"
  printf '%-12s %-9s %s%s\n' "$name" "$role" "$sn" "$note"
done
echo "key.pem is mode 0600 and owned by $(id -un): give it to the account that runs the participant" \
  "(drivegated runs as 'drivegate')."
echo "governance and permissions for domain(s) ${domains[*]}," \
  "namespace $( ((namespace_set)) && echo "'$namespace'" || echo "any"); identities in $outdir/<name>/"
