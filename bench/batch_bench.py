#!/usr/bin/env python3
"""Throughput of season reprocessing (`fieldrig batch`) on this machine, without Slurm.

Prints:
  - serial: `fieldrig process` over each session one after the other: plots per second on one
    core (wall time and the CPU time the processes used);
  - batch: the same sessions planned into --shards tasks and run with `batch run --jobs J`:
    plots per second, and per core (J cores busy);
  - overhead per task: a `fieldrig process` over a session it has already done (start-up, session
    index, calibration, processor set-up, results read back; no set processed), and the tasks'
    own load_s (sessions, calibration, processors) from their summary lines.
docs/season-scale.md turns these figures into cluster time for a season.

Usage: bench/batch_bench.py [BUILD_DIR] [--sessions N] [--plots P] [--shards S] [--jobs J]
Rendering the synthetic sessions takes ~2 s per plot; they are not timed.
"""
import argparse
import glob
import json
import os
import resource
import subprocess
import sys
import tempfile
import time


def children_cpu():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(cmd):
    cpu0, wall0 = children_cpu(), time.monotonic()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.monotonic() - wall0, children_cpu() - cpu0


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("build", nargs="?", default="build")
    parser.add_argument("--sessions", type=int, default=3)
    parser.add_argument("--plots", type=int, default=4, help="plots per session")
    parser.add_argument("--shards", type=int, default=4)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    fieldrig = os.path.abspath(os.path.join(args.build, "tools", "fieldrig"))
    with tempfile.TemporaryDirectory(prefix="fieldrig_batch_bench_") as work:
        sessions = []
        for i in range(args.sessions):
            path = os.path.join(work, f"day{i}")
            subprocess.run([fieldrig, "sim", "plots", "--out", path, "--count", str(args.plots),
                            "--seed", str(11 + i)], check=True, stdout=subprocess.DEVNULL)
            sessions.append(path)
        plots = args.sessions * args.plots

        serial_wall = serial_cpu = 0.0
        for path in sessions:
            wall, cpu = timed([fieldrig, "process", path, "--out", path + "-serial"])
            serial_wall += wall
            serial_cpu += cpu
        overhead = [timed([fieldrig, "process", path, "--out", path + "-serial"])
                    for path in sessions]

        job = os.path.join(work, "job")
        subprocess.run([fieldrig, "batch", "plan", *sessions, "--out", job,
                        "--shards", str(args.shards)], check=True, stdout=subprocess.DEVNULL)
        batch_wall, batch_cpu = timed([fieldrig, "batch", "run", job, "--jobs", str(args.jobs)])
        load, process = [], []
        for log in sorted(glob.glob(os.path.join(job, "logs", "task-*.local.log"))):
            for line in open(log):
                if line.startswith('{"summary"'):
                    summary = json.loads(line)["summary"]
                    load.append(summary["load_s"])
                    process.append(summary["process_s"])
        subprocess.run([fieldrig, "batch", "merge", job], check=True, stdout=subprocess.DEVNULL)

    cores = min(args.jobs, os.cpu_count() or 1)
    figures = {
        "machine": {"cpus": os.cpu_count(), "load_average_1min_at_end": os.getloadavg()[0]},
        "plots": plots,
        "serial": {"wall_s": round(serial_wall, 2), "cpu_s": round(serial_cpu, 2),
                   "plots_per_s_per_core": round(plots / serial_wall, 3),
                   "cpu_s_per_plot": round(serial_cpu / plots, 3)},
        "batch": {"shards": args.shards, "jobs": args.jobs, "wall_s": round(batch_wall, 2),
                  "cpu_s": round(batch_cpu, 2),
                  "plots_per_s": round(plots / batch_wall, 3),
                  "plots_per_s_per_core": round(plots / batch_wall / cores, 3),
                  "cpu_s_per_plot": round(batch_cpu / plots, 3),
                  "speed_up_over_serial": round(serial_wall / batch_wall, 2)},
        "overhead_per_task": {
            "process_start_with_nothing_to_do_wall_s": round(min(w for w, _ in overhead), 3),
            "process_start_with_nothing_to_do_cpu_s": round(min(c for _, c in overhead), 3),
            "task_load_s_mean": round(sum(load) / len(load), 3) if load else None,
            "task_process_s_mean": round(sum(process) / len(process), 3) if process else None},
    }
    print(json.dumps(figures, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
