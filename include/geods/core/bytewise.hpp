#pragma once
// Whether the bytes of a T are its value, so that an array of T can be written
// to a file as is and viewed in place (FlatArray, Archive): every trivially
// copyable type, and the types that say so beside their definition (fixed-size
// Eigen vectors and the structs made of them, whose copy constructors are
// user-provided but copy exactly their bytes).
#include <type_traits>

namespace geods {

template <typename T>
struct is_bytewise : std::is_trivially_copyable<T> {};
template <typename T>
inline constexpr bool is_bytewise_v = is_bytewise<T>::value;

}  // namespace geods
