#include "geods/core/parallel.hpp"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <memory>
#include <mutex>

namespace geods {

namespace {
std::mutex limit_mutex;
std::unique_ptr<tbb::global_control> limit;  // null: no limit
}  // namespace

void set_num_threads(int n) {
  std::lock_guard lock(limit_mutex);
  limit.reset();
  if (n > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, n);
}

int num_threads() {
  return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

}  // namespace geods
