#!/usr/bin/env bash
# Installs the build tree into a temporary DESTDIR and checks what the system integration puts
# where (CTest systemd.install).
#
#   check-install.sh CMAKE BUILD_DIR BINARIES(0|1) UNIT UDEV_RULE SYSUSERS CONFIG BINDIR
#
# UNIT, UDEV_RULE, SYSUSERS and CONFIG are the absolute paths the files must have after
# `cmake --install` (prefix and GNUInstallDirs applied by CMake); BINDIR the absolute bin folder.
# BINARIES=1 when systemd/install.cmake installs fieldrig and fieldrigd: both are checked then.
#
# DESTDIR rather than --prefix: the example configuration goes to CMAKE_INSTALL_FULL_SYSCONFDIR,
# which for the prefix /usr is the absolute /etc (GNUInstallDirs), and the unit names the binary
# and configuration paths fixed at configure time; a --prefix given at install time would move
# neither, and as root would write into the real /etc. DESTDIR stages every path, absolute or not.
set -euo pipefail

if (($# != 8)); then
  echo "usage: $0 CMAKE BUILD_DIR BINARIES UNIT UDEV_RULE SYSUSERS CONFIG BINDIR" >&2
  exit 2
fi
cmake=$1 build=$2 binaries=$3 unit=$4 rule=$5 sysusers=$6 config=$7 bindir=$8

stage=$(mktemp -d)
log=$(mktemp)
trap 'rm -rf "$stage" "$log"' EXIT
DESTDIR=$stage "$cmake" --install "$build" >"$log" 2>&1 || {
  cat "$log" >&2
  echo "check-install: cmake --install failed" >&2
  exit 1
}

failed=0
fail() {
  echo "check-install: $*" >&2
  failed=1
}
for file in "$unit" "$rule" "$sysusers" "$config"; do
  if [[ -s $stage$file ]]; then
    echo "check-install: installed $file"
  else
    fail "missing or empty: $file"
  fi
done

if [[ -s $stage$unit ]]; then
  # The installed unit runs the installed binary with the installed configuration.
  grep -q -x -F "ExecStart=$bindir/fieldrigd run --config $config" "$stage$unit" ||
    fail "$unit: ExecStart= does not run $bindir/fieldrigd with $config"
  ! grep -n '@[A-Za-z_]*@' "$stage$unit" || fail "$unit: unconfigured @VARIABLE@ left"
fi
if [[ -s $stage$sysusers ]] && command -v systemd-sysusers >/dev/null; then
  # Parses the file against an empty root: a syntax error fails, nothing is written.
  mkdir -p "$stage/sysusers-root"
  systemd-sysusers --dry-run --root="$stage/sysusers-root" "$stage$sysusers" >/dev/null ||
    fail "$sysusers: systemd-sysusers rejects it"
fi
if [[ -s $stage$rule ]] && udevadm verify --help >/dev/null 2>&1; then
  # udevadm verify exists from systemd 253 on (Debian 12 has 252: skipped there).
  udevadm verify --resolve-names=never "$stage$rule" || fail "$rule: udevadm verify rejects it"
fi

if [[ $binaries == 1 ]]; then
  for program in fieldrig fieldrigd; do
    if [[ -x $stage$bindir/$program ]]; then
      echo "check-install: installed $bindir/$program"
    else
      fail "missing or not executable: $bindir/$program"
    fi
  done
  # The launcher finds the programs it runs in the installed layout (libexec/fieldrig), not only in
  # the build tree: the full tool for the help, the light one for `traits`.
  launcher=$stage$bindir/fieldrig
  if [[ -x $launcher ]]; then
    help=$("$launcher" --help 2>&1) || true
    grep -q "evaluate" <<<"$help" ||
      fail "$bindir/fieldrig --help does not list the subcommands: $help"
    help=$("$launcher" traits --help 2>&1) || true
    grep -q -- "--cloud" <<<"$help" ||
      fail "$bindir/fieldrig traits --help does not show --cloud: $help"
  fi
else
  echo "check-install: fieldrigd not installed yet (no target or install.cmake not included):" \
    "binaries not checked"
fi
exit $failed
