#!/usr/bin/env python3
"""Whole-run benchmark of fieldrigd on a replay, hardware-free.

Prints, for this machine:
  - replay in virtual time: sets per second end to end (trigger -> traits written) and the latency
    from trigger to the plot's traits, against the baseline `fieldrig process` on the same
    recorded session (the same processor, offline, no rig or recorder) measured in the same run;
  - whether live processing keeps up with one plot every 2 s (a tractor at 2 m/s, 4 m plots);
  - memory over a long replay: resident set at 100 plots and at N plots (default 1,000);
  - daemon start to READY (systemd's notification, received on a socket of our own) and
    shutdown on SIGTERM with a set in flight.

Usage: bench/daemon_replay_bench.py [BUILD_DIR] [--plots N]
The 1,000-plot replay takes about 10 minutes on 2 cores (sets are processed as fast as they come).
"""
import argparse
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw)


def write_config(path, field, session_dir, nmea, map_file):
    with open(path, "w") as out:
        out.write(f"""map: {map_file}
calibration: {field}/source-session/calib
cameras:
  driver: sim
recording:
  dir: {session_dir}
  fsync: none
status:
  port: 0
replay:
  nmea: {nmea}
  session: {field}/source-session
""")


def status_port(proc_err_path, timeout=30):
    deadline = time.time() + timeout
    while time.time() < deadline:
        with open(proc_err_path) as err:
            for line in err:
                if line.startswith('{"status_url"'):
                    url = json.loads(line)["status_url"]
                    return int(url.split(":")[2].split("/")[0])
        time.sleep(0.05)
    raise RuntimeError("no status_url from fieldrigd")


def get_status(port):
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/status", timeout=5) as response:
        return json.loads(response.read())


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("build", nargs="?", default=os.path.join(os.path.dirname(__file__), "..", "build"))
    parser.add_argument("--plots", type=int, default=1000)
    parser.add_argument("--long-only", action="store_true", help="only the long replay (memory)")
    args = parser.parse_args()
    build = os.path.abspath(args.build)
    fieldrig = os.path.join(build, "tools", "fieldrig")
    fieldrigd = os.path.join(build, "daemon", "fieldrigd")
    work = tempfile.mkdtemp(prefix="fieldrigd_bench_")
    try:
        field = os.path.join(work, "field")
        run([fieldrig, "simulate", "--plots", "12", "--rows", "2", "--seed", "7", "--out", field])

        if not args.long_only:
            # 1. Throughput and latency on the 12-plot field, against `fieldrig process`.
            config = os.path.join(work, "replay.yaml")
            write_config(config, field, os.path.join(work, "run12"), f"{field}/drive.nmea", f"{field}/map.csv")
            t0 = time.monotonic()
            daemon = run([fieldrigd, "replay", "--config", config])
            daemon_s = time.monotonic() - t0
            summary = json.loads(daemon.stdout.strip().splitlines()[-1])["summary"]
            t0 = time.monotonic()
            run([fieldrig, "process", os.path.join(work, "run12"), "--out", os.path.join(work, "offline")])
            offline_s = time.monotonic() - t0
            sets = summary["sets_processed"]
            print(f"replay, virtual time, {sets} plots (12-plot synthetic field, 2 rows):")
            print(f"  fieldrigd replay        {daemon_s:6.2f} s whole process, {sets / daemon_s:5.2f} sets/s"
                  f" (in-daemon {summary['sets_per_s']:.2f} sets/s)")
            print(f"  fieldrig process (base) {offline_s:6.2f} s whole process, {sets / offline_s:5.2f} sets/s")
            print(f"  ratio daemon/offline throughput: {offline_s / daemon_s:.2f}")
            lat = summary.get("latency_ms", {})
            print(f"  trigger -> traits latency: mean {lat.get('mean', 0):.0f} ms, p95 {lat.get('p95', 0):.0f} ms,"
                  f" max {lat.get('max', 0):.0f} ms")
            per_plot_s = daemon_s / sets
            print(f"  keeps up with one plot every 2 s: {'yes' if per_plot_s < 2 else 'NO'}"
                  f" ({per_plot_s:.2f} s a plot, margin {2 / per_plot_s:.1f}x)")

        # 2. Memory over a long replay: the 12 rendered plots are served again and again by the
        # sim cameras (their replay wraps) at every location of a longer drive.
        rows = max(2, args.plots // 50)
        long_nmea, long_map = os.path.join(work, "long.nmea"), os.path.join(work, "long.csv")
        run([fieldrig, "sim", "drive", "--row-start", "42.0106,-93.7385", "--row-end", "42.0126,-93.7385",
             "--rows", str(rows), "--plots", str(args.plots // rows), "--plot-length", "3",
             "--alley-length", "1", "--row-spacing", "2.286", "--start-offset", "1", "--speed", "2",
             "--seed", "3", "--out-nmea", long_nmea, "--out-map", long_map])
        config_long = os.path.join(work, "long.yaml")
        write_config(config_long, field, os.path.join(work, "run_long"), long_nmea, long_map)
        err_path = os.path.join(work, "long.err")
        with open(err_path, "w") as err, open(os.path.join(work, "long.out"), "w") as out:
            proc = subprocess.Popen([fieldrigd, "replay", "--config", config_long, "--quiet"],
                                    stdout=out, stderr=err)
            port = status_port(err_path)
            rss_at = {}
            last = None
            t0 = time.monotonic()
            while proc.poll() is None:
                try:
                    s = get_status(port)
                except OSError:
                    break
                if s.get("starting"):
                    time.sleep(0.1)
                    continue
                processed = s["sets"]["processed"]
                last = (processed, s["memory"]["rss_mb"], s["memory"]["peak_rss_mb"])
                for mark in (100, 500, args.plots):
                    if processed >= mark and mark not in rss_at:
                        rss_at[mark] = (s["memory"]["rss_mb"], s["memory"]["peak_rss_mb"])
                time.sleep(0.5)
            proc.wait()
            long_s = time.monotonic() - t0
        with open(os.path.join(work, "long.out")) as out:
            lines = out.read().strip().splitlines()
        long_summary = json.loads(lines[-1])["summary"] if lines else {}
        print(f"long replay: {long_summary.get('locations')} locations, {long_summary.get('triggers')}"
              f" triggered, {long_summary.get('sets_processed')} plots processed in {long_s:.0f} s"
              f" ({long_summary.get('sets_per_s', 0):.2f} sets/s), {long_summary.get('missed')} missed,"
              f" peak RSS {long_summary.get('peak_rss_mb', 0):.0f} MB")
        if last and last[0] not in rss_at:
            rss_at[last[0]] = last[1:]
        for mark, (rss, peak) in sorted(rss_at.items()):
            print(f"  at {mark:5d} plots: RSS {rss:7.1f} MB, peak so far {peak:7.1f} MB")

        if not args.long_only:
            # 3. Start to READY, and shutdown on SIGTERM with a set in flight.
            notify_path = os.path.join(work, "notify.sock")
            notify = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
            notify.bind(notify_path)
            notify.settimeout(30)
            env = dict(os.environ, NOTIFY_SOCKET=notify_path)
            config_stop = os.path.join(work, "stop.yaml")
            write_config(config_stop, field, os.path.join(work, "run_stop"), f"{field}/drive.nmea", f"{field}/map.csv")
            t0 = time.monotonic()
            with open(os.path.join(work, "stop.out"), "w") as out, open(os.path.join(work, "stop.err"), "w") as err:
                proc = subprocess.Popen([fieldrigd, "replay", "--config", config_stop], stdout=out,
                                        stderr=err, env=env)
                ready_s = None
                while ready_s is None:
                    message = notify.recv(4096).decode()
                    if "READY=1" in message:
                        ready_s = time.monotonic() - t0
                time.sleep(1.5)  # a few sets in, one in flight
                t1 = time.monotonic()
                proc.send_signal(signal.SIGTERM)
                code = proc.wait(timeout=60)
                stop_s = time.monotonic() - t1
            print(f"start to READY: {ready_s * 1000:.0f} ms; SIGTERM to exit with a set in flight:"
                  f" {stop_s * 1000:.0f} ms (exit {code})")
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
