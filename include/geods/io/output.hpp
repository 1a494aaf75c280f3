#pragma once
// Output files: the formats each kind of result can be written in, checked by
// name before any work is done, and standard output ("-").
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace geods::io {

/// What is written: decides the accepted extensions.
enum class OutputKind {
  table,  // a 1-D or 2-D array of numbers (indices, counts, distances): .npy, .csv, .txt (write_table)
  array,  // an array of any number of dimensions: .npy
  mesh,   // a triangle mesh: .ply, .obj, .stl (write_mesh)
  image,  // a picture: .png (write_png)
  svg,    // an SVG figure: .svg (SvgWriter::save)
  json,   // a JSON document: .json (write_text)
};

/// The extensions `kind` can be written as, with the dot (".npy", ".csv", ...).
const std::vector<std::string>& output_extensions(OutputKind kind);
/// True if `kind` can be written to standard output, named "-": tables and
/// arrays (as .npy bytes), SVG and JSON (as text); not meshes and images.
bool standard_output_allowed(OutputKind kind);

/// Throws geods::Error unless `path` names a file `kind` can be written as:
/// "x.csv: cannot write an image as '.csv' (accepted: .png)". Commands call it
/// for every output before they read or compute anything.
void check_output_extension(const std::filesystem::path& path, OutputKind kind);

/// Writes text to `path` ("-": standard output), replacing the file.
void write_text(const std::filesystem::path& path, std::string_view text);

/// True once geods wrote an output to standard output ("-"); a second output
/// there is an error. The CLI then prints its report on standard error.
bool standard_output_used();

}  // namespace geods::io
