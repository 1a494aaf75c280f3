#include <cmath>
#include <cstring>
#include <limits>

#include "file_util.hpp"
#include "geods/io/npy.hpp"
#include "volume_detail.hpp"

namespace geods::io {

namespace fs = std::filesystem;
using detail::fail;

namespace detail {

namespace {

template <typename T>
Grid3<T> copy_grid(std::array<std::size_t, 3> dims, std::span<const std::uint8_t> samples) {
  Grid3<T> g;
  g.dims = dims;
  g.data.resize(Grid3<T>::checked_size(dims[0], dims[1], dims[2]));
  if (!g.data.empty()) std::memcpy(g.data.data(), samples.data(), g.data.size() * sizeof(T));
  return g;
}

template <typename T, typename S>
Grid3<T> widen(const fs::path& path, std::array<std::size_t, 3> dims, std::span<const std::uint8_t> samples) {
  Grid3<T> g;
  g.dims = dims;
  const std::size_t n = Grid3<T>::checked_size(dims[0], dims[1], dims[2]);
  g.data.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    S v;
    std::memcpy(&v, samples.data() + i * sizeof(S), sizeof(S));
    if constexpr (sizeof(S) == 8) {
      if (v > S(1ll << 53) || (std::is_signed_v<S> && v < -S(1ll << 53)))
        fail(path, "sample " + std::to_string(i) + " (" + std::to_string(v) +
                       ") is a 64-bit integer that double cannot hold exactly");
    }
    g.data[i] = T(v);
  }
  return g;
}

}  // namespace

AnyGrid3 grid_from_samples(const fs::path& path, std::array<std::size_t, 3> dims, DType dtype,
                           std::span<const std::uint8_t> samples) {
  const std::size_t n = checked_mul(path, checked_mul(path, dims[0], dims[1]), dims[2]);
  if (checked_mul(path, n, dtype_size(dtype)) != samples.size())
    fail(path, "internal: sample bytes do not match the dimensions");
  switch (dtype) {
    case DType::u8: return copy_grid<std::uint8_t>(dims, samples);
    case DType::u16: return copy_grid<std::uint16_t>(dims, samples);
    case DType::i16: return copy_grid<std::int16_t>(dims, samples);
    case DType::f32: return copy_grid<float>(dims, samples);
    case DType::f64: return copy_grid<double>(dims, samples);
    case DType::i8: return widen<std::int16_t, std::int8_t>(path, dims, samples);
    case DType::u32: return widen<double, std::uint32_t>(path, dims, samples);
    case DType::i32: return widen<double, std::int32_t>(path, dims, samples);
    case DType::u64: return widen<double, std::uint64_t>(path, dims, samples);
    case DType::i64: return widen<double, std::int64_t>(path, dims, samples);
  }
  fail(path, "unknown dtype");
}

std::span<const std::uint8_t> grid_bytes(const AnyGrid3& grid) {
  return std::visit(
      [](const auto& g) {
        return std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(g.data.data()),
                                             g.data.size() * sizeof(g.data[0]));
      },
      grid);
}
std::array<std::size_t, 3> grid_dims(const AnyGrid3& grid) {
  return std::visit([](const auto& g) { return g.dims; }, grid);
}
Vec3f grid_origin(const AnyGrid3& grid) {
  return std::visit([](const auto& g) { return g.origin; }, grid);
}
Vec3f grid_spacing(const AnyGrid3& grid) {
  return std::visit([](const auto& g) { return g.spacing; }, grid);
}
void set_geometry(AnyGrid3& grid, const Vec3f& origin, const Vec3f& spacing) {
  std::visit(
      [&](auto& g) {
        g.origin = origin;
        g.spacing = spacing;
      },
      grid);
}

}  // namespace detail

DType grid_dtype(const AnyGrid3& grid) {
  return std::visit([](const auto& g) { return geods::dtype_of<typename std::decay_t<decltype(g)>::value_type>(); },
                    grid);
}

Grid3<float> to_float(const AnyGrid3& grid) {
  return std::visit(
      [](const auto& g) {
        Grid3<float> f;
        f.dims = g.dims;
        f.origin = g.origin;
        f.spacing = g.spacing;
        f.data.resize(g.data.size());
        // Doubles beyond float's range saturate to +-inf (a plain cast would be undefined).
        for (std::size_t i = 0; i < g.data.size(); ++i) {
          const double v = double(g.data[i]);
          constexpr float inf = std::numeric_limits<float>::infinity();
          f.data[i] = detail::fits_float(v) || std::isnan(v) ? float(v) : (v > 0 ? inf : -inf);
        }
        return f;
      },
      grid);
}

namespace {

AnyGrid3 read_npy_volume(const fs::path& path) {
  const NpyArray a = read_npy(path);
  if (a.shape.size() != 3)
    fail(path, "volume arrays must be 3-D (nz, ny, nx), this one has " + std::to_string(a.shape.size()) + " dimensions");
  if (a.size() == 0) fail(path, "empty volume");
  return detail::grid_from_samples(path, {a.shape[2], a.shape[1], a.shape[0]}, a.dtype, a.bytes);
}

void write_npy_volume(const fs::path& path, const AnyGrid3& grid) {
  const auto dims = detail::grid_dims(grid);
  NpyArray a;
  a.dtype = grid_dtype(grid);
  a.shape = {dims[2], dims[1], dims[0]};
  const auto bytes = detail::grid_bytes(grid);
  a.bytes.assign(bytes.begin(), bytes.end());
  write_npy(path, a);
}

}  // namespace

AnyGrid3 read_volume(const fs::path& path) {
  std::string ext = detail::extension(path);
  if (detail::is_gzip_name(path, &ext) && ext == ".nii") return detail::read_nifti(path);
  if (ext == ".npy") return read_npy_volume(path);
  if (ext == ".nrrd" || ext == ".nhdr") return detail::read_nrrd(path);
  if (ext == ".nii") return detail::read_nifti(path);
  fail(path, "unsupported volume format '" + detail::extension(path) + "' (expected .npy, .nrrd, .nhdr, .nii or .nii.gz)");
}

AnyGrid3 read_raw_volume(const fs::path& path, std::array<std::size_t, 3> dims, DType dtype) {
  for (std::size_t d : dims)
    if (d == 0) fail(path, "raw volume dimensions must be positive");
  const std::size_t need =
      detail::checked_mul(path, detail::checked_mul(path, detail::checked_mul(path, dims[0], dims[1]), dims[2]),
                          dtype_size(dtype));
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  // Checked before reading: a wrong dims or dtype is the usual mistake with raw files.
  if (!ec && size != need)
    fail(path, "raw file has " + std::to_string(size) + " bytes, but " + std::to_string(dims[0]) + "x" +
                   std::to_string(dims[1]) + "x" + std::to_string(dims[2]) + " " + std::string(dtype_name(dtype)) +
                   " samples need " + std::to_string(need));
  std::vector<std::uint8_t> bytes = detail::read_file(path);
  if (bytes.size() != need) fail(path, "raw file has " + std::to_string(bytes.size()) + " bytes, expected " + std::to_string(need));
  if constexpr (std::endian::native == std::endian::big) detail::swap_bytes(bytes, dtype_size(dtype));
  return detail::grid_from_samples(path, dims, dtype, bytes);
}

void write_volume(const fs::path& path, const AnyGrid3& grid) {
  const auto dims = detail::grid_dims(grid);
  if (dims[0] * dims[1] * dims[2] == 0 || detail::grid_bytes(grid).size() != dims[0] * dims[1] * dims[2] * dtype_size(grid_dtype(grid)))
    fail(path, "cannot write a volume whose data does not match its dimensions " + std::to_string(dims[0]) + "x" +
                   std::to_string(dims[1]) + "x" + std::to_string(dims[2]));
  std::string ext = detail::output_extension(path);
  if (detail::is_gzip_name(path, &ext) && ext == ".nii") return detail::write_nifti(path, grid);
  if (ext == ".npy") return write_npy_volume(path, grid);
  if (ext == ".nrrd") return detail::write_nrrd(path, grid);
  if (ext == ".nii") return detail::write_nifti(path, grid);
  fail(path, "unsupported volume format '" + detail::extension(path) + "' for writing (expected .npy, .nrrd, .nii or .nii.gz)");
}

}  // namespace geods::io
