#include "geods/core/coordinate_range.hpp"

#include <fmt/format.h>

namespace geods {

std::string short_number(double value) { return fmt::format("{:.6g}", value); }

}  // namespace geods
