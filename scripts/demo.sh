#!/usr/bin/env bash
# The main job on the bundled default: replays a simulated RTK drive (serpentine, 2 m/s, 10 Hz,
# 1 cm noise) against its imaging-location map and prints one JSON line per camera trigger.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${FIELDRIG_BUILD_DIR:-$root/build}
"$root/scripts/build.sh"
exec "$build/tools/fieldrig" triggers --map "$root/sim/data/demo_map.csv" \
  --nmea "$root/sim/data/demo_drive.nmea" "$@"
