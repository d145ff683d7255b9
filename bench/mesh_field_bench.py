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

Usage: bench/mesh_field_bench.py [BUILD_DIR] [--plots 24] [--rows 2] [--seed 11] [--out DIR]
       [--keep] [--process-args ARGS] [--traits-config FILE]
--traits-config sets the trait definitions of both the truth and the processing. With --out the
field and results stay in DIR and a field already there is reused (delete it to remake; one made
with other traits options is refused); without it they go to a temporary folder. Rendering
takes ~5-10 s a plot on 2 cores.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile

TRAITS = [("height_m", "height", "m"), ("width_m", "width", "m"), ("vvi", "VVI", ""),
          ("vai", "VAI", "")]


def stats(pairs, relative):
    """pairs: (measured, truth); errors in the unit, or relative (fraction of truth)."""
    errors = [((m - t) / t if relative else m - t) for m, t in pairs if t]
    if not errors:
        return None
    return {
        "n": len(errors),
        "mean_abs": sum(abs(e) for e in errors) / len(errors),
        "max_abs": max(abs(e) for e in errors),
        "bias": sum(errors) / len(errors),
    }


def table(rows, title):
    print(f"\n{title}")
    print("| trait | plots | mean abs | worst | bias |")
    print("| --- | --- | --- | --- | --- |")
    out = {}
    for key, name, unit in TRAITS:
        relative = unit == ""
        s = stats([(r["measured"][key], r["truth"][key]) for r in rows
                   if r["measured"].get(key) is not None], relative)
        if s is None:
            continue
        out[key] = s
        fmt = (lambda v: f"{100 * v:+.1f} %") if relative else (lambda v: f"{100 * v:+.1f} cm")
        print(f"| {name} | {s['n']} | {fmt(s['mean_abs'])[1:]} | {fmt(s['max_abs'])[1:]} | "
              f"{fmt(s['bias'])} |")
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


def main():
    parser = argparse.ArgumentParser()
    add_field_arguments(parser, plots=24)
    args = parser.parse_args()
    fieldrig = os.path.join(args.build, "tools", "fieldrig")
    work = args.out or tempfile.mkdtemp(prefix="mesh_field_bench_")
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
        cells = [f"{m.get(k, float('nan')):.3f} ({t[k]:.3f})" for k, _, _ in TRAITS]
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
    print(json.dumps({"summary": summary}))


if __name__ == "__main__":
    main()
