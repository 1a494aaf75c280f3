#!/usr/bin/python3
"""2-thread speed-up of one comparison program, measured against the machine's own in the same run.

    bench/compare/probe/speedup.py PROGRAM [--only VARIANT] [--threads 2] [--rounds 3] [--reps 5]
                                   [--data DIR] [--probe build/compare/bin/scaling_probe] [--before OLD_PROGRAM]

Alternates, for --rounds rounds: scaling_probe's compute loop at 1 and N threads, PROGRAM at 1 and
N threads (and OLD_PROGRAM likewise with --before), the probe again. Prints per program, variant and
metric the median time at 1 and N threads, the speed-up, the process's CPU time / wall time at N
threads, and the probe's speed-up in the same rounds: on a loaded machine a program can show no
more than the probe does, so compare the two. With --quiet X, only the rounds whose probe speed-up
(before and after) is at least X count (rounds on a machine that had the cores free).
Also prints the load average before and after.
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
    ap.add_argument("--quiet", type=float, default=0.0, help="keep only rounds whose probe speed-up is >= this")
    a = ap.parse_args()
    progs = [("now", a.program)] + ([("before", a.before)] if a.before else [])
    times = {}  # (label, anchor, variant, metric, threads) -> [s]
    cpu = {}  # (label, threads) -> [cpu / wall of the process]
    probes = []
    kept = 0

    def probe_speedup():
        if not os.access(a.probe, os.X_OK):
            return None
        w = {}
        for t in (1, a.threads):
            recs, _, _ = run([a.probe, "--threads", str(t), "--reps", "5", "--mb", "16"])
            w[t] = [r["wall_s"] for r in recs if r.get("probe") == "compute"][0]
        return w[1] / w[a.threads]

    load0 = os.getloadavg()
    for rnd in range(a.rounds):
        p0 = probe_speedup()
        round_times, round_cpu = {}, {}
        for label, prog in progs:
            for t in (1, a.threads):
                cmd = [prog, "--data", a.data, "--threads", str(t), "--reps", str(a.reps)]
                if a.only:
                    cmd += ["--only", a.only]
                recs, wall, used = run(cmd)
                round_cpu.setdefault((label, t), []).append(used / wall)
                for r in recs:
                    for m in ("build_s", "query_s"):
                        if isinstance(r.get(m), (int, float)) and r[m] > 0:
                            round_times.setdefault((label, r["anchor"], r["variant"], m, t), []).append(r[m])
        p1 = probe_speedup()
        quiet = p0 is None or min(p0, p1) >= a.quiet
        line = ", ".join(f"{k[0]} {k[2]} {k[3]} {v[0] / round_times[k[:4] + (a.threads,)][0]:.2f}"
                         for k, v in round_times.items() if k[4] == 1 and k[:4] + (a.threads,) in round_times)
        print(f"round {rnd + 1}: probe {p0 and f'{p0:.2f}'} / {p1 and f'{p1:.2f}'}"
              f"{'' if quiet else ' (loaded: not kept)'}: {line}", flush=True)
        if quiet:
            kept += 1
            probes += [x for x in (p0, p1) if x]
            for k, v in round_times.items():
                times.setdefault(k, []).extend(v)
            for k, v in round_cpu.items():
                cpu.setdefault(k, []).extend(v)
    load1 = os.getloadavg()
    print(f"load average {' / '.join(f'{x:.1f}' for x in load0)} -> {' / '.join(f'{x:.1f}' for x in load1)}; "
          f"{kept} of {a.rounds} rounds kept")
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
    if probes:
        print(f"probe compute loop: speed-up {statistics.median(probes):.2f} in the kept rounds")


if __name__ == "__main__":
    main()
