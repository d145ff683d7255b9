#!/usr/bin/env bash
# The main job on the bundled default, hardware-free: fieldrigd replays a synthetic field as it
# would run in the field.
#  1. On the first run, `fieldrig simulate` makes the field in build/demo/field: 12 row plots on
#     2 serpentine rows rendered as the six cameras see them (raw Bayer, with the rig's
#     calibration), a simulated RTK drive over them (10 Hz RMC+GGA, 2 m/s, 1 cm noise), the map
#     of imaging locations and the truth of every plot. Kept for later runs (delete it to remake).
#  2. `fieldrigd replay --config config/replay.yaml` replays the drive in virtual time: the
#     planner triggers the sim cameras (which serve the rendered frames) at each location, every
#     set is recorded into build/demo/run and processed live (stereo → fused cloud → traits);
#     one JSON line per plot, and results/plots.{jsonl,csv,geojson} in the session.
#  3. The per-plot traits table, against the truth of the rendered plants.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${FIELDRIG_BUILD_DIR:-$root/build}
"$root/scripts/build.sh"
fieldrig="$build/tools/fieldrig"
fieldrigd="$build/daemon/fieldrigd"
demo="$build/demo"
field="$demo/field"

if [[ ! -s "$field/truth.jsonl" ]]; then
  echo "fieldrig demo: making the synthetic field in $field (first run only)" >&2
  rm -rf "$field"
  "$fieldrig" simulate --plots 12 --rows 2 --seed 7 --out "$field" >/dev/null
fi
rm -rf "$demo/run"
mkdir -p "$demo"
# config/replay.yaml names build/demo/...; another build folder is given on the command line.
"$fieldrigd" replay --config "$root/config/replay.yaml" --recording "$demo/run" \
  --nmea "$field/drive.nmea" --session "$field/source-session" --map "$field/map.csv" \
  --calibration "$field/source-session/calib" >"$demo/plots.jsonl"
echo "fieldrig demo: session $demo/run, results in $demo/run/results" >&2
python3 - "$demo/plots.jsonl" "$field/truth.jsonl" <<'PY'
import json, sys
plots = [json.loads(l) for l in open(sys.argv[1]) if '"traits"' in l]
truth = {j["plot"]: j for j in map(json.loads, open(sys.argv[2]))}
summary = [json.loads(l)["summary"] for l in open(sys.argv[1]) if l.startswith('{"summary"')][0]
print(f"{'plot':8} {'status':8} {'height m (truth)':>18} {'width m (truth)':>17} {'VVI (truth)':>14}")
def value(x):
    return float("nan") if x is None else x
for p in plots:
    t, tr = p["traits"], truth.get(p["plot"], {})
    print(f"{p['plot']:8} {t['status']:8} {value(t['height_m']):8.3f} ({tr.get('height_m', float('nan')):6.3f}) "
          f"{value(t['width_m']):7.3f} ({tr.get('width_m', float('nan')):6.3f}) "
          f"{value(t['vvi']):6.3f} ({tr.get('vvi', float('nan')):5.3f})")
print(f"{summary['triggers']} locations triggered, {summary['sets_recorded']} sets recorded, "
      f"{summary['sets_processed']} processed, {summary['missed']} missed")
PY
