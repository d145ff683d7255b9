#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (unit, pty serial, CLI, fuzz smoke).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${FIELDRIG_BUILD_DIR:-$root/build}
"$root/scripts/build.sh"
ctest --test-dir "$build" --output-on-failure --timeout 300 -j "$(nproc)"
