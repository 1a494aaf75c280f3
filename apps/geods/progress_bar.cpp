#include "progress_bar.hpp"

#include <unistd.h>

#include <cstdio>
#include <string>

namespace geods::cli {

ProgressCallback terminal_progress_bar() {
  if (!isatty(STDERR_FILENO)) return {};
  return [last = -1, last_stage = std::string()](std::string_view stage, double fraction) mutable {
    const int percent = int(fraction * 100);
    if (percent == last && stage == last_stage) return true;
    last = percent;
    last_stage = stage;
    constexpr int kWidth = 30;
    const int filled = percent * kWidth / 100;
    std::fprintf(stderr, "\r%-24.*s [%.*s%*s] %3d%%", int(stage.size()), stage.data(), filled,
                 "##############################", kWidth - filled, "", percent);
    if (percent >= 100) std::fprintf(stderr, "\r%*s\r", 24 + kWidth + 8, "");
    std::fflush(stderr);
    return true;
  };
}

}  // namespace geods::cli
