#!/usr/bin/env bash
# Checks a configured fieldrigd.service with `systemd-analyze verify` (CTest systemd.verify_unit).
#
#   verify-unit.sh [--inject LINE] UNIT INSTALLED_BINARY [BUILT_BINARY]
#
# UNIT is the unit configured in the build tree; INSTALLED_BINARY the path its ExecStart= and
# ExecStartPre= name (e.g. /usr/bin/fieldrigd). verify refuses a unit whose binaries are missing, and
# the binary is not installed at build time: a copy of the unit is verified in which exactly that
# path, and nothing else, is replaced by BUILT_BINARY (the fieldrigd just built) or, while there is
# no fieldrigd target yet, by an executable stub.
#
# verify exits 0 on most unit errors: an unknown key or a bad value is only a warning ("Unknown key
# 'X' in section [Service], ignoring."). So any output line that names the unit fails the check too.
# --inject LINE adds LINE after [Service]: the self-test that a bad directive is caught.
# Works offline, without systemd as PID 1 (verify runs a test-mode manager of its own).
set -euo pipefail

inject=""
if [[ ${1:-} == --inject ]]; then
  inject=$2
  shift 2
fi
if (($# < 2 || $# > 3)); then
  echo "usage: $0 [--inject LINE] UNIT INSTALLED_BINARY [BUILT_BINARY]" >&2
  exit 2
fi
unit=$1
installed_binary=$2
built_binary=${3:-}

if ! command -v systemd-analyze >/dev/null; then
  echo "verify-unit: systemd-analyze not found (Debian package systemd): skipped" >&2
  exit 77
fi
[[ -f $unit ]] || { echo "verify-unit: no unit $unit" >&2; exit 1; }
if grep -n '@[A-Za-z_]*@' "$unit"; then
  echo "verify-unit: $unit: unconfigured @VARIABLE@ left (lines above)" >&2
  exit 1
fi
# Both ExecStartPre= and ExecStart= must name the installed binary: the replacement below has to
# hit them, or verify would check a unit that differs from the installed one.
uses=$(grep -c -F -e "ExecStartPre=$installed_binary " -e "ExecStart=$installed_binary " "$unit" ||
  true)
if ((uses != 2)); then
  echo "verify-unit: $unit: expected ExecStartPre= and ExecStart= to run $installed_binary" >&2
  exit 1
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [[ -n $built_binary ]]; then
  [[ -x $built_binary ]] || {
    echo "verify-unit: $built_binary is not built (build fieldrigd first)" >&2
    exit 1
  }
  binary=$built_binary
else
  binary=$work/fieldrigd
  printf '#!/bin/sh\nexit 0\n' >"$binary"
  chmod +x "$binary"
  echo "verify-unit: no BUILT_BINARY given: ExecStart= checked against a stub"
fi

# The same file name: verify derives the unit's name and type from it.
name=$(basename "$unit")
copy=$work/$name
awk -v from="$installed_binary" -v to="$binary" -v inject="$inject" '
  { line = $0
    while ((i = index(line, from)) > 0) {
      out = out substr(line, 1, i - 1) to
      line = substr(line, i + length(from))
    }
    print out line
    out = ""
    if ($0 == "[Service]" && inject != "") print inject }' "$unit" >"$copy"

status=0
output=$(cd "$work" && systemd-analyze verify --man=no "$copy" 2>&1) || status=$?
[[ -z $output ]] || printf '%s\n' "$output"
if ((status != 0)); then
  echo "verify-unit: systemd-analyze verify failed (exit $status)" >&2
  exit 1
fi
if grep -q -F "$name" <<<"$output"; then
  echo "verify-unit: systemd-analyze verify reported problems in $name (above)" >&2
  exit 1
fi
echo "verify-unit: $name: OK"
