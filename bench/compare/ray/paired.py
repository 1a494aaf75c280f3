#!/usr/bin/env python3
"""Runs compare_ray_paired (geods and Embree taking turns in one process) in
several processes, and prints per variant the median and range of the ratio
Embree's time / geods' over the processes (> 1: geods faster). The ratio of a
single process moves by a few per cent with where its memory lands; the median
of 10 or more moved by 1-3 % between runs on a shared 2-core VM.

With several programs (compare_ray_paired built from different geods trees),
their processes alternate, so that the drift of the machine is shared by
them too: an A/B of two versions of geods, each against Embree. It then
also prints, per program after the first, the median over rounds of its
ratio / the first program's in the same round.

  bench/compare/ray/paired.py --runs 10 --threads 1 --only 100k_incoherent \\
      build/compare/bin/compare_ray_paired [/tmp/compare_ray_paired_other ...]
"""
import argparse
import json
import os
import statistics
import subprocess

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("programs", nargs="*", default=[os.path.join(REPO, "build/compare/bin/compare_ray_paired")])
    ap.add_argument("--runs", type=int, default=10, help="processes per program")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--passes", type=int, default=4, help="passes over the rays per process (--reps)")
    ap.add_argument("--only", default="", help="variant substring, as the programs' --only")
    ap.add_argument("--data", default=os.path.join(REPO, "build/anchors-data"))
    args = ap.parse_args()
    ratios = {}  # (program, variant) -> [ratio per process]
    for run in range(args.runs):
        for prog in (args.programs if run % 2 == 0 else args.programs[::-1]):
            cmd = [prog, "--data", args.data, "--threads", str(args.threads), "--reps", str(args.passes)]
            if args.only:
                cmd += ["--only", args.only]
            out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
            for line in out.splitlines():
                rec = json.loads(line)
                if not rec["ok"]:
                    raise SystemExit(f"{prog}: the libraries disagree: {line}")
                ratios.setdefault((prog, rec["variant"]), []).append(rec["ratio"])
    print("variant\tprogram\tmedian\tmin\tmax\t(Embree's time / geods', one value per process)")
    for (prog, variant), r in sorted(ratios.items(), key=lambda kv: (kv[0][1], args.programs.index(kv[0][0]))):
        print(f"{variant}\t{prog}\t{statistics.median(r):.3f}\t{min(r):.3f}\t{max(r):.3f}")
    if len(args.programs) > 1:
        # Each round's processes ran back to back: their quotient cancels the
        # drift of the machine between rounds, which the medians above keep.
        print("variant\tprogram\tmedian\tmin\tmax\t(its ratio / the first program's, one value per round)")
        for variant in sorted({v for _, v in ratios}):
            first = ratios[(args.programs[0], variant)]
            for prog in args.programs[1:]:
                q = [a / b for a, b in zip(ratios[(prog, variant)], first)]
                print(f"{variant}\t{prog}\t{statistics.median(q):.3f}\t{min(q):.3f}\t{max(q):.3f}")


if __name__ == "__main__":
    main()
