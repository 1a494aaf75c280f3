#!/usr/bin/python3
"""Side-by-side benchmarks of geods against the anchor libraries -> docs/PERFORMANCE.md.

    /usr/bin/python3 bench/compare/run.py --out docs/PERFORMANCE.md [--only predicates,knn]
        [--threads 1,2] [--rounds 1] [--reps 3] [--scale 1] [--jobs N] [--data DIR]
        [--no-setup] [--no-micro] [--before DIR[=LABEL]]

Steps: (a) scripts/setup.sh --bench (installs the anchor packages, bench/compare/anchor-packages.txt),
(b) bench/compare/gen_workloads.py (generates the workloads of anchors/WORKLOADS.md once, checks
their hashes), (c) configures and builds the separate CMake project bench/compare into
build/compare (ccache), (d) runs each comparison's programs interleaved (geods, anchor, ...,
geods, anchor, ... for --rounds rounds) with one thread and with all threads, collecting their
JSON lines, (e) runs the Google Benchmark programs build/release/bin/geods_*_bench if present,
(f) writes the report (--out), the raw JSON lines beside it (performance.jsonl) and when and how
each workload was measured (performance-runs.json).

With --before DIR=LABEL (DIR: the build/compare/bin of an older checkout, LABEL: its revision), every
geods program found there is run too, interleaved with the others, as anchor "<anchor>@before"; its
ratio column is then its time / the same program's time now (> 1: faster now), so that a change
shows before/after ratios measured in one run.

With --report-only, nothing is built or run: the report is rewritten from performance.jsonl and
performance-runs.json (after merging the results of separate runs, say).

With --only W --update, only W is re-run; the other workloads (and, with --no-micro, the micro
benchmarks) keep their earlier results from performance.jsonl / performance-runs.json, and each
section of the report says which run measured it. Ratios are still taken within one run.

A comparison is a folder bench/compare/<workload>/ holding its programs, a CMakeLists.txt that
declares them with geods_compare_program(), and a compare.json read here:

  workload    name, equal to the "workload" field of the JSON lines (and --only)
  title       section title;  about: one paragraph of Markdown (what is timed, inputs, checks)
  programs    [{"anchor": "geods", "program": "compare_<workload>_geods"},
               {"anchor": "cgal", "program": "...", "label": "CGAL Epick", "package": "libcgal-dev"}, ...]
              run in this order; the first one is the baseline of the ratios (geods).
              Instead of "program" (a target of the CMake project, in build/compare/bin), an entry
              may give "command": ["{python}", "{dir}/edt_scipy.py"] (placeholders: {python} =
              /usr/bin/python3, {dir} = the comparison folder, {bin} = build/compare/bin); it gets
              the same arguments and must print the same JSON lines.
  threads     "all": run with every --threads count; "1": single thread only
  metrics     timing fields to tabulate, e.g. ["build_s", "query_s"]
  values      optional fields that are not times (an error, say), tabulated after the metrics with
              the same ratio columns but left out of the geometric means
  rate        optional {"unit": "Mcalls/s", "scale": 1e-6, "metric": "query_s"}: also show
              count / time * scale in the rows of that metric (default query_s)
  agree       optional {"field": "sign_hash", "anchors": ["geods", "cgal"], "label": "..."}:
              that field must be equal across these anchors for each (variant, threads)
  args        optional extra command-line arguments for every program (a program entry may add its
              own "args", e.g. ["--reps", "1"] for a peer that takes minutes)
  rounds      optional number of interleaved rounds when --rounds is not given (default 1)
  timeout_s   optional per-program time limit (default 1800)
  scaling     optional [{"anchor": "geods", "variant": "iso 1.8", "metric": "build_s", "note": "..."}]:
              the measured reason for a geods program's speed-up on all cores (anchor: a name or a
              list of names; variant and metric: the same, left out to match all), shown in the
              "why" column of the All-cores table

Every program takes --data DIR --threads N --reps N [--scale X] and prints one JSON line per
measurement: {"workload","anchor","variant","threads","build_s","query_s","count","median_of",...,"ok"}.
The ratio in the tables is anchor time / geods time: > 1 means geods is faster.
Standard library only.
"""
import argparse
import datetime
import glob
import json
import math
import os
import platform
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
PY = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable


def log(*a):
    print("[bench]", *a, flush=True)


def rel(path):
    return os.path.relpath(path, REPO)


# ----------------------------------------------------------------------------- comparisons
def discover():
    """All comparisons: bench/compare/*/compare.json, sorted by folder name."""
    comps = []
    for path in sorted(glob.glob(os.path.join(HERE, "*", "compare.json"))):
        with open(path) as f:
            c = json.load(f)
        for key in ("workload", "title", "programs", "metrics"):
            if key not in c:
                raise SystemExit(f"{rel(path)}: missing key '{key}'")
        c.setdefault("about", "")
        c.setdefault("threads", "all")
        c.setdefault("args", [])
        c.setdefault("timeout_s", 1800)
        c.setdefault("rounds", 1)
        c["dir"] = os.path.dirname(path)
        comps.append(c)
    return comps


BEFORE = "@before"  # anchor suffix of a program run from an older build (--before)
UNAVAILABLE = 77  # exit status of a program that cannot run on this machine (common.hpp: kUnavailable)


def add_before(comps, bin_dir, label):
    """Adds every geods program of each comparison again, run from bin_dir (an older build), as <anchor>@before."""
    for c in comps:
        c["programs"] += [{"anchor": p["anchor"] + BEFORE, "before": label,
                           "command": [os.path.join(bin_dir, p["program"])],
                           "label": f"{p.get('label', p['anchor'])} before ({label})"}
                          for p in c["programs"]
                          if p["anchor"].startswith("geods") and "program" in p
                          and os.access(os.path.join(bin_dir, p["program"]), os.X_OK)]


# ----------------------------------------------------------------------------- steps a-c
def run_cmd(cmd, **kw):
    log("$", " ".join(shlex.quote(str(x)) for x in cmd))
    return subprocess.run(cmd, **kw)


def setup():
    script = os.path.join(REPO, "scripts", "setup.sh")
    if not os.path.exists(script):
        log("scripts/setup.sh not found; assuming the anchor packages are installed")
        return None
    if run_cmd([script, "--bench"], cwd=REPO).returncode != 0:
        log("WARNING: scripts/setup.sh --bench failed; comparisons whose anchor is missing are skipped")
        return "`scripts/setup.sh --bench` failed (see the console); missing anchors are reported below"
    return None


def generate(data_dir):
    r = run_cmd([PY, os.path.join(HERE, "gen_workloads.py"), data_dir], cwd=REPO)
    if r.returncode != 0:
        raise SystemExit("workload generation failed")
    try:
        with open(os.path.join(data_dir, "VERIFY.json")) as f:
            return json.load(f)
    except OSError:
        return {"reference": None, "ok": False, "checked": 0, "mismatched": [], "missing": []}


def configure(build_dir):
    cmd = ["cmake", "-S", HERE, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release"]
    if shutil.which("ninja") and not os.path.exists(os.path.join(build_dir, "Makefile")):
        cmd += ["-G", "Ninja"]
    if shutil.which("ccache"):
        cmd += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
    if run_cmd(cmd, cwd=REPO).returncode != 0:
        raise SystemExit("configuring bench/compare failed")


def known_targets(build_dir):
    r = subprocess.run(["cmake", "--build", build_dir, "--target", "help"], capture_output=True, text=True)
    return set(re.findall(r"^(?:\.\.\. )?([A-Za-z0-9_.+-]+)(?::| )", r.stdout, re.M))


def build(build_dir, comps, jobs):
    """Builds every program of comps; returns {program: None | reason it is unavailable}."""
    targets = known_targets(build_dir)
    status = {}
    for c in comps:
        names = [p["program"] for p in c["programs"] if "program" in p]
        present = [n for n in names if n in targets]
        for n in names:
            if n not in targets:
                status[n] = "not configured (anchor library missing, see the CMake warnings)"
        if not present:
            continue
        r = run_cmd(["cmake", "--build", build_dir, "-j", str(jobs), "--target", *present], cwd=REPO)
        if r.returncode != 0:  # find out which ones fail
            for n in present:
                rr = run_cmd(["cmake", "--build", build_dir, "-j", str(jobs), "--target", n], cwd=REPO,
                             capture_output=True, text=True)
                status[n] = None if rr.returncode == 0 else "build failed"
        for n in present:
            status.setdefault(n, None)
    return status


# ----------------------------------------------------------------------------- step d
def run_comparison(c, bin_dir, data_dir, threads_list, rounds, reps, scale, status, log_dir):
    """Runs the programs of one comparison interleaved; returns (records, raw lines, problems)."""
    records, raw, problems = [], [], []
    tl = threads_list if c["threads"] == "all" else [1]
    env = dict(os.environ, ANCHORS_REPS=str(reps), ANCHORS_DATA=data_dir)
    # Each round runs every program on 1 thread, then on the other counts: the speed-ups of the
    # All-cores table compare runs minutes apart, not the first and last parts of the comparison.
    for rnd in range(rounds):
        for threads in tl:
            for p in c["programs"]:
                if "command" in p:
                    cmd = [a.format(python=PY, dir=c["dir"], bin=bin_dir) for a in p["command"]]
                    prog = os.path.splitext(os.path.basename(cmd[-1]))[0] + (BEFORE if "before" in p else "")
                else:
                    prog = p["program"]
                    if status.get(prog):
                        continue
                    cmd = [os.path.join(bin_dir, prog)]
                cmd += ["--data", data_dir, "--threads", str(threads), "--reps", str(reps)]
                cmd += [str(a) for a in c["args"]] + [str(a) for a in p.get("args", [])]
                if scale != 1.0:
                    cmd += ["--scale", repr(scale)]
                log(f"{c['workload']}: {prog} threads={threads} round={rnd + 1}/{rounds}")
                errlog = os.path.join(log_dir, f"{prog}_t{threads}_r{rnd + 1}.log")
                t0 = time.time()
                try:
                    with open(errlog, "w") as ef:
                        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=ef, text=True, env=env,
                                           timeout=c["timeout_s"])
                    out, rc = r.stdout, r.returncode
                except subprocess.TimeoutExpired as e:
                    out = e.stdout.decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
                    rc = "timeout"
                n = 0
                for line in out.splitlines():
                    line = line.strip()
                    if not line.startswith("{"):
                        continue
                    try:
                        rec = json.loads(line)
                    except json.JSONDecodeError:
                        continue
                    if "before" in p:  # the older program names itself like the current one
                        rec["anchor"], rec["before"] = p["anchor"], p["before"]
                        line = json.dumps(rec)
                    raw.append(line)
                    rec["_round"] = rnd
                    records.append(rec)
                    n += 1
                log(f"  {n} measurements in {time.time() - t0:.1f} s" + (f", exit {rc}" if rc else ""))
                if rc == UNAVAILABLE and "program" in p:  # cannot run on this machine: skipped from now on
                    with open(errlog) as ef:
                        lines = [l.strip() for l in ef if l.strip()]
                    status[prog] = lines[-1] if lines else "unavailable on this machine"
                elif rc:
                    problems.append(f"`{prog} --threads {threads}` exited with {rc} (stderr: {rel(errlog)})")
    return records, raw, problems


# ----------------------------------------------------------------------------- step e
def run_micro(pattern=os.path.join(REPO, "build", "release", "bin", "geods_*_bench"), timeout_s=900):
    results = []
    for exe in sorted(glob.glob(pattern)):
        if not os.access(exe, os.X_OK):
            continue
        log("micro:", rel(exe))
        try:
            r = subprocess.run([exe, "--benchmark_format=json"], capture_output=True, text=True,
                               timeout=timeout_s)
            data = json.loads(r.stdout)
        except (subprocess.TimeoutExpired, json.JSONDecodeError) as e:
            results.append({"program": os.path.basename(exe), "error": type(e).__name__})
            continue
        results.append({"program": os.path.basename(exe), "benchmarks": data.get("benchmarks", [])})
    return results


# ----------------------------------------------------------------------------- report
def read_first(path, key):
    try:
        with open(path) as f:
            for line in f:
                if line.startswith(key):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def machine_info(build_dir):
    cpu = read_first("/proc/cpuinfo", "model name") or platform.processor() or "unknown CPU"
    mem = read_first("/proc/meminfo", "MemTotal")
    mem_gb = f"{int(mem.split()[0]) / 1048576:.1f} GiB" if mem else "unknown"
    os_name = "unknown"
    try:
        with open("/etc/os-release") as f:
            for line in f:
                if line.startswith("PRETTY_NAME="):
                    os_name = line.split("=", 1)[1].strip().strip('"')
    except OSError:
        pass
    cxx = "c++"
    cache = os.path.join(build_dir, "CMakeCache.txt")
    arch = ""
    if os.path.exists(cache):
        for line in open(cache):
            if line.startswith("CMAKE_CXX_COMPILER:"):
                cxx = line.split("=", 1)[1].strip()
            if line.startswith("GEODS_COMPARE_ARCH:"):
                arch = line.split("=", 1)[1].strip()
    try:
        compiler = subprocess.run([cxx, "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    except (OSError, IndexError):
        compiler = cxx
    flags = "-O3 -DNDEBUG" + (f" -march={arch}" if arch else "")
    git = subprocess.run(["git", "-C", REPO, "describe", "--always", "--dirty"], capture_output=True,
                         text=True).stdout.strip() or "unknown"
    return {"cpu": cpu, "cores": os.cpu_count(), "memory": mem_gb, "os": os_name,
            "kernel": platform.release(), "compiler": compiler, "flags": flags, "git": git,
            "load": os.getloadavg()}


def anchor_versions():
    path = os.path.join(HERE, "anchor-packages.txt")
    pkgs = [l.strip() for l in open(path) if l.strip() and not l.startswith("#")] if os.path.exists(path) else []
    out = []
    for p in pkgs:
        r = subprocess.run(["dpkg-query", "-W", "-f=${Version}", p], capture_output=True, text=True)
        out.append((p, r.stdout.strip() if r.returncode == 0 and r.stdout.strip() else "not installed"))
    return out


def fmt_time(s):
    if s is None or (isinstance(s, float) and math.isnan(s)):
        return "–"
    if s >= 1:
        return f"{s:.3f} s"
    if s >= 1e-3:
        return f"{s * 1e3:.2f} ms"
    return f"{s * 1e6:.1f} µs"


def fmt_rate(v):
    return f"{v:.3g}" if v < 1000 else f"{v:,.0f}"


def md_escape(s):
    return str(s).replace("|", "\\|")


def tabulate(c, records):
    """Markdown table of one comparison and the geometric-mean ratios per (anchor, threads)."""
    anchors = [p["anchor"] for p in c["programs"]]
    base = anchors[0]
    labels = {p["anchor"]: p.get("label", p["anchor"]) for p in c["programs"]}
    for r in records:  # older builds' records kept by --update without --before
        a = str(r.get("anchor"))
        if a.endswith(BEFORE) and a not in labels:
            anchors.append(a)
            now = a[: -len(BEFORE)]
            labels[a] = f"{labels.get(now, now)} before" + (f" ({r['before']})" if r.get("before") else "")
    groups = {}  # (variant, threads) -> anchor -> [records]
    order = []
    for r in records:
        key = (r.get("variant", ""), int(r.get("threads", 1)))
        if key not in groups:
            groups[key] = {}
            order.append(key)
        groups[key].setdefault(r.get("anchor"), []).append(r)
    first = {k: i for i, k in enumerate(order)}
    order.sort(key=lambda k: (k[1], first[k]))
    present = [a for a in anchors if any(a in g for g in groups.values())]

    def reference(a):  # what an anchor's ratio divides by: geods, or for X@before, X now
        now = a[: -len(BEFORE)]
        return now if a.endswith(BEFORE) and now in present else base
    values = c.get("values", [])
    metrics = [m for m in c["metrics"] + values
               if any(isinstance(r.get(m), (int, float)) and r.get(m) > 0 for r in records)]
    agree = c.get("agree")
    head = ["variant", "threads"] + (["metric"] if len(metrics) > 1 else [])
    for a in present:
        head.append(a)
        if a != base:
            head.append(f"{a} / {reference(a)}")
    if agree:
        head.append(agree.get("label", f"{agree['field']} agrees"))
    head.append("ok")
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    ratios = {}  # (anchor, threads) -> [ratio]
    for key in order:
        g = groups[key]
        for m in metrics:
            def med(a):
                vals = [r.get(m) for r in g.get(a, []) if isinstance(r.get(m), (int, float))]
                return statistics.median(vals) if vals else None
            if not any(med(a) for a in present):
                continue  # no program measured this in this variant (or only a phase of 0)
            row = [f"`{key[0]}`", str(key[1])] + ([m] if len(metrics) > 1 else [])
            for a in present:
                t = med(a)
                cell = (f"{t:.4g}" if m in values else fmt_time(t)) if t else "–"  # 0: no such phase
                if t and c.get("rate") and g.get(a) and m == c["rate"].get("metric", "query_s"):
                    cnt = g[a][0].get("count")
                    if cnt:
                        cell += f" ({fmt_rate(cnt / t * c['rate'].get('scale', 1))} {c['rate'].get('unit', '/s')})"
                row.append(cell)
                if a != base:
                    bt = med(reference(a))
                    if t and bt:
                        ratio = t / bt
                        if m not in values:
                            ratios.setdefault((a, key[1]), []).append(ratio)
                        row.append(f"**{ratio:.2f}**")
                    else:
                        row.append("–")
            if agree:
                vals = {a: {r.get(agree["field"]) for r in g.get(a, [])} for a in agree["anchors"] if a in g}
                if len(vals) < 2:
                    row.append("–")
                else:
                    allv = set().union(*vals.values())
                    row.append("yes" if len(allv) == 1 else "**NO**")
            oks = [r.get("ok") for a in present for r in g.get(a, [])]
            bad = [a for a in present if any(r.get("ok") is not True for r in g.get(a, []))]
            row.append("yes" if all(o is True for o in oks) else "**NO** (" + ", ".join(bad) + ")")
            lines.append("| " + " | ".join(md_escape(x) if not x.startswith("`") else x for x in row) + " |")
    summary = {k: math.exp(sum(math.log(x) for x in v) / len(v)) for k, v in ratios.items() if v}
    return "\n".join(lines), summary, labels


def as_list(x):
    return x if isinstance(x, list) else [x]


def speedup_rows(c, records, labels, run):
    """Rows of the all-cores table: every geods program's time on one thread / on the most threads
    measured in the same run, per variant and timing metric, beside the peers' same ratio."""
    times = {}  # (anchor, variant, metric) -> threads -> [time]
    for r in records:
        a = str(r.get("anchor"))
        if a.endswith(BEFORE):
            continue
        for m in c["metrics"]:
            t = r.get(m)
            if isinstance(t, (int, float)) and t > 0:
                times.setdefault((a, r.get("variant", ""), m), {}).setdefault(int(r.get("threads", 1)), []).append(t)

    def speedup(key):
        by = times.get(key, {})
        most = max(by, default=1)
        if 1 not in by or most == 1:
            return None, most
        return statistics.median(by[1]) / statistics.median(by[most]), most
    rows = []
    load = " / ".join(f"{x:.1f}" for x in run["load"]) if run else "?"
    for (a, v, m) in times:
        if not a.startswith("geods"):
            continue
        s, most = speedup((a, v, m))
        if s is None:
            continue
        peers = [f"{labels.get(b, b)} {ps:.2f}" for b in labels if not b.startswith("geods")
                 for ps, _ in [speedup((b, v, m))] if ps]
        mark = f"**{s:.2f}**" if s >= 1.6 else f"{s:.2f} (< 1.6)"
        why = next((n["note"] for n in c.get("scaling", []) if a in as_list(n.get("anchor"))
                    and v in as_list(n.get("variant", v)) and m in as_list(n.get("metric", m))), "")
        rows.append(f"| {c['workload']} | {md_escape(labels.get(a, a))} | `{v}` | {m} | {most} | {mark} | "
                    f"{md_escape(', '.join(peers)) or '–'} | {load} | {md_escape(why) or '–'} |")
    return rows


def agreement_failures(c, records):
    agree = c.get("agree")
    if not agree:
        return []
    bad = []
    groups = {}
    for r in records:
        if r.get("anchor") in agree["anchors"]:
            groups.setdefault((r.get("variant"), r.get("threads")), set()).add(r.get(agree["field"]))
    for k, v in sorted(groups.items(), key=str):
        if len(v) > 1:
            bad.append(f"{c['workload']} {k[0]} threads={k[1]}: {agree['field']} differs")
    return bad


def micro_table(micro):
    lines = []
    for m in micro:
        lines.append(f"**{m['program']}**\n")
        if "error" in m:
            lines.append(f"failed: {m['error']}\n")
            continue
        lines.append("| benchmark | real time | CPU time | items/s |")
        lines.append("|---|---|---|---|")
        for b in m["benchmarks"]:
            if b.get("run_type") == "aggregate":
                continue
            unit = b.get("time_unit", "ns")
            ips = b.get("items_per_second")
            lines.append(f"| `{b.get('name')}` | {b.get('real_time', 0):.4g} {unit} | "
                         f"{b.get('cpu_time', 0):.4g} {unit} | {fmt_rate(ips) if ips else '–'} |")
        lines.append("")
    return "\n".join(lines)


def run_record(cmdline, info, started, machine):
    """When, how and on what one workload (or the micro benchmarks) was measured: kept with its
    section by --update, so a later run on another machine does not relabel it."""
    return {"date": started.strftime("%Y-%m-%d %H:%M UTC"), "git": info["git"],
            "load": [round(x, 2) for x in info["load"]], "command": cmdline, "machine": machine}


def machine_summary(info, versions):
    """One line: the machine, compiler and installed anchor packages of a run."""
    installed = [f"{p} {v}" for p, v in versions if v != "not installed"]
    return (f"{info['cpu']}, {info['cores']} logical cores, {info['memory']}; {info['os']}, kernel "
            f"{info['kernel']}; {info['compiler']}, `{info['flags']}`; anchor packages: "
            + (", ".join(installed) or "none installed"))


def programs_line(c, status):
    """The programs of comparison c and their labels, with why any was unavailable."""
    progs = []
    for p in c["programs"]:
        pname = p.get("program") or " ".join(p["command"]).replace("{python} ", "").replace("{dir}/", "")
        st = status.get(pname)
        progs.append(f"`{pname}` = {p.get('label', p['anchor'])}" + (f" (**{st}**)" if st else ""))
    return "; ".join(progs)


def load_previous(jsonl, comps):
    """Records, raw lines and run records of an earlier report, by workload (for --update)."""
    runs_path = os.path.join(os.path.dirname(jsonl), "performance-runs.json")
    runs = {}
    if os.path.exists(runs_path):
        with open(runs_path) as f:
            runs = json.load(f)
    by_workload = {}
    if os.path.exists(jsonl):
        with open(jsonl) as f:
            for line in f:
                line = line.strip()
                if line.startswith("{"):
                    by_workload.setdefault(json.loads(line).get("workload"), []).append(line)
    results = {}
    for c in comps:
        raw = by_workload.get(c["workload"], [])
        if raw:
            results[c["workload"]] = ([json.loads(line) for line in raw], raw, [])
    return results, runs


def write_report(out, jsonl, cmdline, info, versions, verify, comps, results, status, micro, data_dir,
                 rounds, reps, threads_list, started, runs, early_problems=(), rewritten=False):
    L = []
    L.append("# geods performance\n")
    L.append("Written by `bench/compare/run.py` (`make bench`); do not edit by hand. Every ratio is "
             "**anchor time / geods time measured side by side in the same run** (> 1: geods is faster). "
             "Workloads and timing rules: `anchors/WORKLOADS.md` (generator copy: "
             "`bench/compare/gen_workloads.py`).\n")
    L.append(f"Command: `{cmdline}`\n")
    L.append("## Machine and run\n")
    if rewritten:
        L.append(f"- Date: {started.strftime('%Y-%m-%d %H:%M %Z').strip()}: report rewritten from the stored "
                 "results (`--report-only`), no program run; each section below names the run that measured it")
    else:
        L.append(f"- Date: {started.strftime('%Y-%m-%d %H:%M %Z').strip()} (run took "
                 f"{(datetime.datetime.now(datetime.timezone.utc) - started).total_seconds() / 60:.1f} min)")
    L.append(f"- CPU: {info['cpu']}, {info['cores']} logical cores; memory {info['memory']}")
    if not rewritten:
        L.append(f"- Load average at start: {info['load'][0]:.2f} / {info['load'][1]:.2f} / {info['load'][2]:.2f} "
                 "(other jobs on the machine disturb the timings)")
    L.append(f"- OS: {info['os']}, kernel {info['kernel']}")
    L.append(f"- Compiler: {info['compiler']}; geods and every comparison program built with `{info['flags']}`")
    L.append(f"- geods: `{info['git']}`")
    rtxt = (f"{rounds} interleaved round(s)" if rounds else
            "interleaved rounds as set per comparison (" +
            ", ".join(f"{c['workload']}: {c['rounds']}" for c in comps) + ")")
    L.append(f"- Timing: median of {reps} in-process repetitions (`ANCHORS_REPS`), {rtxt} "
             f"per program (median over rounds), threads {', '.join(map(str, threads_list))} "
             "(TBB limited by `tbb::global_control`)")
    if verify.get("reference") is None:
        vtxt = "not verified (no reference hash list found)"
    elif verify.get("ok"):
        vtxt = f"all {verify['checked']} files match the reference hashes (`{os.path.basename(verify['reference'])}`)"
    else:
        vtxt = (f"**MISMATCH**: {len(verify.get('matched', []))}/{verify.get('checked')} files match the "
                f"reference hashes; differing: {', '.join(verify.get('mismatched', []) + verify.get('missing', []))}")
    L.append(f"- Workloads: `{data_dir}`; {vtxt}")
    L.append("- Anchor packages (Debian): " + ", ".join(f"{p} {v}" for p, v in versions))
    L.append("- Each section below names the run that measured it; sections from earlier runs were kept "
             "by `--update` (this run re-measured only the sections dated as above).")
    L.append("")

    # summary
    L.append("## Summary\n")
    L.append("Geometric mean, over the variants (and metrics) of each workload, of anchor time / geods time "
             "(> 1: geods is faster); for a program run from an older build (`--before`, anchor `...@before`): "
             "its time / the same program's time now (> 1: faster now).\n")
    L.append("| workload | anchor | threads | geomean ratio |")
    L.append("|---|---|---|---|")
    sections = []
    all_cores = []
    problems_all = list(early_problems)
    for c in comps:
        recs, raw, problems = results.get(c["workload"], ([], [], []))
        problems_all += problems + agreement_failures(c, recs)
        if not recs:
            sections.append(f"## {c['workload']} — {c['title']}\n\nNo measurements "
                            f"({'; '.join(problems) or 'programs unavailable'}).\n")
            continue
        table, summary, labels = tabulate(c, recs)
        all_cores += speedup_rows(c, recs, labels, runs.get(c["workload"]))
        for (a, t), g in sorted(summary.items(), key=lambda kv: (kv[0][1], kv[0][0])):
            L.append(f"| {c['workload']} | {labels.get(a, a)} | {t} | **{g:.2f}** |")
        s = [f"## {c['workload']} — {c['title']}\n", c["about"] + "\n"]
        run = runs.get(c["workload"])
        if run:
            s.append(f"Measured {run['date']} on geods `{run['git']}`, load average "
                     f"{' / '.join(f'{x:.2f}' for x in run['load'])}: `{run['command']}`\n")
            if run.get("machine"):
                s.append(f"Machine: {run['machine']}.\n")
        s.append("Programs: " + ((run or {}).get("programs") or programs_line(c, status)) + ".\n")
        s.append(table + "\n")
        if problems:
            s.append("Problems: " + "; ".join(problems) + "\n")
        sections.append("\n".join(s))
    L.append("")
    L.append("## All cores\n")
    L.append("Speed-up of every geods program measured on one thread and on all threads in the same run: "
             "time on 1 thread / time on N threads (N = the machine's cores), with the peers' speed-up on the "
             "same variant for comparison and the load average of that run (a loaded machine cannot show a "
             "speed-up: compare with the peers' column). \"why\": the measured reason, from the comparison's "
             "compare.json (`scaling`), where the speed-up is below 1.6 or the program is sequential by design.\n")
    L.append("| workload | program | variant | metric | threads | speed-up | peers' speed-up | load | why |")
    L.append("|---|---|---|---|---|---|---|---|---|")
    L += all_cores
    L.append("")
    if problems_all:
        L.append("**Problems in this run:**\n")
        L += [f"- {p}" for p in problems_all]
        L.append("")
    L += sections

    L.append("## Micro benchmarks (Google Benchmark)\n")
    if micro:
        L.append("`build/release/bin/geods_*_bench --benchmark_format=json` (geods only, no anchor).\n")
        if runs.get("micro"):
            machine = runs["micro"].get("machine")
            L.append(f"Measured {runs['micro']['date']} on geods `{runs['micro']['git']}`."
                     + (f" Machine: {machine}." if machine else "") + "\n")
        L.append(micro_table(micro))
    else:
        L.append("None found (`build/release/bin/geods_*_bench`; `make release` builds them).\n")

    L.append("## Raw measurements\n")
    L.append(f"Every JSON line printed by the programs, in run order: [`{os.path.basename(jsonl)}`]"
             f"({os.path.basename(jsonl)}).\n")
    raw_all = [line for c in comps for line in results.get(c["workload"], ([], [], []))[1]]
    L.append("<details><summary>JSON lines</summary>\n\n```json")
    L += raw_all
    L.append("```\n</details>\n")
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, "w") as f:
        f.write("\n".join(L))
    with open(jsonl, "w") as f:
        f.write("\n".join(raw_all) + ("\n" if raw_all else ""))
    with open(os.path.join(os.path.dirname(jsonl), "performance-runs.json"), "w") as f:
        json.dump({k: v for k, v in runs.items() if k in results or k == "micro"} | {"micro_results": micro},
                  f, indent=1)
        f.write("\n")
    log("wrote", out, "and", jsonl)
    return problems_all


def rewrite_report(out, jsonl, cmdline, build_dir, data_dir, comps, threads_list, reps):
    """--report-only: the report again from the stored results, every section from its own run."""
    started = datetime.datetime.now(datetime.timezone.utc)
    results, runs = load_previous(jsonl, comps)
    micro = runs.get("micro_results") or []
    try:
        with open(os.path.join(data_dir, "VERIFY.json")) as f:
            verify = json.load(f)
    except OSError:
        verify = {"reference": None}
    problems = write_report(out, jsonl, cmdline, machine_info(build_dir), anchor_versions(), verify,
                            [c for c in comps if c["workload"] in results], results, {}, micro,
                            rel(data_dir) if data_dir.startswith(REPO) else data_dir, None, reps,
                            threads_list, started, runs, rewritten=True)
    for p in problems:
        log("PROBLEM:", p)
    return 1 if problems else 0


# ----------------------------------------------------------------------------- main
def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(REPO, "docs", "PERFORMANCE.md"), help="report (Markdown)")
    ap.add_argument("--jsonl", help="raw JSON lines (default: performance.jsonl beside --out)")
    ap.add_argument("--only", help="comma-separated workloads (folders of bench/compare)")
    ap.add_argument("--threads", help="comma-separated thread counts (default: 1,<all cores>)")
    ap.add_argument("--rounds", type=int, help="interleaved runs of every program "
                    "(default: the comparison's \"rounds\", else 1)")
    ap.add_argument("--reps", type=int, default=int(os.environ.get("ANCHORS_REPS", 3)),
                    help="in-process repetitions, median reported (default 3)")
    ap.add_argument("--scale", type=float, default=1.0, help="problem size factor (quick checks: 0.1)")
    ap.add_argument("--jobs", type=int, default=os.cpu_count(), help="build jobs")
    ap.add_argument("--data", default=os.environ.get("ANCHORS_DATA", os.path.join(REPO, "build", "anchors-data")))
    ap.add_argument("--build-dir", default=os.path.join(REPO, "build", "compare"))
    ap.add_argument("--no-setup", action="store_true", help="skip scripts/setup.sh --bench")
    ap.add_argument("--no-micro", action="store_true", help="skip the Google Benchmark programs")
    ap.add_argument("--before", metavar="DIR[=LABEL]", help="also run the geods programs of an older build "
                    "(its build/compare/bin) as <anchor>@before, interleaved; LABEL names its revision")
    ap.add_argument("--report-only", action="store_true", help="rewrite the report from the stored "
                    "results (performance.jsonl, performance-runs.json) without building or running")
    ap.add_argument("--update", action="store_true", help="with --only: keep the other workloads' "
                    "earlier results (and the micro benchmarks with --no-micro) in the report")
    args = ap.parse_args()

    started = datetime.datetime.now(datetime.timezone.utc)
    cmdline = "/usr/bin/python3 bench/compare/run.py " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    out = os.path.abspath(args.out)
    jsonl = os.path.abspath(args.jsonl or os.path.join(os.path.dirname(out), "performance.jsonl"))
    data_dir = os.path.abspath(args.data)
    build_dir = os.path.abspath(args.build_dir)
    ncpu = os.cpu_count() or 1
    threads_list = ([int(t) for t in args.threads.split(",")] if args.threads
                    else sorted({1, ncpu}))

    all_comps = comps = discover()
    if args.report_only:
        return rewrite_report(out, jsonl, cmdline, build_dir, data_dir, all_comps, threads_list, args.reps)
    if args.update and not args.only:
        raise SystemExit("--update needs --only (the workloads to re-run)")
    if args.only:
        want = {w.strip() for w in args.only.split(",") if w.strip()}
        unknown = want - {c["workload"] for c in comps}
        if unknown:
            raise SystemExit(f"unknown workload(s): {', '.join(sorted(unknown))}; "
                             f"known: {', '.join(c['workload'] for c in comps)}")
        comps = [c for c in comps if c["workload"] in want]
    if args.before:
        before_dir, _, label = args.before.partition("=")
        add_before(comps, os.path.abspath(before_dir), label or before_dir)
    log("comparisons:", ", ".join(c["workload"] for c in comps))

    setup_problem = None if args.no_setup else setup()  # (a)
    verify = generate(data_dir)                   # (b)
    configure(build_dir)                          # (c)
    status = build(build_dir, comps, args.jobs)
    for prog, st in status.items():
        if st:
            log(f"WARNING: {prog}: {st}")

    log_dir = os.path.join(build_dir, "logs")
    os.makedirs(log_dir, exist_ok=True)
    results = {}
    for c in comps:                               # (d)
        results[c["workload"]] = run_comparison(c, os.path.join(build_dir, "bin"), data_dir, threads_list,
                                                args.rounds or c["rounds"], args.reps, args.scale, status,
                                                log_dir)
    micro = [] if args.no_micro else run_micro()  # (e)
    info = machine_info(build_dir)
    versions = anchor_versions()
    machine = machine_summary(info, versions)
    runs = {c["workload"]: run_record(cmdline, info, started, machine) | {"programs": programs_line(c, status)}
            for c in comps}
    if micro:
        runs["micro"] = run_record(cmdline, info, started, machine)
    if args.update:
        previous, previous_runs = load_previous(jsonl, all_comps)
        for c in all_comps:
            w = c["workload"]
            if w not in results and w in previous:
                results[w] = previous[w]
                runs[w] = previous_runs.get(w, {"date": "an earlier run", "git": "unknown", "load": [0, 0, 0],
                                               "command": "unknown"})
        if not micro and previous_runs.get("micro_results"):
            micro = previous_runs["micro_results"]
            runs["micro"] = previous_runs.get("micro", {"date": "an earlier run", "git": "unknown"})
        comps = [c for c in all_comps if c["workload"] in results]
    problems = write_report(out, jsonl, cmdline, info, versions, verify,  # (f)
                            comps, results, status, micro, rel(data_dir) if data_dir.startswith(REPO) else data_dir,
                            args.rounds, args.reps, threads_list, started, runs,
                            [setup_problem] if setup_problem else [])
    for p in problems:
        log("PROBLEM:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
