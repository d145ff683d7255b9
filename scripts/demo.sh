#!/usr/bin/env bash
# The main job on the bundled default, hardware-free:
#  1. replays a simulated RTK drive (serpentine, 2 m/s, 10 Hz, 1 cm noise) against its
#     imaging-location map: the camera triggers go to build/demo/triggers.jsonl;
#  2. records a session of three synthetic row plots as the six-camera rig would (raw Bayer
#     frames, calibration, and the truth of the rendered plants in truth.jsonl);
#  3. processes that session: stereo → fused cloud → traits, one JSON line per plot, and
#     plots.csv / plots.geojson in build/demo/session/results.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${FIELDRIG_BUILD_DIR:-$root/build}
"$root/scripts/build.sh"
fieldrig="$build/tools/fieldrig"
demo="$build/demo"
rm -rf "$demo"
mkdir -p "$demo"

"$fieldrig" triggers --map "$root/sim/data/demo_map.csv" --nmea "$root/sim/data/demo_drive.nmea" \
  >"$demo/triggers.jsonl"
echo "fieldrig demo: $(wc -l <"$demo/triggers.jsonl") triggers in $demo/triggers.jsonl" >&2

"$fieldrig" sim plots --out "$demo/session" --count 3 >/dev/null
echo "fieldrig demo: truth of the synthetic plots: $demo/session/truth.jsonl" >&2
"$fieldrig" process "$demo/session"
