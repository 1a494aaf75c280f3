#pragma once
// Shared helpers of the side-by-side comparison programs (bench/compare/*/).
//
// Every program follows the timing rules of anchors/WORKLOADS.md:
//   * inputs are loaded and converted before timing,
//   * std::chrono::steady_clock around the operation only (ANCHORS_CPU_TIME=1: the process's CPU
//     time instead, for A/B runs on a loaded machine; not for recorded runs),
//   * each measurement is repeated `reps` times (ANCHORS_REPS, default 3), the median is reported,
//   * one JSON line per measurement on stdout:
//     {"workload","anchor","variant","threads","build_s","query_s","count","median_of",...,"ok"}
//
// Command line of every program (parsed by parse_args):
//   PROGRAM [--data DIR] [--threads N] [--reps N] [--scale X] [--only SUBSTRING]
//   --data    workload directory (default $ANCHORS_DATA, else build/anchors-data)
//   --threads thread count (default 1); TBB is limited with tbb::global_control
//   --reps    repetitions per measurement (default $ANCHORS_REPS, else 3)
//   --scale   multiplies the problem sizes a program chooses itself (quick runs: 0.1)
//   --only    run only the variants whose name contains SUBSTRING
// Diagnostics go to stderr; stdout carries only JSON lines.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <tbb/global_control.h>

namespace compare {

// ----------------------------------------------------------------------------- arguments

struct Args {
  std::string data_dir;
  int threads = 1;
  int reps = 3;
  double scale = 1.0;
  std::string only;  // variant filter (substring), empty = all

  std::string path(const std::string& file) const { return data_dir + "/" + file; }
  bool wants(std::string_view variant) const {
    return only.empty() || variant.find(only) != std::string_view::npos;
  }
  /// n scaled by --scale, at least 1.
  std::size_t scaled(std::size_t n) const {
    return std::max<std::size_t>(1, static_cast<std::size_t>(static_cast<double>(n) * scale));
  }
};

/// Exit status of a program whose anchor cannot run on this machine (Embree's
/// packets of 16 without AVX-512, ...): run.py lists the program as
/// unavailable, with the last line of its stderr as the reason, instead of
/// reporting a problem. (77: the "skipped" status of automake's test harness.)
inline constexpr int kUnavailable = 77;

[[noreturn]] inline void die(const std::string& msg) {
  std::fprintf(stderr, "error: %s\n", msg.c_str());
  std::exit(2);
}

inline Args parse_args(int argc, char** argv) {
  Args a;
  if (const char* d = std::getenv("ANCHORS_DATA")) a.data_dir = d;
  if (a.data_dir.empty()) a.data_dir = "build/anchors-data";
  if (const char* r = std::getenv("ANCHORS_REPS")) a.reps = std::max(1, std::atoi(r));
  for (int i = 1; i < argc; ++i) {
    std::string k = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) die("missing value after " + k);
      return argv[++i];
    };
    if (k == "--data") a.data_dir = value();
    else if (k == "--threads") a.threads = std::max(1, std::stoi(value()));
    else if (k == "--reps") a.reps = std::max(1, std::stoi(value()));
    else if (k == "--scale") a.scale = std::stod(value());
    else if (k == "--only") a.only = value();
    else if (k == "-h" || k == "--help") {
      std::fprintf(stderr, "usage: %s [--data DIR] [--threads N] [--reps N] [--scale X] [--only VARIANT]\n",
                   argv[0]);
      std::exit(0);
    } else {
      die("unknown argument " + k);
    }
  }
  return a;
}

/// Limits TBB to args.threads for the lifetime of the object (construct it first in main).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads)
      : control_(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads)) {}

 private:
  tbb::global_control control_;
};

/// The main of a driver with named variants: parses the command line, limits the
/// threads, and calls run_variant(args, variant) for each variant that --only selects.
template <class RunVariant>
int run_variants(int argc, char** argv, std::initializer_list<const char*> variants, RunVariant run_variant) {
  const Args args = parse_args(argc, argv);
  const ThreadLimit limit(args.threads);
  for (const char* variant : variants)
    if (args.wants(variant)) run_variant(args, variant);
  return 0;
}

// ----------------------------------------------------------------------------- timing

using Clock = std::chrono::steady_clock;

/// Seconds taken by fn().
/// With the environment variable ANCHORS_CPU_TIME=1: CPU seconds of the
/// process (all its threads) instead, for A/B runs on a loaded machine.
template <class F>
double time_s(F&& fn) {
  static const bool cpu = [] {
    const char* e = std::getenv("ANCHORS_CPU_TIME");
    return e && *e && std::string_view(e) != "0";
  }();
  if (cpu) {
    auto now = [] {
      timespec ts;
      clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
      return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
    };
    const double t0 = now();
    fn();
    return now() - t0;
  }
  auto t0 = Clock::now();
  fn();
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

inline double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Runs fn() reps times and returns the median time in seconds.
template <class F>
double median_time_s(int reps, F&& fn) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) t.push_back(time_s(fn));
  return median(std::move(t));
}

/// Keeps the compiler from discarding a computed value.
template <class T>
inline void do_not_optimize(const T& value) {
  asm volatile("" : : "r,m"(value) : "memory");
}

// ----------------------------------------------------------------------------- input files

/// Reads a header-less little-endian raw file of T records (*.f32, *.f64, *.u8).
template <class T>
std::vector<T> read_raw(const std::string& path) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  if (!f) die("cannot open " + path + " (run bench/compare/gen_workloads.py)");
  auto bytes = static_cast<std::size_t>(f.tellg());
  if (bytes % sizeof(T)) die(path + ": size " + std::to_string(bytes) + " is not a multiple of the record size");
  std::vector<T> v(bytes / sizeof(T));
  f.seekg(0);
  f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(bytes));
  if (!f) die("read error on " + path);
  return v;
}

/// A triangle mesh as stored in the workload PLY files.
struct PlyMesh {
  std::vector<float> xyz;          // 3 per vertex
  std::vector<std::int32_t> tris;  // 3 per triangle
  std::size_t vertices() const { return xyz.size() / 3; }
  std::size_t triangles() const { return tris.size() / 3; }
};

/// Reads the binary PLY layout of WORKLOADS.md: float x/y/z vertices, then triangles as
/// (uchar 3, int32 × 3). Anything else is rejected.
inline PlyMesh read_ply(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) die("cannot open " + path + " (run bench/compare/gen_workloads.py)");
  std::string line;
  std::size_t nv = 0, nf = 0;
  bool binary = false;
  while (std::getline(f, line)) {
    if (line == "end_header") break;
    std::istringstream ls(line);
    std::string w1, w2;
    ls >> w1 >> w2;
    if (w1 == "format") binary = w2 == "binary_little_endian";
    if (w1 == "element" && w2 == "vertex") ls >> nv;
    if (w1 == "element" && w2 == "face") ls >> nf;
  }
  if (!binary || nv == 0) die(path + ": not a binary little-endian PLY with vertices");
  PlyMesh m;
  m.xyz.resize(nv * 3);
  f.read(reinterpret_cast<char*>(m.xyz.data()), static_cast<std::streamsize>(nv * 12));
  m.tris.resize(nf * 3);
  for (std::size_t i = 0; i < nf; ++i) {
    unsigned char n = 0;
    f.read(reinterpret_cast<char*>(&n), 1);
    if (n != 3) die(path + ": face " + std::to_string(i) + " is not a triangle");
    f.read(reinterpret_cast<char*>(&m.tris[3 * i]), 12);
  }
  if (!f) die(path + ": truncated");
  return m;
}

// ----------------------------------------------------------------------------- randomness

/// splitmix64: a tiny deterministic generator, identical in every program, so that every
/// library gets exactly the same derived inputs (sampled tuples, permutations...).
struct SplitMix64 {
  std::uint64_t state;
  explicit SplitMix64(std::uint64_t seed) : state(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  /// Uniform integer in [0, n).
  std::uint64_t below(std::uint64_t n) { return next() % n; }
  /// Uniform integer in [lo, hi].
  std::int64_t range(std::int64_t lo, std::int64_t hi) {
    return lo + static_cast<std::int64_t>(below(static_cast<std::uint64_t>(hi - lo + 1)));
  }
  /// Uniform double in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
};

/// FNV-1a over bytes: a compact fingerprint of a result array for cross-library checks.
inline std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t h = 0xcbf29ce484222325ULL) {
  auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001b3ULL;
  return h;
}

/// Fingerprint of m k-NN answers (k ids per query): FNV-1a of each query's ids sorted,
/// so libraries that order equal distances differently still agree.
template <std::size_t K>
std::uint64_t neighbour_checksum(const std::uint32_t* ids, std::size_t m) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::size_t i = 0; i < m; ++i) {
    std::array<std::uint32_t, K> sorted;
    std::copy_n(ids + i * K, K, sorted.begin());
    std::sort(sorted.begin(), sorted.end());
    h = fnv1a(sorted.data(), sizeof sorted, h);
  }
  return h;
}

inline std::string hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// ----------------------------------------------------------------------------- JSON output

/// One JSON line, keys in insertion order. Mandatory keys first (constructor), extras with
/// set(), then print() appends "ok" last.
class Record {
 public:
  Record(std::string workload, std::string anchor, std::string variant, int threads) {
    set("workload", std::move(workload));
    set("anchor", std::move(anchor));
    set("variant", std::move(variant));
    set("threads", threads);
  }
  Record& set(const std::string& key, const std::string& v) { return raw(key, quote(v)); }
  Record& set(const std::string& key, const char* v) { return raw(key, quote(v)); }
  Record& set(const std::string& key, bool v) { return raw(key, v ? "true" : "false"); }
  Record& set(const std::string& key, int v) { return raw(key, std::to_string(v)); }
  Record& set(const std::string& key, long v) { return raw(key, std::to_string(v)); }
  Record& set(const std::string& key, long long v) { return raw(key, std::to_string(v)); }
  Record& set(const std::string& key, unsigned long v) { return raw(key, std::to_string(v)); }
  Record& set(const std::string& key, unsigned long long v) { return raw(key, std::to_string(v)); }
  Record& set(const std::string& key, double v) {
    if (!std::isfinite(v)) return raw(key, "null");
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return raw(key, buf);
  }
  /// The standard timing block: build_s, query_s, count, median_of.
  Record& timing(double build_s, double query_s, std::size_t count, int median_of) {
    set("build_s", build_s);
    set("query_s", query_s);
    set("count", static_cast<unsigned long long>(count));
    return set("median_of", median_of);
  }
  /// Writes the line with "ok" as the last key and flushes.
  void print(bool ok) {
    set("ok", ok);
    std::string s = "{";
    for (std::size_t i = 0; i < fields_.size(); ++i) {
      if (i) s += ", ";
      s += quote(fields_[i].first) + ": " + fields_[i].second;
    }
    s += "}\n";
    std::fputs(s.c_str(), stdout);
    std::fflush(stdout);
  }

 private:
  Record& raw(const std::string& key, std::string v) {
    for (auto& f : fields_)
      if (f.first == key) {
        f.second = std::move(v);
        return *this;
      }
    fields_.emplace_back(key, std::move(v));
    return *this;
  }
  static std::string quote(std::string_view s) {
    std::string o = "\"";
    for (char c : s) {
      if (c == '"' || c == '\\') o += '\\';
      if (static_cast<unsigned char>(c) < 0x20) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\u%04x", c);
        o += buf;
        continue;
      }
      o += c;
    }
    return o + "\"";
  }
  std::vector<std::pair<std::string, std::string>> fields_;
};

}  // namespace compare
