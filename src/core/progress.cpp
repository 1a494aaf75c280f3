#include "geods/core/progress.hpp"

#include <algorithm>
#include <string>

#include "geods/core/error.hpp"

namespace geods {

void Progress::report(double done) {
  if (!callback_) return;
  if (!callback_(stage_, std::clamp(done / total_, 0.0, 1.0))) {
    throw Error(stage_ + ": cancelled");
  }
}

}  // namespace geods
