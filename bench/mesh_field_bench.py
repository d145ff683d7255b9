#!/usr/bin/env python3
"""End-to-end accuracy on the rendered mesh field (issue 11): the baseline stereo fixes are
measured against.

Makes (or reuses) a synthetic field with the Embree mesh renderer, `fieldrig simulate --plots N
--rows R --stage early,mid,mature --seed S`, processes its session with `fieldrig process`, and
prints per plot and per trait (height, width, VVI, VAI) the error against the mesh truth
(DIR/truth.jsonl): mean absolute, worst, bias; over all plots, over the plots whose plants stay
inside the rig's field of view (truth `exceeds_view` false), those again against the truth of
what both cameras of a head see (`stereo_view`: what stereo can place at all, where the main
truth counts what any camera sees), and per growth stage. The last line is one JSON summary.

With --seeds S1,S2,... it does this on one field per seed (DIR/seed-S each) and ends with the
fields side by side: per field, height and width of the in-view plots against both truths and how
many plots are within 3 cm (issue 11's bound is every plot), then all fields pooled; and how far
the heights are off by the plot's slice top spread (quality.slice_top_spread_m), which says when
a height is to be trusted; the widths' pooled error spread (median, 90th percentile, plots
within 3 and 6 cm); and VVI and VAI by growth stage against issue 11's bounds, with VAI's
two factors (total area and effective ground area) as ratios to the truth's. Seeds the defaults
were not tuned on make it a held-out check.

Usage: bench/mesh_field_bench.py [BUILD_DIR] [--plots 24] [--rows 2] [--seed 11 | --seeds 11,12]
       [--out DIR] [--process-args ARGS] [--traits-config FILE]
--traits-config sets the trait definitions of both the truth and the processing. With --out the
field and results stay in DIR and a field already there is reused (delete it to remake; one made
with other traits options is refused); without it they go to a temporary folder. Rendering
takes ~5-10 s a plot on 2 cores.
"""
import argparse
import copy
import json
import os
import shlex
import statistics
import subprocess
import sys
import tempfile

TRAITS = [("height_m", "height", "m"), ("width_m", "width", "m"), ("vvi", "VVI", ""),
          ("vai", "VAI", "")]
WITHIN_M = 0.03  # issue 11: height and width within 3 cm on every plot
WITHIN_RELATIVE = {"vvi": 0.15, "vai": 0.20}  # issue 11: VVI within 15 %, VAI within 20 %
WIDTH_SPREAD_WITHIN_M = 0.06  # the width table's second count: twice issue 11's bound
# The truths a plot's traits are scored against: what some camera sees (the truth's own traits)
# and what both cameras of a head see (stereo_view: what stereo can place at all).
TRUTH_VIEWS = (("seen", lambda r: r["truth"]),
               ("stereo_view", lambda r: r["truth"].get("stereo_view", {})))


def count_unmeasured(pairs):
    """Plots with a truth whose measurement is missing (the processing could not measure them)."""
    return sum(1 for m, t in pairs if t and m is None)


def stats(pairs, relative, within=None):
    """pairs: (measured, truth); errors in the unit, or relative (fraction of truth). A plot the
    processing could not measure (measured None) is counted as unmeasured, never left out
    silently: within_3cm is out of measured and unmeasured plots alike. With `within`, also how
    many errors are within that bound (in the errors' unit)."""
    errors = [((m - t) / t if relative else m - t) for m, t in pairs if t and m is not None]
    unmeasured = count_unmeasured(pairs)
    if not errors:
        return None
    magnitudes = [abs(e) for e in errors]
    return {
        "n": len(errors),
        "unmeasured": unmeasured,
        "mean_abs": sum(magnitudes) / len(errors),
        "median_abs": statistics.median(magnitudes),
        # The error nine plots in ten stay within (inclusive: from the smallest to the largest).
        "p90_abs": (statistics.quantiles(magnitudes, n=10, method="inclusive")[-1]
                    if len(magnitudes) > 1 else magnitudes[0]),
        "max_abs": max(magnitudes),
        "bias": sum(errors) / len(errors),
        "within_3cm": None if relative else sum(m <= WITHIN_M for m in magnitudes),
        **({} if within is None else {"within": sum(m <= within for m in magnitudes)}),
    }


def table(rows, title):
    print(f"\n{title}")
    print("| trait | plots | mean abs | worst | bias |")
    print("| --- | --- | --- | --- | --- |")
    out = {}
    for key, name, unit in TRAITS:
        relative = unit == ""
        pairs = [(r["measured"].get(key), r["truth"][key]) for r in rows]
        s = stats(pairs, relative)
        if s is None:
            unmeasured = count_unmeasured(pairs)
            if unmeasured:
                print(f"| {name} | 0 (+{unmeasured} unmeasured) | - | - | - |")
            continue
        out[key] = s
        fmt = (lambda v: f"{100 * v:+.1f} %") if relative else (lambda v: f"{100 * v:+.1f} cm")
        unmeasured = f" (+{s['unmeasured']} unmeasured)" if s["unmeasured"] else ""
        print(f"| {name} | {s['n']}{unmeasured} | {fmt(s['mean_abs'])[1:]} | "
              f"{fmt(s['max_abs'])[1:]} | {fmt(s['bias'])} |")
    return out


def add_field_arguments(parser, plots):
    """The options every bench on the rendered field takes (also attribution_bench.py)."""
    parser.add_argument("build", nargs="?", default="build")
    parser.add_argument("--plots", type=int, default=plots)
    parser.add_argument("--rows", type=int, default=2)
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--out")
    parser.add_argument("--process-args", default="")
    parser.add_argument("--traits-config", default="",
                        help="traits options (YAML) for the truth and the processing alike")


def traits_config_args(args):
    """`--traits-config FILE` for fieldrig simulate and process, or nothing."""
    return ["--traits-config", args.traits_config] if args.traits_config else []


def read_text(path):
    if not path or not os.path.exists(path):
        return ""
    with open(path) as f:
        return f.read()


def rendered_field(fieldrig, args, work):
    """WORK/field, rendered by `fieldrig simulate` unless a field is already there."""
    field = os.path.join(work, "field")
    # The truth's trait definitions are fixed when the field is rendered: a field is reused only
    # with the traits options it was made with (a copy is kept beside it).
    definitions = os.path.join(work, "field-traits-config.yaml")
    wanted = read_text(args.traits_config)
    if not os.path.exists(os.path.join(field, "truth.jsonl")):
        subprocess.run([fieldrig, "simulate", "--plots", str(args.plots), "--rows", str(args.rows),
                        "--seed", str(args.seed), "--stage", "early,mid,mature", "--out", field] +
                       traits_config_args(args), check=True, stdout=subprocess.DEVNULL)
        with open(definitions, "w") as f:
            f.write(wanted)
    elif read_text(definitions) != wanted:
        sys.exit(f"{field}: its truth was made with other traits options ({definitions}) than "
                 f"--traits-config '{args.traits_config}'; use another --out")
    return field


def read_truth(field):
    """The field's per-plot truth lines by plot id."""
    truth = {}
    with open(os.path.join(field, "truth.jsonl")) as f:
        for line in f:
            j = json.loads(line)
            truth[j["plot"]] = j
    return truth


def measure_field(fieldrig, args, work):
    """Render (or reuse) WORK/field, process it, print its tables; the rows and the summary."""
    field = rendered_field(fieldrig, args, work)
    results = os.path.join(work, "results")
    subprocess.run([fieldrig, "process", os.path.join(field, "source-session"), "--map",
                    os.path.join(field, "map.csv"), "--out", results, "--force"] +
                   traits_config_args(args) + shlex.split(args.process_args), check=True,
                   stdout=subprocess.DEVNULL)
    truth = read_truth(field)
    rows = []
    with open(os.path.join(results, "plots.jsonl")) as f:
        for line in f:
            j = json.loads(line)
            t = truth.get(j["plot"])
            if t is None:
                sys.exit(f"{j['plot']}: not in the truth")
            rows.append({"plot": j["plot"], "stage": t.get("stage", "?"),
                         "in_view": not t.get("exceeds_view", False), "truth": t,
                         "measured": j["traits"]})
    rows.sort(key=lambda r: r["truth"]["set"])
    print("| plot | stage | plants m | in view | status | height m (truth) | width m (truth) | "
          "VVI (truth) | VAI (truth) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        m, t = r["measured"], r["truth"]
        # A plot the processing could not measure (its status says why) has no traits: "-".
        cells = [f"{'-' if m.get(k) is None else format(m[k], '.3f')} ({t[k]:.3f})"
                 for k, _, _ in TRAITS]
        print(f"| {r['plot']} | {r['stage']} | {t['plant_height_m']:.2f} | "
              f"{'yes' if r['in_view'] else 'no'} | {m['status']} | " + " | ".join(cells) + " |")
    summary = {"plots": len(rows), "all": table(rows, "All plots")}
    inside = [r for r in rows if r["in_view"]]
    summary["in_view"] = table(inside, "Plots inside the field of view")
    # The same plots against the truth on what both cameras of some head see (what stereo can
    # place at all); fields simulated before that truth existed have no `stereo_view`.
    stereo_view = [dict(r, truth=r["truth"]["stereo_view"]) for r in inside
                   if "stereo_view" in r["truth"]]
    if stereo_view:
        summary["in_view_stereo_view"] = table(
            stereo_view, "Plots inside the field of view, against the stereo-view truth "
            "(plant both cameras of a head see)")
    for stage in ("early", "mid", "mature"):
        summary[stage] = table([r for r in rows if r["stage"] == stage], f"Stage {stage}")
    return rows, summary


def length_cells(rows, key):
    """mean abs / worst / bias in cm and the plots within 3 cm, for height_m or width_m."""
    pairs = [(r["measured"].get(key), r["truth"][key]) for r in rows]
    s = stats(pairs, False)
    if s is None:
        # No plot measured: the group still says how many plots it had, in both of its columns.
        unmeasured = count_unmeasured(pairs)
        return (f"- | 0 of {unmeasured} ({unmeasured} unmeasured)" if unmeasured else "- | -"), None
    unmeasured = f" ({s['unmeasured']} unmeasured)" if s["unmeasured"] else ""
    return (f"{100 * s['mean_abs']:.1f} / {100 * s['max_abs']:.1f} / {100 * s['bias']:+.1f} | "
            f"{s['within_3cm']} of {s['n'] + s['unmeasured']}{unmeasured}"), s


def across_fields(per_seed):
    """The fields side by side (in-view plots) and pooled, and heights by slice top spread."""
    print("\nIn-view plots of every field: mean abs / worst / bias (cm) | plots within 3 cm")
    print("| field seed | height vs seen | | height vs stereo view | | width vs seen | | "
          "width vs stereo view | |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    out = {}
    pooled = []
    for seed, rows in list(per_seed.items()) + [("all", None)]:
        inside = [r for r in (rows if rows is not None else pooled) if r["in_view"]]
        if rows is not None:
            pooled += rows
        sv = [dict(r, truth=r["truth"]["stereo_view"]) for r in inside
              if "stereo_view" in r["truth"]]
        cells, out[str(seed)] = [], {}
        for name, group in (("seen", inside), ("stereo_view", sv)):
            for key in ("height_m", "width_m"):
                text, s = length_cells(group, key)
                cells.append((key, name, text))
                out[str(seed)][f"{key}_vs_{name}"] = s
        order = [("height_m", "seen"), ("height_m", "stereo_view"), ("width_m", "seen"),
                 ("width_m", "stereo_view")]
        texts = {(k, n): t for k, n, t in cells}
        print(f"| {seed} | " + " | ".join(texts[o] for o in order) + " |")
    # How the width's errors spread, pooled: issue 11 bounds every plot, and a few plots decide
    # the worst case; the median and 90th percentile say what most plots get.
    print("\nIn-view widths of every field, pooled: absolute error (cm) | plots within 3 and 6 cm")
    print("| truth | plots | mean | median | 90th percentile | worst | within 3 cm | within 6 cm |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    out["width_spread"] = {}
    inside = [r for r in pooled if r["in_view"]]
    for name, truth_of in TRUTH_VIEWS:
        s = stats([(r["measured"].get("width_m"), truth_of(r).get("width_m")) for r in inside],
                  False, within=WIDTH_SPREAD_WITHIN_M)
        out["width_spread"][name] = s
        if s is None:
            print(f"| {name} | 0 | - | - | - | - | - | - |")
            continue
        print(f"| {name} | {s['n'] + s['unmeasured']} | {100 * s['mean_abs']:.1f} | "
              f"{100 * s['median_abs']:.1f} | {100 * s['p90_abs']:.1f} | {100 * s['max_abs']:.1f} | "
              f"{s['within_3cm']} | {s['within']} |")
    # A height whose slices disagree (a gap, an off-type tall plant) sits on one of two levels.
    print("\nIn-view heights against the seen truth by the plot's slice top spread")
    print("| slice top spread | plots | mean abs | worst | within 3 cm |")
    print("| --- | --- | --- | --- | --- |")
    out["height_by_top_spread"] = []
    inside = [r for r in pooled if r["in_view"] and r["measured"].get("height_m") is not None]
    for low, high in ((0.0, 0.05), (0.05, 0.10), (0.10, 0.20), (0.20, float("inf"))):
        band = [r for r in inside
                if low <= r["measured"]["quality"].get("slice_top_spread_m", 0.0) < high]
        s = stats([(r["measured"]["height_m"], r["truth"]["height_m"]) for r in band], False)
        label = f"{100 * low:.0f}-{100 * high:.0f} cm" if high != float("inf") else \
            f"over {100 * low:.0f} cm"
        if s is None:
            print(f"| {label} | 0 | - | - | - |")
            continue
        print(f"| {label} | {s['n']} | {100 * s['mean_abs']:.1f} cm | {100 * s['max_abs']:.1f} cm "
              f"| {s['within_3cm']} |")
        out["height_by_top_spread"].append(dict(s, spread_from_m=low, spread_to_m=high))
    out["indices_by_stage"] = indices_by_stage(pooled)
    return out


def indices_by_stage(pooled):
    """VVI and VAI of the in-view plots of every field, per stage, against both truths, with how
    many are within issue 11's bounds; and VAI's two factors against the seen truth: VAI is the
    total vegetation area over the effective ground area (EGA), so a VAI off by stage says
    whether the area or the EGA (width, row extent, valid slices) is off."""
    print("\nIn-view VVI and VAI of every field by stage: mean abs / worst / bias (%) | plots within "
          "15 % (VVI) or 20 % (VAI); VAI's factors as the median ratio measured / seen truth")
    print("| stage | VVI vs seen | | VVI vs stereo view | | VAI vs seen | | VAI vs stereo view | | "
          "area ratio | EGA ratio |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    out = {}
    inside = [r for r in pooled if r["in_view"]]
    for stage in ("early", "mid", "mature", "all"):
        rows = [r for r in inside if stage in ("all", r["stage"])]
        if not rows:
            continue
        cells, out[stage] = [], {}
        for key in ("vvi", "vai"):
            for view, truth_of in TRUTH_VIEWS:
                pairs = [(r["measured"].get(key), truth_of(r).get(key)) for r in rows]
                s = stats(pairs, True, within=WITHIN_RELATIVE[key])
                if s is None:
                    cells.append("- | -")
                    continue
                out[stage][f"{key}_vs_{view}"] = s
                cells.append(f"{100 * s['mean_abs']:.1f} / {100 * s['max_abs']:.1f} / "
                             f"{100 * s['bias']:+.1f} | {s['within']} of {s['n'] + s['unmeasured']}")
        factors = []
        for measured_key, truth_key in (("total_area_m2", "visible_area_in_box_m2"),
                                        ("ega_m2", "ega_m2")):
            ratios = [r["measured"][measured_key] / r["truth"][truth_key] for r in rows
                      if r["measured"].get(measured_key) is not None and r["truth"].get(truth_key)]
            ratio = statistics.median(ratios) if ratios else None
            out[stage][f"{measured_key}_ratio"] = ratio
            factors.append("-" if ratio is None else f"{ratio:.2f}")
        print(f"| {stage} | " + " | ".join(cells + factors) + " |")
    return out


def main():
    parser = argparse.ArgumentParser()
    add_field_arguments(parser, plots=24)
    parser.add_argument("--seeds", default="",
                        help="comma-separated seeds: one field each, then all side by side")
    args = parser.parse_args()
    fieldrig = os.path.join(args.build, "tools", "fieldrig")
    work = args.out or tempfile.mkdtemp(prefix="mesh_field_bench_")
    if not args.seeds:
        _, summary = measure_field(fieldrig, args, work)
        print(json.dumps({"summary": summary}))
        return
    try:
        seeds = [int(s) for s in args.seeds.split(",")]
    except ValueError:
        sys.exit(f"--seeds {args.seeds}: not a comma-separated list of integers")
    per_seed, summaries = {}, {}
    for seed in seeds:
        print(f"\n## Field seed {seed}")
        seed_args = copy.copy(args)
        seed_args.seed = seed
        per_seed[seed], summaries[str(seed)] = measure_field(
            fieldrig, seed_args, os.path.join(work, f"seed-{seed}"))
    print(json.dumps({"summary": {"fields": summaries, "across": across_fields(per_seed)}}))


if __name__ == "__main__":
    main()
