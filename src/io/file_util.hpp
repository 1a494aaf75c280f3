#pragma once
// Helpers shared by the readers and writers of geods::io (not public API):
// whole-file reads with errors that name the file, gzip, byte order, text parsing.
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "geods/core/error.hpp"

namespace geods::io::detail {

/// Throws geods::Error "<path>: <message>".
[[noreturn]] void fail(const std::filesystem::path& path, const std::string& message);

/// True for the path "-": standard input for a reader, standard output for a writer.
inline bool is_standard_stream(const std::filesystem::path& path) { return path.native() == "-"; }

/// The whole file; throws for missing, unreadable or non-regular files.
/// "-" is standard input, read to its end once and kept, so that every
/// reader of "-" in a process sees the same bytes.
std::vector<std::uint8_t> read_file(const std::filesystem::path& path);
/// Writes the bytes, replacing the file; throws if it cannot. "-" writes to
/// standard output, once per process (a second output there is an error).
void write_file(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);
void write_file(const std::filesystem::path& path, std::string_view text);
/// True once write_file wrote to standard output.
bool standard_output_used();

/// Lower-case extension with the dot (".ply"); for "x.ply.gz" it is ".gz".
/// For "-" (standard input) the format its bytes show: ".npy" (numpy magic),
/// ".ply" ("ply" line), ".off" (first word ending in OFF), ".gz" (gzip magic),
/// else ".txt" (a text table).
std::string extension(const std::filesystem::path& path);
/// The extension a writer dispatches on: extension(path), and ".npy" for "-".
std::string output_extension(const std::filesystem::path& path);
/// True for a ".gz" file name; `inner` receives the extension below it (".ply").
bool is_gzip_name(const std::filesystem::path& path, std::string* inner = nullptr);

/// Inflates gzip (or zlib) data. More than `max_bytes` of output is an error
/// naming the file, so a small hostile file cannot make us allocate without bound.
/// With `prefix`, returns the first max_bytes (or fewer, if the data ends) instead.
std::vector<std::uint8_t> gunzip(const std::filesystem::path& path, std::span<const std::uint8_t> data,
                                 std::size_t max_bytes, bool prefix = false);
/// Compresses into the gzip format.
std::vector<std::uint8_t> gzip(std::span<const std::uint8_t> data);

/// a * b, or fail(path, what overflows) if the product overflows size_t.
std::size_t checked_mul(const std::filesystem::path& path, std::size_t a, std::size_t b);

/// Loads a T stored at p in the given byte order.
template <typename T>
T load(const std::uint8_t* p, bool big_endian) {
  std::uint8_t b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  }
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

/// Reverses the bytes of each `width`-byte element in place.
void swap_bytes(std::span<std::uint8_t> bytes, std::size_t width);

/// Parses a whole token as a number (leading '+' allowed); false if it is not one.
bool parse_double(std::string_view token, double& value);
bool parse_size(std::string_view token, std::size_t& value);

/// Splits on spaces, tabs and carriage returns (and on commas if `commas`).
std::vector<std::string_view> split_fields(std::string_view line, bool commas = false);

/// Iterates over the lines of a text buffer (without "\n" or "\r\n"), counting from 1.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  bool next(std::string_view& line);
  std::size_t line_number() const { return line_; }
  std::size_t offset() const { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0, line_ = 0;
};

inline std::string_view as_text(std::span<const std::uint8_t> bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

std::string_view trim(std::string_view s);

/// The fields of a text line, with its line number for messages.
struct TextRow {
  std::size_t line;
  std::vector<std::string_view> fields;
};

/// The rows of a text file (.xyz, .csv, .edg, .cin...): blank lines and lines
/// starting with '#' are skipped; fields are split as split_fields does.
std::vector<TextRow> text_rows(std::string_view text, bool commas);

/// Field `column` of the row as a finite number; fails naming the line otherwise.
double number(const std::filesystem::path& path, const TextRow& row, std::size_t column);

/// True if the double converts to a finite float (casting one that does not is undefined behaviour).
inline bool fits_float(double v) { return v >= -3.4028234663852886e38 && v <= 3.4028234663852886e38; }

}  // namespace geods::io::detail
