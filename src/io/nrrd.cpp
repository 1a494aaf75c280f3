// NRRD (teem's "nearly raw raster data"): a text header, then raw or gzip samples,
// attached (.nrrd) or in a separate file named by "data file:" (.nhdr).
#include <fmt/format.h>

#include <cmath>
#include <map>

#include "file_util.hpp"
#include "volume_detail.hpp"

namespace geods::io::detail {

namespace fs = std::filesystem;

namespace {

DType nrrd_type(const fs::path& path, const std::string& t) {
  static const std::map<std::string, DType> types = {
      {"uchar", DType::u8},         {"unsigned char", DType::u8},     {"uint8", DType::u8},
      {"uint8_t", DType::u8},       {"signed char", DType::i8},       {"int8", DType::i8},
      {"int8_t", DType::i8},        {"short", DType::i16},            {"short int", DType::i16},
      {"signed short", DType::i16}, {"signed short int", DType::i16}, {"int16", DType::i16},
      {"int16_t", DType::i16},      {"ushort", DType::u16},           {"unsigned short", DType::u16},
      {"unsigned short int", DType::u16}, {"uint16", DType::u16},     {"uint16_t", DType::u16},
      {"int", DType::i32},          {"signed int", DType::i32},       {"int32", DType::i32},
      {"int32_t", DType::i32},      {"uint", DType::u32},             {"unsigned int", DType::u32},
      {"uint32", DType::u32},       {"uint32_t", DType::u32},         {"float", DType::f32},
      {"double", DType::f64},
  };
  const auto it = types.find(t);
  if (it == types.end()) fail(path, "unsupported NRRD type '" + t + "'");
  return it->second;
}

std::string nrrd_type_name(DType t) {
  switch (t) {
    case DType::u8: return "uchar";
    case DType::u16: return "ushort";
    case DType::i16: return "short";
    case DType::f32: return "float";
    default: return "double";
  }
}

// "(1,0,0)" -> {1, 0, 0}; "none" -> empty.
std::vector<double> parse_vector(const fs::path& path, std::string_view s, const std::string& field) {
  s = trim(s);
  if (s == "none") return {};
  if (s.size() < 2 || s.front() != '(' || s.back() != ')') fail(path, "malformed vector '" + std::string(s.substr(0, 60)) + "' in " + field);
  std::vector<double> v;
  for (std::string_view t : split_fields(s.substr(1, s.size() - 2), true)) {
    double x = 0;
    if (!parse_double(t, x) || !std::isfinite(x)) fail(path, "malformed number '" + std::string(t.substr(0, 40)) + "' in " + field);
    v.push_back(x);
  }
  return v;
}

// Splits "(a,b,c) none (d,e,f)" into its vectors.
std::vector<std::string_view> split_vectors(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    if (i >= s.size()) break;
    const std::size_t start = i;
    if (s[i] == '(') {
      const std::size_t close = s.find(')', i);
      i = close == std::string_view::npos ? s.size() : close + 1;
    } else {
      while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
    }
    out.push_back(s.substr(start, i - start));
  }
  return out;
}

}  // namespace

AnyGrid3 read_nrrd(const fs::path& path) {
  std::vector<std::uint8_t> file = read_file(path);
  if (file.empty()) fail(path, "empty file");
  const std::string_view text = as_text(file);
  if (text.substr(0, 7) != "NRRD000" || text.size() < 8) fail(path, "not a NRRD file (wrong magic)");

  std::map<std::string, std::string> fields;
  LineReader lines(text);
  std::string_view line;
  lines.next(line);
  bool attached_data = false;
  while (lines.next(line)) {
    if (line.empty()) {
      attached_data = true;  // a blank line ends the header; the data follows
      break;
    }
    if (line[0] == '#') continue;
    const std::size_t colon = line.find(": ");
    if (colon == std::string_view::npos) {
      if (line.find(":=") != std::string_view::npos) continue;  // key/value pairs carry no geometry
      fail(path, "malformed header line " + std::to_string(lines.line_number()) + ": '" + std::string(line.substr(0, 60)) + "'");
    }
    std::string key(line.substr(0, colon));
    if (key == "datafile") key = "data file";
    if (key == "spacedirections") key = "space directions";
    if (key == "spaceorigin") key = "space origin";
    if (key == "byteskip") key = "byte skip";
    if (key == "lineskip") key = "line skip";
    fields[key] = std::string(trim(line.substr(colon + 2)));
  }
  auto field = [&](const std::string& key) -> const std::string* {
    const auto it = fields.find(key);
    return it == fields.end() ? nullptr : &it->second;
  };
  for (const char* required : {"type", "dimension", "sizes", "encoding"})
    if (!field(required)) fail(path, std::string("NRRD header has no '") + required + "' field");

  const DType dtype = nrrd_type(path, *field("type"));
  if (*field("dimension") != "3") fail(path, "only 3-D NRRD volumes are supported (dimension: " + *field("dimension") + ")");
  std::array<std::size_t, 3> dims{};
  const auto sizes = split_fields(*field("sizes"));
  if (sizes.size() != 3) fail(path, "'sizes' must have 3 entries");
  for (int i = 0; i < 3; ++i)
    if (!parse_size(sizes[std::size_t(i)], dims[std::size_t(i)]) || dims[std::size_t(i)] == 0)
      fail(path, "malformed 'sizes': '" + *field("sizes") + "'");
  const std::size_t need = checked_mul(path, checked_mul(path, checked_mul(path, dims[0], dims[1]), dims[2]), dtype_size(dtype));

  bool big_endian = false;
  if (const std::string* e = field("endian")) {
    if (*e == "big") big_endian = true;
    else if (*e != "little") fail(path, "unknown endian '" + *e + "'");
  } else if (dtype_size(dtype) > 1) {
    fail(path, "NRRD header has no 'endian' field for multi-byte samples");
  }
  const std::string& encoding = *field("encoding");
  const bool gzip = encoding == "gzip" || encoding == "gz";
  if (!gzip && encoding != "raw") fail(path, "unsupported NRRD encoding '" + encoding + "' (raw or gzip)");

  std::size_t line_skip = 0;
  long long byte_skip = 0;
  if (const std::string* s = field("line skip"))
    if (!parse_size(*s, line_skip)) fail(path, "malformed 'line skip'");
  if (const std::string* s = field("byte skip")) {
    std::size_t v = 0;
    if (*s == "-1") byte_skip = -1;
    else if (parse_size(*s, v) && v < (1ull << 62)) byte_skip = (long long)v;
    else fail(path, "malformed 'byte skip'");
    if (byte_skip < 0 && gzip) fail(path, "'byte skip: -1' is only allowed with raw encoding");
  }

  // The data: after the blank line, or in the file that "data file" names.
  std::vector<std::uint8_t> detached;
  fs::path data_path = path;
  std::span<const std::uint8_t> data;
  if (const std::string* name = field("data file")) {
    if (name->starts_with("LIST") || name->find('%') != std::string::npos)
      fail(path, "multi-file NRRD data ('data file: " + *name + "') is not supported");
    data_path = fs::path(*name).is_absolute() ? fs::path(*name) : path.parent_path() / *name;
    std::error_code ec;
    if (fs::equivalent(data_path, path, ec))
      fail(path, "'data file' names the header itself");
    try {
      detached = read_file(data_path);
    } catch (const Error& e) {
      fail(path, std::string("data file: ") + e.what());
    }
    data = detached;
  } else {
    if (!attached_data) fail(path, "truncated: no blank line ending the header (and no 'data file')");
    data = std::span<const std::uint8_t>(file).subspan(std::min(lines.offset(), file.size()));
  }
  for (std::size_t l = 0; l < line_skip; ++l) {
    const auto nl = std::find(data.begin(), data.end(), std::uint8_t('\n'));
    if (nl == data.end()) fail(data_path, "truncated: cannot skip " + std::to_string(line_skip) + " lines");
    data = data.subspan(std::size_t(nl - data.begin()) + 1);
  }
  std::vector<std::uint8_t> inflated;
  if (gzip) {
    if (need > std::size_t(-1) - std::size_t(byte_skip)) fail(path, "'byte skip' too large");
    inflated = gunzip(data_path, data, need + std::size_t(byte_skip));
    data = inflated;
  }
  if (byte_skip < 0) {
    if (data.size() < need)
      fail(data_path, "truncated: volume needs " + std::to_string(need) + " bytes, file has " + std::to_string(data.size()));
    data = data.last(need);
  } else {
    if (std::size_t(byte_skip) > data.size()) fail(data_path, "truncated: 'byte skip' beyond the end of the data");
    data = data.subspan(std::size_t(byte_skip));
  }
  if (data.size() < need)
    fail(data_path, "truncated: " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" + std::to_string(dims[2]) +
                        " " + *field("type") + " samples need " + std::to_string(need) + " bytes, data has " +
                        std::to_string(data.size()));
  if (data.size() > need) fail(data_path, std::to_string(data.size() - need) + " unexpected bytes after the volume data");

  std::vector<std::uint8_t> samples(data.begin(), data.end());
  if (big_endian != (std::endian::native == std::endian::big)) swap_bytes(samples, dtype_size(dtype));
  AnyGrid3 grid = grid_from_samples(path, dims, dtype, samples);

  // Geometry: each axis's spacing is the length of its space direction (a
  // rotation is not represented by Grid3), else "spacings"; origin from "space origin".
  Vec3f origin = Vec3f::Zero(), spacing = Vec3f::Ones();
  if (const std::string* s = field("space directions")) {
    const auto vectors = split_vectors(*s);
    if (vectors.size() != 3) fail(path, "'space directions' must have 3 entries");
    for (int i = 0; i < 3; ++i) {
      const auto v = parse_vector(path, vectors[std::size_t(i)], "space directions");
      if (v.empty()) continue;
      double len = 0;
      for (double x : v) len += x * x;
      len = std::sqrt(len);
      if (!(len > 0) || !fits_float(len)) fail(path, "degenerate space direction for axis " + std::to_string(i));
      spacing[i] = float(len);
    }
  } else if (const std::string* s = field("spacings")) {
    const auto values = split_fields(*s);
    if (values.size() != 3) fail(path, "'spacings' must have 3 entries");
    for (int i = 0; i < 3; ++i) {
      double v = 0;
      if (!parse_double(values[std::size_t(i)], v)) fail(path, "malformed 'spacings'");
      if (v > 0 && fits_float(v)) spacing[i] = float(v);  // "nan" means unknown
    }
  }
  if (const std::string* s = field("space origin")) {
    const auto v = parse_vector(path, *s, "space origin");
    if (v.size() < 3) fail(path, "'space origin' must have 3 components");
    for (int i = 0; i < 3; ++i) {
      if (!fits_float(v[std::size_t(i)])) fail(path, "'space origin' out of float range");
      origin[i] = float(v[std::size_t(i)]);
    }
  }
  set_geometry(grid, origin, spacing);
  return grid;
}

void write_nrrd(const fs::path& path, const AnyGrid3& grid) {
  const auto d = grid_dims(grid);
  const Vec3f o = grid_origin(grid), s = grid_spacing(grid);
  std::string header = fmt::format(
      "NRRD0004\n# written by geods\ntype: {}\ndimension: 3\nspace dimension: 3\nsizes: {} {} {}\n"
      "space directions: ({},0,0) (0,{},0) (0,0,{})\nspace origin: ({},{},{})\nkinds: domain domain domain\n"
      "endian: little\nencoding: raw\n\n",
      nrrd_type_name(grid_dtype(grid)), d[0], d[1], d[2], s.x(), s.y(), s.z(), o.x(), o.y(), o.z());
  std::vector<std::uint8_t> out(header.begin(), header.end());
  const auto bytes = grid_bytes(grid);
  out.insert(out.end(), bytes.begin(), bytes.end());
  if constexpr (std::endian::native == std::endian::big)
    swap_bytes(std::span(out).subspan(header.size()), dtype_size(grid_dtype(grid)));
  write_file(path, out);
}

}  // namespace geods::io::detail
