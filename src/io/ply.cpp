#include "ply.hpp"

#include <cctype>
#include <array>
#include <cmath>
#include <limits>

#include "file_util.hpp"

namespace geods::io::detail {

namespace fs = std::filesystem;

namespace {

bool scalar_type(std::string_view t, PlyProperty& p) {
  struct Entry {
    std::string_view a, b;
    int size;
    bool is_float, is_signed;
  };
  static constexpr Entry types[] = {
      {"char", "int8", 1, false, true},     {"uchar", "uint8", 1, false, false},  {"short", "int16", 2, false, true},
      {"ushort", "uint16", 2, false, false}, {"int", "int32", 4, false, true},     {"uint", "uint32", 4, false, false},
      {"float", "float32", 4, true, true},   {"double", "float64", 8, true, true},
  };
  for (const Entry& e : types) {
    if (t == e.a || t == e.b) {
      p.size = e.size;
      p.is_float = e.is_float;
      p.is_signed = e.is_signed;
      return true;
    }
  }
  return false;
}

double load_binary(const std::uint8_t* p, const PlyProperty& prop, bool big) {
  if (prop.is_float) return prop.size == 4 ? double(load<float>(p, big)) : load<double>(p, big);
  switch (prop.size) {
    case 1: return prop.is_signed ? double(std::int8_t(*p)) : double(*p);
    case 2: return prop.is_signed ? double(load<std::int16_t>(p, big)) : double(load<std::uint16_t>(p, big));
    default: return prop.is_signed ? double(load<std::int32_t>(p, big)) : double(load<std::uint32_t>(p, big));
  }
}

// Reads the body one value at a time, binary or ascii, and reports where it ran out.
class BodyReader {
 public:
  BodyReader(const fs::path& path, std::span<const std::uint8_t> body, PlyFormat format)
      : path_(path), body_(body), format_(format) {}

  double value(int size, bool is_float, bool is_signed, const PlyElement& e, std::size_t k) {
    // The message is only built on failure: this runs once per value.
    auto what = [&] { return e.name + " " + std::to_string(k) + " of " + std::to_string(e.count); };
    if (format_ == PlyFormat::ascii) {
      while (pos_ < body_.size() && std::isspace(body_[pos_])) ++pos_;
      const std::size_t start = pos_;
      while (pos_ < body_.size() && !std::isspace(body_[pos_])) ++pos_;
      if (start == pos_) fail(path_, "truncated: file ends while reading " + what());
      double v = 0;
      if (!parse_double(as_text(body_.subspan(start, pos_ - start)), v))
        fail(path_, "malformed number '" + std::string(as_text(body_.subspan(start, std::min<std::size_t>(pos_ - start, 40)))) +
                        "' in " + what());
      return v;
    }
    if (body_.size() - pos_ < std::size_t(size)) fail(path_, "truncated: file ends while reading " + what());
    PlyProperty p;
    p.size = size;
    p.is_float = is_float;
    p.is_signed = is_signed;
    const double v = load_binary(body_.data() + pos_, p, format_ == PlyFormat::binary_be);
    pos_ += std::size_t(size);
    return v;
  }
  std::size_t remaining() const { return body_.size() - pos_; }

 private:
  const fs::path& path_;
  std::span<const std::uint8_t> body_;
  PlyFormat format_;
  std::size_t pos_ = 0;
};

}  // namespace

PlyHeader parse_ply_header(const fs::path& path, std::span<const std::uint8_t> file) {
  if (file.empty()) fail(path, "empty file");
  const std::string_view text = as_text(file);
  if (text.substr(0, 3) != "ply" || (text.size() > 3 && text[3] != '\n' && text[3] != '\r'))
    fail(path, "not a PLY file (wrong magic)");
  PlyHeader h;
  LineReader lines(text);
  std::string_view line;
  bool have_format = false, done = false;
  lines.next(line);
  while (lines.next(line)) {
    const auto f = split_fields(line);
    const std::string where = " (header line " + std::to_string(lines.line_number()) + ")";
    if (f.empty() || f[0] == "comment" || f[0] == "obj_info") continue;
    if (f[0] == "end_header") {
      done = true;
      break;
    }
    if (f[0] == "format") {
      if (f.size() != 3) fail(path, "malformed format line" + where);
      if (f[1] == "ascii") h.format = PlyFormat::ascii;
      else if (f[1] == "binary_little_endian") h.format = PlyFormat::binary_le;
      else if (f[1] == "binary_big_endian") h.format = PlyFormat::binary_be;
      else fail(path, "unknown PLY format '" + std::string(f[1]) + "'" + where);
      have_format = true;
    } else if (f[0] == "element") {
      PlyElement e;
      if (f.size() != 3 || !parse_size(f[2], e.count)) fail(path, "malformed element line" + where);
      e.name = f[1];
      h.elements.push_back(std::move(e));
    } else if (f[0] == "property") {
      if (h.elements.empty()) fail(path, "property before any element" + where);
      PlyProperty p;
      if (f.size() == 5 && f[1] == "list") {
        PlyProperty count;
        if (!scalar_type(f[2], count) || count.is_float || !scalar_type(f[3], p))
          fail(path, "malformed list property" + where);
        p.count_size = count.size;
        p.name = f[4];
      } else if (f.size() == 3 && scalar_type(f[1], p)) {
        p.name = f[2];
      } else {
        fail(path, "malformed property line" + where);
      }
      h.elements.back().properties.push_back(std::move(p));
    } else {
      fail(path, "unexpected header line '" + std::string(line.substr(0, 40)) + "'" + where);
    }
  }
  if (!done) fail(path, "truncated: no end_header");
  if (!have_format) fail(path, "missing format line");
  h.body_offset = std::min(lines.offset(), file.size());

  // Every value takes at least one byte (binary: its size; ascii: a digit and
  // a separator), so the counts are bounded by the bytes after the header.
  const std::size_t body = file.size() - h.body_offset;
  for (const PlyElement& e : h.elements) {
    if (e.properties.empty() && e.count > 0) fail(path, "element '" + e.name + "' has no properties");
    std::size_t per = 0;
    for (const PlyProperty& p : e.properties)
      per += h.format == PlyFormat::ascii ? 2 : std::size_t(p.count_size ? p.count_size : p.size);
    if (per != 0 && e.count > (body + 1) / per)
      fail(path, "truncated: header declares " + std::to_string(e.count) + " " + e.name + " elements but only " +
                     std::to_string(body) + " bytes follow the header");
  }
  return h;
}

PlyData read_ply(const fs::path& path, std::span<const std::uint8_t> file) {
  const PlyHeader h = parse_ply_header(path, file);
  BodyReader in(path, file.subspan(h.body_offset), h.format);
  PlyData out;
  std::size_t num_vertices = 0;
  bool found = false;
  for (const PlyElement& e : h.elements) {
    const bool is_vertex = e.name == "vertex" && !found;
    const bool is_face = e.name == "face";
    int axis[6] = {-1, -1, -1, -1, -1, -1};  // x y z nx ny nz
    int indices = -1;
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const PlyProperty& p = e.properties[i];
      if (is_face && p.count_size && (p.name == "vertex_indices" || p.name == "vertex_index")) indices = int(i);
      if (p.count_size) continue;
      for (int a = 0; a < 6; ++a)
        if (p.name == std::array<const char*, 6>{"x", "y", "z", "nx", "ny", "nz"}[std::size_t(a)]) axis[a] = int(i);
    }
    if (is_vertex) {
      if (axis[0] < 0 || axis[1] < 0) fail(path, "vertex element has no x and y properties");
      found = true;
      num_vertices = e.count;
      out.dim = axis[2] < 0 ? 2 : 3;
      out.positions.reserve(e.count * std::size_t(out.dim));  // bounded by the header check
      if (axis[3] >= 0 && axis[4] >= 0 && axis[5] >= 0) out.normals.reserve(e.count * 3);
    }
    if (is_face && indices >= 0 && !found) fail(path, "face element before the vertex element");
    std::vector<double> row(e.properties.size());
    std::vector<std::uint32_t> polygon;
    for (std::size_t k = 0; k < e.count; ++k) {
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const PlyProperty& p = e.properties[i];
        if (!p.count_size) {
          row[i] = in.value(p.size, p.is_float, p.is_signed, e, k);
          continue;
        }
        const double n = in.value(p.count_size, false, false, e, k);
        if (!(n >= 0) || n != std::floor(n)) fail(path, "bad list length in " + e.name + " " + std::to_string(k));
        if (n > double(in.remaining()))
          fail(path, "truncated: list of " + std::to_string(std::size_t(n)) + " items in " + e.name + " " + std::to_string(k));
        polygon.clear();
        for (std::size_t j = 0; j < std::size_t(n); ++j) {
          const double v = in.value(p.size, p.is_float, p.is_signed, e, k);
          if (int(i) != indices) continue;
          if (!(v >= 0 && v < double(num_vertices)) || v != std::floor(v))
            fail(path, "face " + std::to_string(k) + " has vertex index " + std::to_string(v) + " out of range (" +
                           std::to_string(num_vertices) + " vertices)");
          polygon.push_back(std::uint32_t(v));
        }
        if (int(i) == indices) {
          if (polygon.size() < 3) fail(path, "face " + std::to_string(k) + " has fewer than 3 vertices");
          for (std::size_t j = 1; j + 1 < polygon.size(); ++j)
            out.triangles.insert(out.triangles.end(), {polygon[0], polygon[j], polygon[j + 1]});
        }
      }
      if (is_vertex) {
        for (int d = 0; d < out.dim; ++d) {
          const double v = row[std::size_t(axis[d])];
          if (!std::isfinite(v)) fail(path, "vertex " + std::to_string(k) + " has a non-finite coordinate");
          out.positions.push_back(v);
        }
        if (out.normals.capacity())
          for (int d = 3; d < 6; ++d) {
            const double v = row[std::size_t(axis[d])];
            out.normals.push_back(fits_float(v) ? float(v) : std::numeric_limits<float>::quiet_NaN());
          }
      }
    }
  }
  if (!found) fail(path, "no vertex element");
  const std::span<const std::uint8_t> rest = file.last(in.remaining());
  if (h.format == PlyFormat::ascii ? !trim(as_text(rest)).empty() : !rest.empty())
    fail(path, std::to_string(in.remaining()) + " unexpected bytes after the last element");
  return out;
}

}  // namespace geods::io::detail
