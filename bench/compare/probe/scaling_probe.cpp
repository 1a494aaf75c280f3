// What the machine gives a parallel program right now: the 2-thread speed-up of plain loops,
// to put beside a program's speed-up measured in the same minutes (bench/compare/*/compare.json
// "scaling" notes). Not a comparison (no compare.json): run it by hand,
//   build/compare/bin/scaling_probe [--threads N] [--mb 64] [--reps 7]
// It prints one JSON line per loop with the median wall time and the process CPU time of the
// repetitions:
//   compute     an FP loop on registers (no memory): scales with the free cores;
//   copy_fresh  copies MB megabytes into newly allocated memory (page faults, as a structure that
//               copies its input does);
//   copy_warm   the same copy into memory already touched (memory bandwidth);
//   scan        counts the floats above 0.5 in the MB megabytes (a read-only pass: memory bandwidth).
// On a loaded machine wall / cpu shows how much of a core the process got.
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace {

double cpu_s() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

template <class F>
void measure(const char* name, int threads, int reps, F&& f) {
  std::vector<double> wall;
  const double c0 = cpu_s();
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  const double cpu = (cpu_s() - c0) / reps;
  std::sort(wall.begin(), wall.end());
  std::printf("{\"probe\": \"%s\", \"threads\": %d, \"wall_s\": %.6g, \"cpu_s\": %.6g}\n", name, threads,
              wall[wall.size() / 2], cpu);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 1, reps = 7;
  std::size_t mb = 64;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--threads") threads = std::max(1, std::atoi(argv[i + 1]));
    else if (k == "--mb") mb = std::size_t(std::max(1, std::atoi(argv[i + 1])));
    else if (k == "--reps") reps = std::max(1, std::atoi(argv[i + 1]));
    else return std::fprintf(stderr, "usage: %s [--threads N] [--mb MB] [--reps N]\n", argv[0]), 2;
  }
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  const std::size_t n = mb << 18;  // floats
  std::vector<float> src(n);
  for (std::size_t i = 0; i < n; ++i) src[i] = float(i % 1000) * 0.001f;
  const std::size_t grain = 1 << 16;

  volatile double sink = 0;
  measure("compute", threads, reps, [&] {
    sink = sink + tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, 1 << 12, 1), 0.0,
        [](const tbb::blocked_range<std::size_t>& r, double acc) {
          for (std::size_t i = r.begin(); i < r.end(); ++i) {
            double x = double(i), y = 1.0;
            for (int k = 0; k < 20000; ++k) y = y * 0.999999 + x * 1e-9;
            acc += y;
          }
          return acc;
        },
        [](double a, double b) { return a + b; });
  });
  measure("copy_fresh", threads, reps, [&] {
    std::unique_ptr<float[]> dst(new float[n]);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
      std::memcpy(dst.get() + r.begin(), src.data() + r.begin(), (r.end() - r.begin()) * sizeof(float));
    });
    sink = sink + dst[n / 2];
  });
  std::vector<float> dst(n);
  measure("copy_warm", threads, reps, [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
      std::memcpy(dst.data() + r.begin(), src.data() + r.begin(), (r.end() - r.begin()) * sizeof(float));
    });
    sink = sink + dst[n / 3];
  });
  measure("scan", threads, reps, [&] {
    sink = sink + double(tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, grain), std::size_t(0),
        [&](const tbb::blocked_range<std::size_t>& r, std::size_t count) {
          for (std::size_t i = r.begin(); i < r.end(); ++i) count += src[i] > 0.5f;  // vectorized
          return count;
        },
        [](std::size_t a, std::size_t b) { return a + b; }));
  });
  return 0;
}
