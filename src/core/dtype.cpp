#include "geods/core/dtype.hpp"

#include <string>

#include "geods/core/error.hpp"

namespace geods {

DType parse_dtype(std::string_view name) {
  for (DType t : {DType::u8, DType::i8, DType::u16, DType::i16, DType::u32, DType::i32, DType::u64,
                  DType::i64, DType::f32, DType::f64}) {
    if (dtype_name(t) == name) return t;
  }
  throw Error("unknown dtype '" + std::string(name) + "' (expected u8, i8, u16, i16, u32, i32, u64, i64, f32 or f64)");
}

}  // namespace geods
