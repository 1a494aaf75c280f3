#include "geods/io/npy.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "file_util.hpp"
#include "geods/io/output.hpp"

namespace geods::io {

namespace fs = std::filesystem;
using detail::fail;

std::size_t NpyArray::size() const {
  std::size_t n = 1;
  for (std::size_t s : shape) n *= s;
  return n;
}

namespace {

// Converts one element, refusing values T cannot hold (a float NaN or 1e300
// cast to an integer is undefined behaviour, a wrapped integer is silent loss).
template <typename T, typename S>
T convert_element(S v, std::size_t index, DType from) {
  if constexpr (std::is_floating_point_v<T>) {
    if constexpr (sizeof(T) < sizeof(S) && std::is_floating_point_v<S>) {
      if (std::isfinite(v) && !detail::fits_float(double(v)))
        throw Error("npy: element " + std::to_string(index) + " (" + format_number(double(v)) + ") of dtype " +
                    std::string(dtype_name(from)) + " does not fit " + std::string(dtype_name(dtype_of<T>())));
    }
    return static_cast<T>(v);
  } else if constexpr (std::is_floating_point_v<S>) {
    constexpr double lo = double(std::numeric_limits<T>::min());
    constexpr double hi = double(std::numeric_limits<T>::max()) + 1.0;  // exact: a power of two
    if (!(double(v) >= lo && double(v) < hi))
      throw Error("npy: element " + std::to_string(index) + " (" + format_number(double(v)) + ") of dtype " +
                  std::string(dtype_name(from)) + " does not fit " + std::string(dtype_name(dtype_of<T>())));
    return static_cast<T>(v);
  } else {
    if (!std::in_range<T>(v))
      throw Error("npy: element " + std::to_string(index) + " (" + std::to_string(v) + ") of dtype " +
                  std::string(dtype_name(from)) + " does not fit " + std::string(dtype_name(dtype_of<T>())));
    return static_cast<T>(v);
  }
}

template <typename T, typename S>
void convert_all(const NpyArray& a, std::vector<T>& out) {
  const std::size_t n = a.bytes.size() / sizeof(S);
  out.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    S v;
    std::memcpy(&v, a.bytes.data() + i * sizeof(S), sizeof(S));
    out[i] = convert_element<T>(v, i, a.dtype);
  }
}

// A cursor over the header's Python dict literal, e.g.
// {'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }
class DictParser {
 public:
  DictParser(const fs::path& path, std::string_view text) : path_(path), s_(text) {}

  void skip_ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
  }
  bool accept(char c) {
    skip_ws();
    if (i_ < s_.size() && s_[i_] == c) {
      ++i_;
      return true;
    }
    return false;
  }
  void expect(char c) {
    if (!accept(c)) error(std::string("expected '") + c + "'");
  }
  std::string string() {
    skip_ws();
    if (i_ >= s_.size() || (s_[i_] != '\'' && s_[i_] != '"')) error("expected a string");
    const char quote = s_[i_++];
    const std::size_t end = s_.find(quote, i_);
    if (end == std::string_view::npos) error("unterminated string");
    std::string v(s_.substr(i_, end - i_));
    i_ = end + 1;
    return v;
  }
  bool boolean() {
    skip_ws();
    for (auto [word, value] : {std::pair{"True", true}, std::pair{"False", false}}) {
      const std::string_view w(word);
      if (s_.substr(i_, w.size()) == w) {
        i_ += w.size();
        return value;
      }
    }
    error("expected True or False");
  }
  std::vector<std::size_t> shape() {
    expect('(');
    std::vector<std::size_t> dims;
    while (!accept(')')) {
      skip_ws();
      const std::size_t start = i_;
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
      std::size_t v = 0;
      if (!detail::parse_size(s_.substr(start, i_ - start), v)) error("shape entries must be non-negative integers");
      if (i_ < s_.size() && s_[i_] == 'L') ++i_;  // Python 2 long
      dims.push_back(v);
      if (dims.size() > 32) error("more than 32 dimensions");
      if (!accept(',')) {
        expect(')');
        break;
      }
    }
    return dims;
  }
  [[noreturn]] void error(const std::string& what) const {
    fail(path_, "malformed npy header: " + what + " at character " + std::to_string(i_));
  }

 private:
  const fs::path& path_;
  std::string_view s_;
  std::size_t i_ = 0;
};

struct Descr {
  DType dtype;
  bool big_endian;
};

Descr parse_descr(const fs::path& path, const std::string& d) {
  if (d.size() < 3) fail(path, "unsupported npy dtype '" + d + "'");
  const char order = d[0], kind = d[1];
  std::size_t size = 0;
  if (!detail::parse_size(std::string_view(d).substr(2), size)) fail(path, "unsupported npy dtype '" + d + "'");
  if (order != '<' && order != '>' && order != '|' && order != '=')
    fail(path, "unsupported npy dtype '" + d + "' (unknown byte order)");
  const bool big = order == '>';
  auto pick = [&](std::initializer_list<std::pair<std::size_t, DType>> options) -> Descr {
    for (auto [s, t] : options)
      if (s == size) return {t, big};
    fail(path, "unsupported npy dtype '" + d + "'");
  };
  switch (kind) {
    case 'u': return pick({{1, DType::u8}, {2, DType::u16}, {4, DType::u32}, {8, DType::u64}});
    case 'i': return pick({{1, DType::i8}, {2, DType::i16}, {4, DType::i32}, {8, DType::i64}});
    case 'f': return pick({{4, DType::f32}, {8, DType::f64}});
    case 'b': return pick({{1, DType::u8}});  // bool: 0 or 1 as u8
    default: fail(path, "unsupported npy dtype '" + d + "' (only integer, float and bool arrays)");
  }
}

std::string descr_of(DType t) {
  switch (t) {
    case DType::u8: return "|u1";
    case DType::i8: return "|i1";
    case DType::u16: return "<u2";
    case DType::i16: return "<i2";
    case DType::u32: return "<u4";
    case DType::i32: return "<i4";
    case DType::u64: return "<u8";
    case DType::i64: return "<i8";
    case DType::f32: return "<f4";
    case DType::f64: return "<f8";
  }
  return "";
}

// The elements of a Fortran-order (first index fastest) array rearranged in C
// order (last index fastest), each `width` bytes.
std::vector<std::uint8_t> fortran_to_c_order(const std::vector<std::uint8_t>& bytes, const std::vector<std::size_t>& shape,
                                             std::size_t width) {
  if (shape.size() < 2 || bytes.empty()) return bytes;
  const std::size_t k = shape.size();
  std::vector<std::size_t> stride(k), index(k, 0);  // Fortran strides in elements
  stride[0] = 1;
  for (std::size_t j = 1; j < k; ++j) stride[j] = stride[j - 1] * shape[j - 1];
  std::vector<std::uint8_t> out(bytes.size());
  std::size_t from = 0;  // Fortran offset of `index`
  for (std::size_t to = 0; to < bytes.size(); to += width) {
    std::memcpy(out.data() + to, bytes.data() + from * width, width);
    for (std::size_t j = k; j-- > 0;) {  // next C-order index: the last one fastest
      if (++index[j] < shape[j]) {
        from += stride[j];
        break;
      }
      from -= (shape[j] - 1) * stride[j];
      index[j] = 0;
    }
  }
  return out;
}

}  // namespace

template <typename T>
std::vector<T> NpyArray::to_vector() const {
  std::vector<T> out;
  switch (dtype) {
    case DType::u8: convert_all<T, std::uint8_t>(*this, out); break;
    case DType::i8: convert_all<T, std::int8_t>(*this, out); break;
    case DType::u16: convert_all<T, std::uint16_t>(*this, out); break;
    case DType::i16: convert_all<T, std::int16_t>(*this, out); break;
    case DType::u32: convert_all<T, std::uint32_t>(*this, out); break;
    case DType::i32: convert_all<T, std::int32_t>(*this, out); break;
    case DType::u64: convert_all<T, std::uint64_t>(*this, out); break;
    case DType::i64: convert_all<T, std::int64_t>(*this, out); break;
    case DType::f32: convert_all<T, float>(*this, out); break;
    case DType::f64: convert_all<T, double>(*this, out); break;
  }
  return out;
}

NpyArray read_npy(const fs::path& path) {
  std::vector<std::uint8_t> file = detail::read_file(path);
  if (file.empty()) fail(path, "empty file");
  static constexpr std::uint8_t magic[6] = {0x93, 'N', 'U', 'M', 'P', 'Y'};
  if (file.size() < 10 || !std::equal(magic, magic + 6, file.begin())) fail(path, "not an npy file (wrong magic)");
  const int major = file[6];
  std::size_t header_len = 0, header_start = 0;
  if (major == 1) {
    header_len = detail::load<std::uint16_t>(&file[8], false);
    header_start = 10;
  } else if (major == 2 || major == 3) {
    if (file.size() < 12) fail(path, "truncated npy header");
    header_len = detail::load<std::uint32_t>(&file[8], false);
    header_start = 12;
  } else {
    fail(path, "unsupported npy format version " + std::to_string(major) + "." + std::to_string(file[7]));
  }
  if (header_len > file.size() - header_start)
    fail(path, "truncated: header of " + std::to_string(header_len) + " bytes, file has " +
                   std::to_string(file.size() - header_start) + " after the preamble");

  DictParser p(path, detail::as_text(std::span(file).subspan(header_start, header_len)));
  std::string descr;
  bool fortran = false, have_descr = false, have_order = false, have_shape = false;
  NpyArray a;
  p.expect('{');
  while (!p.accept('}')) {
    const std::string key = p.string();
    p.expect(':');
    if (key == "descr") {
      p.skip_ws();
      if (p.accept('[')) fail(path, "structured npy dtypes are not supported");
      descr = p.string();
      have_descr = true;
    } else if (key == "fortran_order") {
      fortran = p.boolean();
      have_order = true;
    } else if (key == "shape") {
      a.shape = p.shape();
      have_shape = true;
    } else {
      p.error("unexpected key '" + key + "'");
    }
    if (!p.accept(',')) {
      p.expect('}');
      break;
    }
  }
  if (!have_descr || !have_order || !have_shape) fail(path, "malformed npy header: needs descr, fortran_order and shape");
  const Descr d = parse_descr(path, descr);
  a.dtype = d.dtype;

  std::size_t count = 1;
  for (std::size_t s : a.shape) count = detail::checked_mul(path, count, s);
  const std::size_t need = detail::checked_mul(path, count, dtype_size(a.dtype));
  const std::size_t data_start = header_start + header_len;
  const std::size_t have = file.size() - data_start;
  // Checked before any allocation: the file must hold exactly the data the shape promises.
  if (have < need)
    fail(path, "truncated: shape needs " + std::to_string(need) + " bytes of data, file has " + std::to_string(have));
  if (have > need) fail(path, std::to_string(have - need) + " unexpected bytes after the array data");
  file.erase(file.begin(), file.begin() + std::ptrdiff_t(data_start));
  a.bytes = std::move(file);
  if (d.big_endian) detail::swap_bytes(a.bytes, dtype_size(a.dtype));
  if (fortran) a.bytes = fortran_to_c_order(a.bytes, a.shape, dtype_size(a.dtype));
  return a;
}

void write_npy(const fs::path& path, const NpyArray& array) {
  // Another name would hold .npy bytes under a name that says otherwise.
  check_output_extension(path, OutputKind::array);
  std::size_t count = 1;
  for (std::size_t s : array.shape) count = detail::checked_mul(path, count, s);
  if (count * dtype_size(array.dtype) != array.bytes.size())
    fail(path, "write_npy: shape holds " + std::to_string(count) + " elements but there are " +
                   std::to_string(array.bytes.size()) + " bytes of " + std::string(dtype_name(array.dtype)));
  std::string header = "{'descr': '" + descr_of(array.dtype) + "', 'fortran_order': False, 'shape': (";
  for (std::size_t s : array.shape) header += std::to_string(s) + ", ";
  if (array.shape.size() == 1) header.pop_back();  // "(3,)"
  else if (array.shape.size() > 1) header.resize(header.size() - 2);
  header += "), }";
  // Pad with spaces and a newline so that the data starts 64-byte aligned (as numpy does).
  const bool v2 = header.size() + 64 + 10 > 65535;
  const std::size_t preamble = v2 ? 12 : 10;
  const std::size_t total = (preamble + header.size() + 1 + 63) / 64 * 64;
  header.append(total - preamble - header.size() - 1, ' ');
  header += '\n';
  std::vector<std::uint8_t> out = {0x93, 'N', 'U', 'M', 'P', 'Y', std::uint8_t(v2 ? 2 : 1), 0};
  const std::size_t n = header.size();
  out.push_back(std::uint8_t(n & 0xff));
  out.push_back(std::uint8_t((n >> 8) & 0xff));
  if (v2) {
    out.push_back(std::uint8_t((n >> 16) & 0xff));
    out.push_back(std::uint8_t((n >> 24) & 0xff));
  }
  out.insert(out.end(), header.begin(), header.end());
  out.insert(out.end(), array.bytes.begin(), array.bytes.end());
  if constexpr (std::endian::native == std::endian::big)
    detail::swap_bytes(std::span(out).subspan(total), dtype_size(array.dtype));
  detail::write_file(path, out);
}

template <typename T>
void write_npy(const fs::path& path, std::span<const T> data, std::vector<std::size_t> shape) {
  NpyArray a;
  a.dtype = dtype_of<T>();
  a.shape = std::move(shape);
  a.bytes.resize(data.size_bytes());
  if (!data.empty()) std::memcpy(a.bytes.data(), data.data(), data.size_bytes());
  write_npy(path, a);
}

#define GEODS_NPY_INSTANTIATE(T)                        \
  template std::vector<T> NpyArray::to_vector<T>() const; \
  template void write_npy<T>(const fs::path&, std::span<const T>, std::vector<std::size_t>);
GEODS_NPY_INSTANTIATE(std::uint8_t)
GEODS_NPY_INSTANTIATE(std::int8_t)
GEODS_NPY_INSTANTIATE(std::uint16_t)
GEODS_NPY_INSTANTIATE(std::int16_t)
GEODS_NPY_INSTANTIATE(std::uint32_t)
GEODS_NPY_INSTANTIATE(std::int32_t)
GEODS_NPY_INSTANTIATE(std::uint64_t)
GEODS_NPY_INSTANTIATE(std::int64_t)
GEODS_NPY_INSTANTIATE(float)
GEODS_NPY_INSTANTIATE(double)
#undef GEODS_NPY_INSTANTIATE

}  // namespace geods::io
