#include "geods/io/output.hpp"

#include "file_util.hpp"

namespace geods::io {

namespace fs = std::filesystem;

namespace {

const char* kind_name(OutputKind kind) {
  switch (kind) {
    case OutputKind::table: return "a table";
    case OutputKind::array: return "an array";
    case OutputKind::mesh: return "a mesh";
    case OutputKind::image: return "an image";
    case OutputKind::svg: return "an SVG figure";
    case OutputKind::json: return "JSON";
  }
  return "this output";
}

}  // namespace

const std::vector<std::string>& output_extensions(OutputKind kind) {
  static const std::vector<std::string> table = {".npy", ".csv", ".txt"}, array = {".npy"},
                                        mesh = {".ply", ".obj", ".stl"}, image = {".png"}, svg = {".svg"},
                                        json = {".json"};
  switch (kind) {
    case OutputKind::table: return table;
    case OutputKind::array: return array;
    case OutputKind::mesh: return mesh;
    case OutputKind::image: return image;
    case OutputKind::svg: return svg;
    case OutputKind::json: return json;
  }
  return array;
}

bool standard_output_allowed(OutputKind kind) { return kind != OutputKind::mesh && kind != OutputKind::image; }

void check_output_extension(const fs::path& path, OutputKind kind) {
  if (detail::is_standard_stream(path)) {
    if (standard_output_allowed(kind)) return;
  } else {
    const std::string ext = detail::extension(path);
    for (const std::string& e : output_extensions(kind))
      if (ext == e) return;
  }
  std::string accepted;
  for (const std::string& e : output_extensions(kind)) accepted += (accepted.empty() ? "" : ", ") + e;
  if (standard_output_allowed(kind)) accepted += "; - for standard output";
  // Appended, not "'" + extension: GCC 12 at -O3 warns falsely (-Wstringop-overflow) on that insert at the front.
  std::string ext = "standard output";
  if (!detail::is_standard_stream(path)) ext = std::string("'").append(detail::extension(path)).append("'");
  detail::fail(path, std::string("cannot write ") + kind_name(kind) + " as " + (ext == "''" ? "a file without extension" : ext) +
                         " (accepted: " + accepted + ")");
}

void write_text(const fs::path& path, std::string_view text) { detail::write_file(path, text); }

bool standard_output_used() { return detail::standard_output_used(); }

}  // namespace geods::io
