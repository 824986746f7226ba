#!/bin/sh
# Checks the systemd files with systemd's own parsers and fails on any complaint (they only warn
# and still exit 0 for unknown keys or bad values).
#   $1: unit configured for this test (ExecStart=/bin/true, see CMakeLists.txt)
#   $2: the unit as it will be installed   $3: sysusers file   $4: tmpfiles file
set -eu
test_unit=$1 installed_unit=$2 sysusers=$3 tmpfiles=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0

# check NAME FILE COMMAND...: COMMAND must succeed and print nothing about FILE (the parsers
# report problems as "FILE:LINE: ..."; sysusers also prints what it would create).
check() {
  name=$1 file=$2
  shift 2
  if ! "$@" >"$work/out" 2>&1 || grep -qF "$file" "$work/out"; then
    echo "FAIL: $name" >&2
    cat "$work/out" >&2
    status=1
  fi
}

# The test copy must be the installed unit except for the ExecStart= binary path.
if ! diff "$installed_unit" "$test_unit" >"$work/diff"; then
  if grep '^[<>]' "$work/diff" | grep -qv '^[<>] ExecStart='; then
    echo "FAIL: test unit differs from the installed unit beyond ExecStart=" >&2
    cat "$work/diff" >&2
    status=1
  fi
fi

# verify needs the file name to end in .service; copy it under its real name.
cp "$test_unit" "$work/drivegated.service"
# verify prints nothing at all for a clean unit.
if ! systemd-analyze verify "$work/drivegated.service" >"$work/out" 2>&1 || [ -s "$work/out" ]; then
  echo "FAIL: systemd-analyze verify" >&2
  cat "$work/out" >&2
  status=1
fi

# Both tools act on a scratch root, never on this machine; they need absolute file names.
mkdir -p "$work/root/etc"
: >"$work/root/etc/passwd"
: >"$work/root/etc/group"
check "systemd-sysusers" "$sysusers" systemd-sysusers --root="$work/root" --dry-run "$sysusers"
check "systemd-tmpfiles" "$tmpfiles" systemd-tmpfiles --root="$work/root" --create "$tmpfiles"
if [ ! -d "$work/root/etc/drivegate" ]; then
  echo "FAIL: tmpfiles did not create /etc/drivegate" >&2
  status=1
fi
exit $status
