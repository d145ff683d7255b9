#!/usr/bin/env python3
"""Where the trait error comes from on the rendered mesh field (issue 11): stereo, or fusion, crop
and traits.

Makes (or reuses) a synthetic field as bench/mesh_field_bench.py does (`fieldrig simulate --plots N
--rows R --stage early,mid,mature --seed S`) and processes its session twice with the same
`fieldrig process` chain, differing only in where each head's depth comes from:
  (a) the truth: traits by their definitions on the plants' mesh surfaces that some camera sees
      (DIR/truth.jsonl; meshPlotTruth). Everything is measured against it, so it is the zero row;
      "(a'') stereo view" what stereo cannot place (the truth's `stereo_view` block: the same
      definitions on the samples both cameras of some head see; plant only one camera of a pair
      sees is in (a) but not in it);
      "(a') full geometry" shows what the view itself hides (the truth's `full` block: the same
      definitions on all of the plot's surfaces, seen or not).
  (b) `--depth-source truth`: each head's left camera's rendered truth depth map (beside every
      frame) as its disparity → the shipped chain after matching: edge filter (off by default),
      reprojection, fusion, crop and traits.
  (b') as (b) with the depth-edge filter on (the shipped config/fieldrigd.yaml with
      pipeline.cloud.edge_max_jump_px 2, off by default; left out when --process-args names a
      --config): what that filter would cost with perfect depth, where it drops the outermost
      leaf edges and tips.
  (c0) `--depth-source truth-where-matched`: stereo runs, then exactly the pixels it matched take
      the truth's depth (the others none).
  (c) stereo (SGBM, the rig's path), with `--score-stereo`.
(b) − (a) is what fusion, crop and the traits code cost with perfect depth; (c) − (b) is what
stereo costs, split into (c0) − (b), the pixels stereo leaves out, and (c) − (c0), the depth it
gets wrong on the pixels it keeps. For (b), (b') and (c), the near and far edges of each plot's box against the
truth's box say on which side of the row the width was lost or gained, and (c) against (c0) slice
by slice (the same pixels, each plot sliced over its length from the map) how many slice edges
stereo's depth errors alone move by more than 3 cm, outward and inward. Per trait: mean absolute
error, worst, bias (heights and widths in cm, VVI and VAI relative to the truth). Per head,
stereo against the per-pixel truth on vegetation pixels whose truth depth lies inside the depth
crop: the fraction matched, the bad-pixel rate (|disparity error| > 2 px at matching
resolution, of the matched ones) and the median depth error; and each head's points in the fused
cloud from (b) and (c). The last line is one JSON summary.

Usage: bench/attribution_bench.py [BUILD_DIR] [--plots 8] [--rows 2] [--seed 11] [--out DIR]
       [--process-args ARGS] [--traits-config FILE]
With --out the field and results stay in DIR and a field already there is reused (delete it to
remake); without it they go to a temporary folder. Rendering takes ~5-10 s a plot on 2 cores.
"""
import argparse
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile

from mesh_field_bench import (WITHIN_M, add_field_arguments, read_truth, rendered_field,
                              traits_config_args)

TRAITS = [("height_m", "height", "m"), ("width_m", "width", "m"), ("vvi", "VVI", ""),
          ("vai", "VAI", "")]


def stats(pairs, relative):
    """pairs: (measured, truth); errors in the unit, or relative (fraction of truth)."""
    errors = [((m - t) / t if relative else m - t) for m, t in pairs
              if t and m is not None]
    if not errors:
        return None
    return {"n": len(errors), "mean_abs": sum(abs(e) for e in errors) / len(errors),
            "max_abs": max(abs(e) for e in errors), "bias": sum(errors) / len(errors)}


def fmt(value, relative, signed=False):
    text = f"{100 * value:+.1f} {'%' if relative else 'cm'}"
    return text if signed else text[1:]


def read_results(path):
    lines = {}
    with open(path) as f:
        for line in f:
            j = json.loads(line)
            lines[j["plot"]] = j
    return lines


def process(fieldrig, field, out, extra, args):
    # --force replaces the results but not the plot clouds of an earlier run into the same folder,
    # which the slice comparison would otherwise take for this run's where a set wrote none.
    if os.path.isdir(out):
        for name in os.listdir(out):
            if name.endswith(".ply"):
                os.remove(os.path.join(out, name))
    subprocess.run([fieldrig, "process", os.path.join(field, "source-session"), "--map",
                    os.path.join(field, "map.csv"), "--out", out, "--force"] + extra +
                   traits_config_args(args) + shlex.split(args.process_args), check=True,
                   stdout=subprocess.DEVNULL)
    return read_results(os.path.join(out, "plots.jsonl"))


SLICE_BOUNDS_AGREE_M = 0.005  # slices of (c) and (c0) compared when both bounds agree this well


def plot_slices(fieldrig, cloud, traits_config):
    """The slices and width `fieldrig traits --json` gives one plot cloud written by --clouds;
    no slices when it measures nothing there (its status, or its error, says why)."""
    run = subprocess.run([fieldrig, "traits", "--cloud", cloud, "--json", "--config",
                          traits_config], capture_output=True, text=True)
    try:
        result = json.loads(run.stdout)
    except json.JSONDecodeError:
        print(f"{cloud}: fieldrig traits exited {run.returncode}: {run.stderr.strip()}",
              file=sys.stderr)
        return [], None
    return result.get("slices", []), result.get("width_m")


def slice_edge_table(fieldrig, work, plots, truth, from_coverage, coverage_dir, from_stereo,
                     stereo_dir, args):
    """(c) against (c0) slice by slice. Both clouds hold exactly the pixels stereo matched, (c0)
    with the truth's depth, so a slice edge more than 3 cm apart was moved by a wrong stereo depth
    and by nothing else: the stereo-caused share of slice edges, by side. Each run slices its own
    plants' extent along the row, which stereo's mismatches stretch (bounds 2-20 cm apart on
    rendered plots), so both clouds are sliced over the plot's own length from the map
    (crop_to_row_length, the trait definitions otherwise those of the processing) and only slices
    whose bounds agree are compared."""
    traits_config = os.path.join(work, "slice-comparison-traits.yaml")
    with open(traits_config, "w") as out:
        if args.traits_config:
            with open(args.traits_config) as f:
                text = f.read()
            # Appended as a YAML line: a JSON file, or one that sets the key already, would
            # come out invalid or with the key twice.
            if text.lstrip().startswith("{"):
                sys.exit(f"{args.traits_config}: the slice comparison needs a YAML traits config "
                         f"(it adds crop_to_row_length to it), not JSON")
            if "crop_to_row_length" in text:
                sys.exit(f"{args.traits_config}: crop_to_row_length is set here; the slice "
                         f"comparison sets it itself (true), so leave it out")
            out.write(text.rstrip("\n") + "\n")
        out.write("crop_to_row_length: true\n")
    print(f"\nSlice edges moved by stereo's depth alone: (c) stereo against (c0) truth depth on "
          f"the same pixels, {len(plots)} plots, each sliced over its length from the map "
          f"(crop_to_row_length; widths here by that definition), comparing the slices whose "
          f"bounds agree within {1000 * SLICE_BOUNDS_AGREE_M:.0f} mm. A far edge 'out' lies "
          f"> 3 cm farther from the cameras than (c0)'s, 'in' > 3 cm nearer; a near edge 'out' "
          f"> 3 cm nearer, 'in' > 3 cm farther (out widens the slice, in narrows it)"
          + ("; --process-args names a --config, whose traits options this does not read"
             if "--config" in args.process_args else ""))
    print("| plot | stage | width m: (c0) | (c) | slices compared | far out | far in | "
          "near out | near in |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    keys = ("far_out", "far_in", "near_out", "near_in")
    totals = dict.fromkeys(("slices", "compared") + keys, 0)
    per_plot = {}
    for p in plots:
        clouds = [os.path.join(directory, f"{p}_set{results.get(p, {}).get('set')}.ply")
                  for directory, results in ((stereo_dir, from_stereo),
                                             (coverage_dir, from_coverage))]
        if not all(os.path.exists(c) for c in clouds):
            print(f"| {p} | {truth[p].get('stage', '?')} | — | — | no cloud (not measured) "
                  f"| | | | |")
            continue
        (stereo_slices, stereo_width), (coverage_slices, coverage_width) = (
            plot_slices(fieldrig, c, traits_config) for c in clouds)
        counts = dict.fromkeys(totals, 0)
        counts["slices"] = len(stereo_slices)
        for stereo, coverage in zip(stereo_slices, coverage_slices):
            aligned = (abs(stereo["y_begin"] - coverage["y_begin"]) <= SLICE_BOUNDS_AGREE_M and
                       abs(stereo["y_end"] - coverage["y_end"]) <= SLICE_BOUNDS_AGREE_M)
            if not aligned or not stereo.get("points") or not coverage.get("points"):
                continue
            counts["compared"] += 1
            counts["far_out"] += stereo["z_max"] > coverage["z_max"] + WITHIN_M
            counts["far_in"] += stereo["z_max"] < coverage["z_max"] - WITHIN_M
            counts["near_out"] += stereo["z_min"] < coverage["z_min"] - WITHIN_M
            counts["near_in"] += stereo["z_min"] > coverage["z_min"] + WITHIN_M
        for key in totals:
            totals[key] += counts[key]
        per_plot[p] = dict(counts, width_c0_m=coverage_width, width_c_m=stereo_width)
        widths = " | ".join("—" if w is None else f"{w:.3f}"
                            for w in (coverage_width, stereo_width))
        print(f"| {p} | {truth[p].get('stage', '?')} | {widths} | "
              f"{counts['compared']} of {counts['slices']} | "
              + " | ".join(str(counts[k]) for k in keys) + " |")
    n = totals["compared"]
    print(f"| all | | | | {n} of {totals['slices']} | " + " | ".join(
        f"{totals[k]} ({100 * totals[k] / n:.0f} %)" if n else "0" for k in keys) + " |")
    return {"totals": totals, "plots": per_plot}


def main():
    parser = argparse.ArgumentParser()
    add_field_arguments(parser, plots=8)
    args = parser.parse_args()
    fieldrig = os.path.join(args.build, "tools", "fieldrig")
    work = args.out or tempfile.mkdtemp(prefix="attribution_bench_")
    field = rendered_field(fieldrig, args, work)
    truth = read_truth(field)
    from_truth = process(fieldrig, field, os.path.join(work, "results-truth-depth"),
                         ["--depth-source", "truth"], args)
    from_truth_edges = None
    if "--config" not in args.process_args:
        shipped = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config",
                               "fieldrigd.yaml")
        with open(shipped) as f:
            text, replaced = re.subn(r"edge_max_jump_px: *[0-9.]+", "edge_max_jump_px: 2",
                                     f.read())
        if replaced != 1:
            sys.exit(f"{shipped}: expected one edge_max_jump_px, found {replaced}")
        edges = os.path.join(work, "edge-filter.yaml")
        with open(edges, "w") as f:
            f.write(text)
        from_truth_edges = process(fieldrig, field,
                                   os.path.join(work, "results-truth-depth-edge-filter"),
                                   ["--depth-source", "truth", "--config", edges], args)
    # (c0) and (c) keep their plot clouds (--clouds) for the slice-by-slice comparison below.
    coverage_dir = os.path.join(work, "results-truth-where-matched")
    stereo_dir = os.path.join(work, "results-stereo")
    from_coverage = process(fieldrig, field, coverage_dir,
                            ["--depth-source", "truth-where-matched", "--clouds"], args)
    from_stereo = process(fieldrig, field, stereo_dir, ["--score-stereo", "--clouds"], args)
    for name, results in (("truth depth", from_truth), ("truth where matched", from_coverage),
                          ("stereo", from_stereo)):
        for plot in results:
            if plot not in truth:
                sys.exit(f"{plot} ({name}): not in the truth")
    plots = sorted(truth, key=lambda p: truth[p]["set"])

    print("| plot | stage | plants m | width m: truth | (a') full | (b) truth depth | "
          "(b') edge filter 2 px | (c0) truth where matched | (c) stereo |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for p in plots:
        t = truth[p]
        cells = [from_truth.get(p, {}).get("traits", {}).get("width_m"),
                 (from_truth_edges or {}).get(p, {}).get("traits", {}).get("width_m"),
                 from_coverage.get(p, {}).get("traits", {}).get("width_m"),
                 from_stereo.get(p, {}).get("traits", {}).get("width_m")]
        full = t.get("full", {}).get("width_m")
        print(f"| {p} | {t.get('stage', '?')} | {t['plant_height_m']:.2f} | {t['width_m']:.3f} | "
              + " | ".join("—" if v is None else f"{v:.3f}" for v in [full] + cells) + " |")

    rows = [
        ("(a) mesh truth (seen surfaces)", {p: truth[p] for p in plots}),
        ("(a') full geometry, seen or not", {p: truth[p].get("full", {}) for p in plots}),
        ("(a'') stereo view: seen by both cameras of a head",
         {p: truth[p].get("stereo_view", {}) for p in plots}),
        ("(b) truth depth → fusion → traits", {p: from_truth.get(p, {}).get("traits", {})
                                               for p in plots}),
        ("(b') truth depth, edge filter 2 px", {p: (from_truth_edges or {}).get(p, {})
                                               .get("traits", {}) for p in plots}),
        ("(c0) truth depth where SGBM matched", {p: from_coverage.get(p, {}).get("traits", {})
                                                for p in plots}),
        ("(c) SGBM → fusion → traits", {p: from_stereo.get(p, {}).get("traits", {})
                                        for p in plots}),
    ]
    summary = {"plots": len(plots), "rows": {}}
    print(f"\nAgainst the mesh truth, {len(plots)} plots: mean abs / worst / bias")
    print("| row | " + " | ".join(name for _, name, _ in TRAITS) + " |")
    print("| --- |" + " --- |" * len(TRAITS))
    for label, measured in rows:
        cells, row_summary = [], {}
        for key, _, unit in TRAITS:
            relative = unit == ""
            s = stats([(measured[p].get(key), truth[p][key]) for p in plots], relative)
            row_summary[key] = s
            cells.append("—" if s is None else
                         f"{fmt(s['mean_abs'], relative)} / {fmt(s['max_abs'], relative)} / "
                         f"{fmt(s['bias'], relative, True)}")
        summary["rows"][label.split(" ")[0]] = row_summary
        print(f"| {label} | " + " | ".join(cells) + " |")
    for name, (low, high), title in (
            ("stereo_cost", ("(b)", "(c)"), "stereo's share, (c) − (b)"),
            ("coverage_cost", ("(b)", "(c0)"), "of it, the pixels left out, (c0) − (b)"),
            ("depth_error_cost", ("(c0)", "(c)"), "of it, the depth on the kept ones, (c) − (c0)")):
        lo, hi = summary["rows"][low], summary["rows"][high]
        cost, cells = {}, []
        for key, _, unit in TRAITS:
            relative = unit == ""
            if lo.get(key) and hi.get(key):
                cost[key] = {"mean_abs": hi[key]["mean_abs"] - lo[key]["mean_abs"],
                             "bias": hi[key]["bias"] - lo[key]["bias"]}
                cells.append(f"{fmt(cost[key]['mean_abs'], relative, True)} mean abs, "
                             f"{fmt(cost[key]['bias'], relative, True)} bias")
            else:
                cells.append("—")
        summary[name] = cost
        print(f"| {title} | " + " | ".join(cells) + " |")

    # A width error is a near edge (toward the cameras) or a far edge out of place: each plot's
    # refined box against the truth's, so a fix can aim at the side that moved.
    print(f"\nWhere the width goes: each plot's box edges against the truth's (z_min, the near "
          f"edge; z_max, the far edge; + is away from the cameras), {len(plots)} plots: mean abs "
          f"/ worst / bias")
    print("| row | near edge | far edge |")
    print("| --- | --- | --- |")
    summary["edges"] = {}
    for label, measured in rows[3:]:
        cells, row_summary = [], {}
        for edge, key in (("near", "z_min"), ("far", "z_max")):
            s = stats([(measured[p].get("box", {}).get(key), truth[p].get(key + "_m"))
                       for p in plots], relative=False)
            if s is None:
                cells.append("—")
                continue
            row_summary[edge] = s
            cells.append(f"{fmt(s['mean_abs'], False)} / {fmt(s['max_abs'], False)} / "
                         f"{fmt(s['bias'], False, True)}")
        summary["edges"][label.split(" ")[0]] = row_summary
        print(f"| {label} | " + " | ".join(cells) + " |")

    summary["slice_edges"] = slice_edge_table(fieldrig, work, plots, truth, from_coverage,
                                              coverage_dir, from_stereo, stereo_dir, args)

    print("\nPer head, stereo against the per-pixel truth (vegetation pixels inside the depth crop; "
          "bad = |disparity error| > 2 px at matching resolution, of the matched pixels); "
          "points in the fused cloud, and of stereo's points those > 3 cm off the truth surface "
          "on their ray (or on sky), with the worst plot's share; the off points nearer and "
          "farther than the truth on their own ray, and the nearer ones whose truth lies beyond "
          "the depth crop")
    print("| head | plots seen | vegetation px | matched | bad | median abs depth error | "
          "median depth error | points (b) | points (c) | (c) off surface | worst plot | "
          "on sky | nearer | farther | from beyond the crop |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- "
          "| --- |")
    heads = {}
    for p in plots:
        for head in from_stereo.get(p, {}).get("heads", []):
            h = heads.setdefault(head["name"], {"plots": 0, "pixels": 0, "matched": 0.0,
                                                "bad": 0.0, "abs": [], "signed": [],
                                                "points_b": 0, "points_c": 0, "scored": 0,
                                                "off": 0.0, "sky": 0.0, "off_worst": 0.0,
                                                "nearer": 0.0, "farther": 0.0, "beyond": 0.0})
            h["points_c"] += head.get("points", 0)
            cloud_score = head.get("points_vs_truth")
            if cloud_score and cloud_score["points"]:
                n = cloud_score["points"]
                h["scored"] += n
                h["off"] += cloud_score["off_surface_3cm_fraction"] * n
                h["sky"] += cloud_score["on_sky_fraction"] * n
                # Sessions processed before the side of the truth was scored have no such keys.
                h["nearer"] += cloud_score.get("off_nearer_fraction", 0.0) * n
                h["farther"] += cloud_score.get("off_farther_fraction", 0.0) * n
                h["beyond"] += cloud_score.get("from_beyond_crop_fraction", 0.0) * n
                h["off_worst"] = max(h["off_worst"], cloud_score["off_surface_3cm_fraction"])
            score = head.get("stereo_vs_truth")
            if not score or not score["vegetation_pixels"]:
                continue
            n = score["vegetation_pixels"]
            h["plots"] += 1
            h["pixels"] += n
            h["matched"] += score["matched_fraction"] * n
            h["bad"] += score["bad_fraction"] * score["matched_fraction"] * n
            h["abs"].append(score["median_abs_depth_error_m"])
            h["signed"].append(score["median_depth_error_m"])
        for head in from_truth.get(p, {}).get("heads", []):
            if head["name"] in heads:
                heads[head["name"]]["points_b"] += head.get("points", 0)
    summary["heads"] = {}
    for name, h in heads.items():
        matched = h["matched"] / h["pixels"] if h["pixels"] else 0.0
        bad = h["bad"] / h["matched"] if h["matched"] else 0.0
        med_abs = statistics.median(h["abs"]) if h["abs"] else 0.0
        med = statistics.median(h["signed"]) if h["signed"] else 0.0
        off = h["off"] / h["scored"] if h["scored"] else 0.0
        sky = h["sky"] / h["scored"] if h["scored"] else 0.0
        nearer, farther, beyond = (h[k] / h["scored"] if h["scored"] else 0.0
                                   for k in ("nearer", "farther", "beyond"))
        summary["heads"][name] = {"plots": h["plots"], "vegetation_pixels": h["pixels"],
                                  "matched_fraction": matched, "bad_fraction": bad,
                                  "median_abs_depth_error_m": med_abs,
                                  "median_depth_error_m": med, "points_truth_depth": h["points_b"],
                                  "points_stereo": h["points_c"], "off_surface_3cm_fraction": off,
                                  "off_surface_worst_plot": h["off_worst"],
                                  "on_sky_fraction": sky, "off_nearer_fraction": nearer,
                                  "off_farther_fraction": farther,
                                  "from_beyond_crop_fraction": beyond}
        print(f"| {name} | {h['plots']} | {h['pixels']} | {100 * matched:.1f} % | "
              f"{100 * bad:.1f} % | {1000 * med_abs:.1f} mm | {1000 * med:+.1f} mm | "
              f"{h['points_b']} | {h['points_c']} | {100 * off:.1f} % | "
              f"{100 * h['off_worst']:.1f} % | {100 * sky:.2f} % | {100 * nearer:.1f} % | "
              f"{100 * farther:.1f} % | {100 * beyond:.1f} % |")
    print("(depth errors: the median over plots of each plot's median)")
    print(json.dumps({"summary": summary}))


if __name__ == "__main__":
    main()
