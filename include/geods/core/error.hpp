#pragma once
// The one exception type of geods: every bad input at an API boundary raises it.
#include <stdexcept>
#include <string>

namespace geods {

/// Raised for bad input (files, NaN/inf, empty or degenerate sets, wrong
/// dimensions). The message says what is wrong and where, in one line.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace geods
