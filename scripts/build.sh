#!/usr/bin/env bash
# Configures and builds fieldrig into build/ (or $FIELDRIG_BUILD_DIR), RelWithDebInfo (or
# $FIELDRIG_BUILD_TYPE), with the sanitizers of $FIELDRIG_SANITIZE (none when unset; see
# scripts/test-sanitize.sh).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${FIELDRIG_BUILD_DIR:-$root/build}
build_type=${FIELDRIG_BUILD_TYPE:-RelWithDebInfo}
# Progress goes to stderr: stdout is kept for the data the commands print (JSON lines).
"$root/scripts/install-deps.sh" >&2
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE="$build_type" \
  -DFIELDRIG_SANITIZE="${FIELDRIG_SANITIZE:-}" >/dev/null
cmake --build "$build" --parallel "$(nproc)" >&2
