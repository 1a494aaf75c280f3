// NIfTI-1 single-file volumes (.nii, .nii.gz) through nifticlib. The header is
// checked here first, so nifticlib never allocates for dimensions the file
// cannot hold.
#include <nifti1_io.h>

#include <cmath>
#include <cstring>

#include "file_util.hpp"
#include "volume_detail.hpp"

namespace geods::io::detail {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t header_size = 348;

struct NiftiType {
  DType dtype;
  int bytes;
};

bool nifti_type(int datatype, NiftiType& t) {
  switch (datatype) {
    case DT_UINT8: t = {DType::u8, 1}; return true;
    case DT_INT8: t = {DType::i8, 1}; return true;
    case DT_INT16: t = {DType::i16, 2}; return true;
    case DT_UINT16: t = {DType::u16, 2}; return true;
    case DT_INT32: t = {DType::i32, 4}; return true;
    case DT_UINT32: t = {DType::u32, 4}; return true;
    case DT_FLOAT32: t = {DType::f32, 4}; return true;
    case DT_FLOAT64: t = {DType::f64, 8}; return true;
    default: return false;
  }
}

struct Layout {
  std::array<std::size_t, 3> dims;  // nx, ny, nz
  std::size_t end;                  // vox_offset + sample bytes
};

// Validates the header, and for an uncompressed file its size too.
Layout check_header(const fs::path& path, std::span<const std::uint8_t> h, std::size_t file_size,
                                        bool gz) {
  if (h.size() < header_size) fail(path, "truncated: NIfTI header needs 348 bytes, file has " + std::to_string(h.size()));
  bool big = false;
  if (load<std::int32_t>(h.data(), false) != 348) {
    if (load<std::int32_t>(h.data(), true) != 348) fail(path, "not a NIfTI-1 file (sizeof_hdr is not 348)");
    big = true;
  }
  const std::string_view magic = as_text(h.subspan(344, 4));
  if (magic == std::string_view("ni1\0", 4)) fail(path, "two-file NIfTI (.hdr/.img) is not supported; convert to .nii");
  if (magic != std::string_view("n+1\0", 4)) fail(path, "not a NIfTI-1 file (wrong magic)");
  std::int16_t dim[8];
  for (int i = 0; i < 8; ++i) dim[i] = load<std::int16_t>(h.data() + 40 + 2 * i, big);
  if (dim[0] < 1 || dim[0] > 7) fail(path, "bad NIfTI dim[0] " + std::to_string(dim[0]));
  std::array<std::size_t, 3> dims{1, 1, 1};
  for (int i = 1; i <= dim[0]; ++i) {
    if (dim[i] < 1) fail(path, "bad NIfTI dimension dim[" + std::to_string(i) + "] = " + std::to_string(dim[i]));
    if (i <= 3) dims[std::size_t(i - 1)] = std::size_t(dim[i]);
    else if (dim[i] != 1)
      fail(path, std::to_string(dim[0]) + "-D NIfTI images with dim[" + std::to_string(i) + "] = " +
                     std::to_string(dim[i]) + " are not supported (only 3-D volumes)");
  }
  const int datatype = load<std::int16_t>(h.data() + 70, big);
  NiftiType t{};
  if (!nifti_type(datatype, t))
    fail(path, "unsupported NIfTI datatype " + std::to_string(datatype) + " (" + nifti_datatype_string(datatype) + ")");
  const float vox_offset = load<float>(h.data() + 108, big);
  if (!(vox_offset >= 348.0f) || vox_offset > float(file_size) || vox_offset > 1e12f) fail(path, "bad NIfTI vox_offset " + std::to_string(vox_offset));
  const std::size_t need = dims[0] * dims[1] * dims[2] * std::size_t(t.bytes);  // < 2^48: no overflow
  const std::size_t start = std::size_t(vox_offset);
  if (!gz && file_size - start < need)
    fail(path, "truncated: NIfTI data needs " + std::to_string(need) + " bytes after offset " + std::to_string(start) +
                   ", file has " + std::to_string(file_size - start));
  return {dims, start + need};
}

template <typename T>
const T* typed(const nifti_image* nim) {
  return static_cast<const T*>(nim->data);
}

struct NiftiFree {
  void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};

}  // namespace

AnyGrid3 read_nifti(const fs::path& path) {
  const std::vector<std::uint8_t> file = read_file(path);
  if (file.empty()) fail(path, "empty file");
  const bool gz = file.size() >= 2 && file[0] == 0x1f && file[1] == 0x8b;
  Layout layout;
  if (gz) {
    layout = check_header(path, gunzip(path, file, header_size, true), std::size_t(-1), true);
    // Inflating is bounded by what the header declares, and must reach it.
    const std::size_t have = gunzip(path, file, layout.end + (1u << 20)).size();
    if (have < layout.end)
      fail(path, "truncated: NIfTI data needs " + std::to_string(layout.end) + " bytes, file inflates to " + std::to_string(have));
  } else {
    layout = check_header(path, file, file.size(), false);
  }
  const auto& dims = layout.dims;

  nifti_set_debug_level(0);
  std::unique_ptr<nifti_image, NiftiFree> nim(nifti_image_read(path.c_str(), 1));
  if (!nim || !nim->data) fail(path, "nifticlib cannot read the file");
  if (std::size_t(nim->nx) != dims[0] || std::size_t(std::max(nim->ny, 1)) != dims[1] ||
      std::size_t(std::max(nim->nz, 1)) != dims[2] || nim->nvox != dims[0] * dims[1] * dims[2])
    fail(path, "nifticlib disagrees with the header's dimensions");
  NiftiType t{};
  if (!nifti_type(nim->datatype, t) || nim->nbyper != t.bytes) fail(path, "unsupported NIfTI datatype");
  const std::span<const std::uint8_t> samples(static_cast<const std::uint8_t*>(nim->data), nim->nvox * std::size_t(t.bytes));

  // Scaled data (scl_slope != 0 and not the identity) is converted to float with
  // value * scl_slope + scl_inter, as the NIfTI standard defines; otherwise the
  // samples keep the file's type.
  AnyGrid3 grid;
  const float slope = nim->scl_slope, inter = nim->scl_inter;
  if (slope != 0 && (slope != 1 || inter != 0)) {
    if (!std::isfinite(slope) || !std::isfinite(inter)) fail(path, "non-finite scl_slope or scl_inter");
    Grid3<float> scaled = to_float(grid_from_samples(path, dims, t.dtype, samples));
    for (float& v : scaled.data) v = v * slope + inter;
    grid = std::move(scaled);
  } else {
    grid = grid_from_samples(path, dims, t.dtype, samples);
  }

  // Origin from the qform (else the sform); spacing from pixdim. Rotations and
  // axis flips are not represented by Grid3 and are dropped.
  Vec3f origin = Vec3f::Zero(), spacing = Vec3f::Ones();
  if (nim->qform_code > 0) origin = {nim->qoffset_x, nim->qoffset_y, nim->qoffset_z};
  else if (nim->sform_code > 0) origin = {nim->sto_xyz.m[0][3], nim->sto_xyz.m[1][3], nim->sto_xyz.m[2][3]};
  if (!origin.allFinite()) origin = Vec3f::Zero();
  const float d[3] = {nim->dx, nim->dy, nim->dz};
  for (int i = 0; i < 3; ++i) spacing[i] = std::isfinite(d[i]) && d[i] != 0 ? std::abs(d[i]) : 1.0f;
  set_geometry(grid, origin, spacing);
  return grid;
}

void write_nifti(const fs::path& path, const AnyGrid3& grid) {
  const auto dims = grid_dims(grid);
  for (std::size_t d : dims)
    if (d > 32767) fail(path, "NIfTI-1 dimensions are limited to 32767, volume has " + std::to_string(d));
  int datatype = DT_FLOAT64;
  switch (grid_dtype(grid)) {
    case DType::u8: datatype = DT_UINT8; break;
    case DType::u16: datatype = DT_UINT16; break;
    case DType::i16: datatype = DT_INT16; break;
    case DType::f32: datatype = DT_FLOAT32; break;
    default: break;
  }
  const int nifti_dims[8] = {3, int(dims[0]), int(dims[1]), int(dims[2]), 1, 1, 1, 1};
  std::unique_ptr<nifti_image, NiftiFree> nim(nifti_make_new_nim(nifti_dims, datatype, 0));
  if (!nim) fail(path, "nifticlib cannot create the image");
  const Vec3f o = grid_origin(grid), s = grid_spacing(grid);
  nim->dx = nim->pixdim[1] = s.x();
  nim->dy = nim->pixdim[2] = s.y();
  nim->dz = nim->pixdim[3] = s.z();
  nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
  nim->sform_code = NIFTI_XFORM_UNKNOWN;
  nim->quatern_b = nim->quatern_c = nim->quatern_d = 0;
  nim->qfac = 1;
  nim->qoffset_x = o.x();
  nim->qoffset_y = o.y();
  nim->qoffset_z = o.z();
  nim->xyz_units = NIFTI_UNITS_MM;
  nim->nifti_type = NIFTI_FTYPE_NIFTI1_1;
  if (nifti_set_filenames(nim.get(), path.c_str(), 0, 1) != 0) fail(path, "nifticlib rejects the file name");
  // nifticlib only reads the samples; it must not free our buffer.
  nim->data = const_cast<std::uint8_t*>(grid_bytes(grid).data());
  nifti_set_debug_level(0);
  std::error_code ec;
  fs::remove(path, ec);
  nifti_image_write(nim.get());
  nim->data = nullptr;
  const std::size_t min_size = is_gzip_name(path) ? 20 : header_size + 4;
  if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) < min_size) fail(path, "cannot write NIfTI file");
}

}  // namespace geods::io::detail
