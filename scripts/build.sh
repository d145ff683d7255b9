#!/usr/bin/env bash
# Configures and builds fieldrig into build/ (or $FIELDRIG_BUILD_DIR), RelWithDebInfo (or
# $FIELDRIG_BUILD_TYPE), with the sanitizers of $FIELDRIG_SANITIZE (none when unset; see
# scripts/test-sanitize.sh). FIELDRIG_UNITY_BUILD=ON compiles each target's sources in batches
# (CMAKE_UNITY_BUILD): CI's Release and sanitizer builds use it to parse the heavy headers (PCL,
# OpenCV, Eigen, Boost) once per batch instead of once per file. FIELDRIG_BUILD_TARGETS (space
# separated, e.g. "tests/core/all") builds only those targets and what they need.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${FIELDRIG_BUILD_DIR:-$root/build}
build_type=${FIELDRIG_BUILD_TYPE:-RelWithDebInfo}
# Progress goes to stderr: stdout is kept for the data the commands print (JSON lines).
"$root/scripts/install-deps.sh" >&2
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE="$build_type" \
  -DFIELDRIG_SANITIZE="${FIELDRIG_SANITIZE:-}" -DCMAKE_UNITY_BUILD="${FIELDRIG_UNITY_BUILD:-OFF}" \
  >/dev/null
read -r -a targets <<<"${FIELDRIG_BUILD_TARGETS:-all}"
cmake --build "$build" --parallel "$(nproc)" --target "${targets[@]}" >&2
