#pragma once
// The csg comparison's shared driver: the same inputs, checks and output for every library.
//
// Variants
//   union, difference  A op B of the csg workload (csg_a.ply, csg_b.ply, 58,784 triangles
//                      each); build_s: the inputs into the library's structure, query_s: the
//                      boolean; checks: output closed (every directed edge of the output, its
//                      vertices welded by exact coordinates, has its opposite) and the
//                      identity of WORKLOADS.md vol(A ∪ B) − vol(A \ B) = vol(B) (relative
//                      error, `identity_error`, both outputs of this program).
//   fuzz               fuzz_corpus.txt (gen_fuzz.py, seeded): per case, union, intersection
//                      and difference in a forked child (a crash or an exception is a
//                      `failure`, more than kFuzzTimeout seconds a `loop`), each output checked
//                      for closedness (`cracks`: outputs not closed) and the identities
//                      vol(U) + vol(I) = vol(A) + vol(B), vol(D) = vol(A) − vol(I) within
//                      1e-5 max(vol A, vol B) (`wrong`: cases violating one).
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common.hpp"

namespace csg_bench {

struct Mesh {
  std::vector<double> xyz;                          // 3 per vertex
  std::vector<std::array<std::uint32_t, 3>> tri;
  std::size_t vertices() const { return xyz.size() / 3; }
};

enum class Op { union_, intersection, difference };
inline const char* op_name(Op op) {
  return op == Op::union_ ? "union" : op == Op::intersection ? "intersection" : "difference";
}

/// One boolean: fills out and the two times; returns false (or throws) on failure.
using Boolean = std::function<bool(const Mesh& a, const Mesh& b, Op op, Mesh& out, double& build_s, double& query_s)>;

inline Mesh from_ply(const compare::PlyMesh& p) {
  Mesh m;
  m.xyz.assign(p.xyz.begin(), p.xyz.end());
  for (std::size_t t = 0; t < p.triangles(); ++t)
    m.tri.push_back({static_cast<std::uint32_t>(p.tris[3 * t]), static_cast<std::uint32_t>(p.tris[3 * t + 1]),
                     static_cast<std::uint32_t>(p.tris[3 * t + 2])});
  return m;
}

inline double volume(const Mesh& m) {
  double v = 0;
  for (const auto& t : m.tri) {
    const double* a = &m.xyz[3 * t[0]];
    const double* b = &m.xyz[3 * t[1]];
    const double* c = &m.xyz[3 * t[2]];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v / 6;
}

/// Every directed edge has its opposite once vertices with equal coordinates are one.
inline bool closed(const Mesh& m) {
  std::map<std::array<double, 3>, std::uint32_t> weld;
  std::vector<std::uint32_t> id(m.vertices());
  for (std::size_t v = 0; v < m.vertices(); ++v)
    id[v] = weld.try_emplace({m.xyz[3 * v], m.xyz[3 * v + 1], m.xyz[3 * v + 2]}, static_cast<std::uint32_t>(weld.size()))
                .first->second;
  std::vector<std::uint64_t> fwd, bwd;
  for (const auto& t : m.tri)
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t u = id[t[k]], v = id[t[(k + 1) % 3]];
      if (u == v) continue;  // a degenerate corner
      fwd.push_back(u << 32 | v);
      bwd.push_back(v << 32 | u);
    }
  std::sort(fwd.begin(), fwd.end());
  std::sort(bwd.begin(), bwd.end());
  return fwd == bwd;
}

inline constexpr double kFuzzTimeout = 30;

struct FuzzCase {
  std::string name;
  Mesh a, b;
};

inline std::vector<FuzzCase> read_corpus(const std::string& path) {
  std::ifstream f(path);
  if (!f) compare::die("cannot open " + path);
  std::vector<FuzzCase> out;
  std::string word;
  while (f >> word) {
    if (word != "case") compare::die(path + ": expected 'case'");
    FuzzCase c;
    f.get();
    std::getline(f, c.name);
    for (Mesh* m : {&c.a, &c.b}) {
      std::string tag;
      std::size_t nv = 0, nt = 0;
      f >> tag >> nv >> nt;
      m->xyz.resize(3 * nv);
      for (auto& x : m->xyz) f >> x;
      m->tri.resize(nt);
      for (auto& t : m->tri) f >> t[0] >> t[1] >> t[2];
    }
    if (!f) compare::die(path + ": truncated");
    out.push_back(std::move(c));
  }
  return out;
}

// Child of a fuzz case: "status closed volume triangles" per operation on the pipe.
inline void fuzz_child(const FuzzCase& c, const Boolean& boolean, int fd) {
  std::ostringstream s;
  s.precision(17);
  for (Op op : {Op::union_, Op::intersection, Op::difference}) {
    Mesh out;
    double b = 0, q = 0;
    bool ok = false;
    try {
      ok = boolean(c.a, c.b, op, out, b, q);
    } catch (...) {
      ok = false;
    }
    s << (ok ? 0 : 1) << ' ' << (ok && closed(out) ? 1 : 0) << ' ' << (ok ? volume(out) : 0.0) << ' ' << out.tri.size()
      << '\n';
  }
  const std::string str = s.str();
  const ssize_t w = write(fd, str.data(), str.size());
  (void)w;
}

inline void run_fuzz(const compare::Args& args, const char* anchor, const Boolean& boolean) {
  const auto corpus = read_corpus(CSG_FUZZ_CORPUS);
  std::size_t failures = 0, loops = 0, cracks = 0, wrong = 0;
  std::string failed;
  const auto start = compare::Clock::now();
  for (const auto& c : corpus) {
    int fds[2];
    if (pipe(fds) != 0) compare::die("pipe");
    const pid_t pid = fork();
    if (pid == 0) {
      close(fds[0]);
      fuzz_child(c, boolean, fds[1]);
      _exit(0);
    }
    close(fds[1]);
    std::string text;
    char buf[4096];
    bool timed_out = false;
    const auto case_start = compare::Clock::now();
    for (;;) {
      pollfd p{fds[0], POLLIN, 0};
      const double left = kFuzzTimeout - std::chrono::duration<double>(compare::Clock::now() - case_start).count();
      if (left <= 0) {
        timed_out = true;
        break;
      }
      if (poll(&p, 1, static_cast<int>(left * 1000) + 1) <= 0) continue;
      const ssize_t n = read(fds[0], buf, sizeof buf);
      if (n <= 0) break;
      text.append(buf, static_cast<std::size_t>(n));
    }
    close(fds[0]);
    if (timed_out) kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    std::istringstream in(text);
    int st[3] = {1, 1, 1}, cl[3] = {0, 0, 0};
    double vol[3] = {0, 0, 0};
    std::size_t tris[3] = {0, 0, 0};
    int got = 0;
    for (int k = 0; k < 3 && (in >> st[k] >> cl[k] >> vol[k] >> tris[k]); ++k) ++got;
    std::string what;
    if (timed_out) {
      ++loops, what = "loop";
    } else if (got < 3 || st[0] || st[1] || st[2]) {
      ++failures, what = "failure";
    } else {
      const double va = volume(c.a), vb = volume(c.b), tol = 1e-5 * std::max(std::fabs(va), std::fabs(vb));
      if (!cl[0] || !cl[1] || !cl[2]) ++cracks, what = "crack";
      if (std::fabs(vol[0] + vol[1] - va - vb) > tol || std::fabs(vol[2] - (va - vol[1])) > tol) {
        ++wrong;
        what += what.empty() ? "wrong volume" : "+wrong volume";
      }
    }
    if (!what.empty()) failed += (failed.empty() ? "" : "; ") + c.name + ": " + what;
  }
  const double total = std::chrono::duration<double>(compare::Clock::now() - start).count();
  compare::Record("csg", anchor, "fuzz", args.threads)
      .timing(0, total, corpus.size(), 1)
      .set("failures", static_cast<unsigned long long>(failures))
      .set("loops", static_cast<unsigned long long>(loops))
      .set("cracks", static_cast<unsigned long long>(cracks))
      .set("wrong", static_cast<unsigned long long>(wrong))
      .set("failed_cases", failed)
      .print(true);
}

/// main of a csg program.
inline int run(int argc, char** argv, const char* anchor, const Boolean& boolean) {
  const compare::Args args = compare::parse_args(argc, argv);
  const compare::ThreadLimit limit(args.threads);
  if (args.wants("union") || args.wants("difference")) {
    const Mesh a = from_ply(compare::read_ply(args.path("csg_a.ply")));
    const Mesh b = from_ply(compare::read_ply(args.path("csg_b.ply")));
    const double vb = volume(b);
    std::map<Op, Mesh> out;
    std::map<Op, std::pair<double, double>> times;
    for (Op op : {Op::union_, Op::difference}) {
      std::vector<double> build, query;
      for (int r = 0; r < args.reps; ++r) {
        double bs = 0, qs = 0;
        Mesh m;
        if (!boolean(a, b, op, m, bs, qs)) compare::die(std::string(op_name(op)) + " failed");
        build.push_back(bs), query.push_back(qs);
        out[op] = std::move(m);
      }
      times[op] = {compare::median(build), compare::median(query)};
    }
    const double err = std::fabs(volume(out[Op::union_]) - volume(out[Op::difference]) - vb) / vb;
    for (Op op : {Op::union_, Op::difference}) {
      if (!args.wants(op_name(op))) continue;
      const bool cl = closed(out[op]);
      compare::Record("csg", anchor, op_name(op), args.threads)
          .timing(times[op].first, times[op].second, out[op].tri.size(), args.reps)
          .set("triangles", static_cast<unsigned long long>(out[op].tri.size()))
          .set("closed", cl)
          .set("volume", volume(out[op]))
          .set("identity_error", err)
          .print(cl && err < 1e-5);
    }
  }
  if (args.wants("fuzz")) run_fuzz(args, anchor, boolean);
  return 0;
}

}  // namespace csg_bench
