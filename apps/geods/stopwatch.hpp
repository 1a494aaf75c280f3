#pragma once
// Wall-clock timing for the _s keys of reports.
#include <chrono>

namespace geods::cli {

class Stopwatch {
 public:
  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_ = Clock::now();
};

}  // namespace geods::cli
