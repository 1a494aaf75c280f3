#!/usr/bin/python3
"""2-thread speed-up of one comparison program, measured against the machine's own in the same run.

    bench/compare/probe/speedup.py PROGRAM [--only VARIANT] [--threads 2] [--rounds 3] [--reps 5]
                                   [--data DIR] [--probe build/compare/bin/scaling_probe] [--before OLD_PROGRAM]

Alternates, for --rounds rounds: PROGRAM at 1 thread, at N threads (and OLD_PROGRAM likewise with
--before), then scaling_probe's compute loop at 1 and N threads. Prints per program, variant and
metric the median time at 1 and N threads, the speed-up, the process's CPU time / wall time at N
threads, and the probe's speed-up in the same rounds: on a loaded machine a program can show no
more than the probe does, so compare the two. Also prints the load average before and after.
"""
import argparse
import json
import os
import statistics
import subprocess
import time


def run(cmd):
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    out = p.stdout.read()
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.monotonic() - t0
    return [json.loads(line) for line in out.splitlines() if line.startswith("{")], wall, ru.ru_utime + ru.ru_stime


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("program")
    ap.add_argument("--only")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--data", default="build/anchors-data")
    ap.add_argument("--probe", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                    "../../../build/compare/bin/scaling_probe"))
    ap.add_argument("--before", help="the same program from an older build, alternated with it")
    a = ap.parse_args()
    progs = [("now", a.program)] + ([("before", a.before)] if a.before else [])
    times = {}  # (label, anchor, variant, metric, threads) -> [s]
    cpu = {}  # (label, threads) -> [cpu / wall of the process]
    probe = {1: [], a.threads: []}
    load0 = os.getloadavg()
    for _ in range(a.rounds):
        for label, prog in progs:
            for t in (1, a.threads):
                cmd = [prog, "--data", a.data, "--threads", str(t), "--reps", str(a.reps)]
                if a.only:
                    cmd += ["--only", a.only]
                recs, wall, used = run(cmd)
                cpu.setdefault((label, t), []).append(used / wall)
                for r in recs:
                    for m in ("build_s", "query_s"):
                        if isinstance(r.get(m), (int, float)) and r[m] > 0:
                            times.setdefault((label, r["anchor"], r["variant"], m, t), []).append(r[m])
        if os.access(a.probe, os.X_OK):
            for t in probe:
                recs, _, _ = run([a.probe, "--threads", str(t), "--reps", "5", "--mb", "16"])
                probe[t] += [r["wall_s"] for r in recs if r.get("probe") == "compute"]
    load1 = os.getloadavg()
    print(f"load average {' / '.join(f'{x:.1f}' for x in load0)} -> {' / '.join(f'{x:.1f}' for x in load1)}")
    for (label, anchor, variant, m, t), v in sorted(times.items()):
        if t != 1:
            continue
        many = times.get((label, anchor, variant, m, a.threads))
        if not many:
            continue
        one, n = statistics.median(v), statistics.median(many)
        print(f"{label:6} {anchor} {variant!r} {m}: 1 thread {one:.4g} s, {a.threads} threads {n:.4g} s, "
              f"speed-up {one / n:.2f} (process CPU/wall at {a.threads} threads "
              f"{statistics.median(cpu[(label, a.threads)]):.2f})")
    if probe[1] and probe[a.threads]:
        print(f"probe compute loop: speed-up {statistics.median(probe[1]) / statistics.median(probe[a.threads]):.2f} "
              f"in the same rounds")


if __name__ == "__main__":
    main()
