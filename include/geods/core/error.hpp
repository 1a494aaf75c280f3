#pragma once
// The one exception type of geods: every bad input at an API boundary raises it.
#include <cstdio>
#include <stdexcept>
#include <string>

namespace geods {

/// Raised for bad input (files, NaN/inf, empty or degenerate sets, wrong
/// dimensions). The message says what is wrong and where, in one line.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// A number as messages print it: %g with 6 significant digits ("1e+300",
/// "1e-300", "0.25", "inf", "nan"), never std::to_string's 300 digits or "0.000000".
inline std::string format_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", v);
  return buffer;
}

}  // namespace geods
