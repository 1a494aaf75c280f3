#pragma once
// Progress reporting for long operations.
#include <functional>
#include <string>
#include <string_view>
#include <utility>

namespace geods {

/// Called with the current stage name and the fraction done in [0, 1].
/// Returning false asks the operation to stop; it then throws geods::Error("cancelled").
using ProgressCallback = std::function<bool(std::string_view stage, double fraction)>;

/// Wraps an optional callback for an operation with `total` steps; forwards at
/// most about 200 updates so that calling step() in a hot loop stays cheap.
class Progress {
 public:
  // Holds copies of the callback and the stage name, so temporaries are fine.
  Progress(ProgressCallback callback, std::string_view stage, double total)
      : callback_(std::move(callback)), stage_(stage), total_(total > 0 ? total : 1) {
    report(0);
  }

  /// Reports that `done` of `total` steps are finished.
  void update(double done) {
    if (callback_ && done >= next_) {
      next_ = done + total_ / 200;
      report(done);
    }
  }
  void finish() { report(total_); }

 private:
  void report(double done);

  ProgressCallback callback_;
  std::string stage_;
  double total_;
  double next_ = 0;
};

}  // namespace geods
