#include "file_util.hpp"

#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cmath>
#include <fstream>
#include <limits>

namespace geods::io::detail {

namespace fs = std::filesystem;

void fail(const fs::path& path, const std::string& message) { throw Error(path.string() + ": " + message); }

namespace {

std::atomic<bool> stdout_used{false};

const std::vector<std::uint8_t>& standard_input() {
  static const std::vector<std::uint8_t> bytes = [] {
    std::vector<std::uint8_t> b;
    std::uint8_t buffer[1 << 16];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof(buffer), stdin)) > 0) b.insert(b.end(), buffer, buffer + n);
    if (std::ferror(stdin)) throw Error("-: read error on standard input");
    return b;
  }();
  return bytes;
}

std::string sniff(std::span<const std::uint8_t> bytes) {
  const std::string_view text = as_text(bytes);
  if (text.starts_with("\x93NUMPY")) return ".npy";
  if (bytes.size() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b) return ".gz";
  if (text.starts_with("ply\n") || text.starts_with("ply\r\n")) return ".ply";
  const std::string_view head = trim(text.substr(0, 64));
  const std::string_view word = head.substr(0, head.find_first_of(" \t\r\n"));
  if (word.size() >= 3 && word.size() <= 5 && word.ends_with("OFF")) return ".off";
  return ".txt";
}

}  // namespace

bool standard_output_used() { return stdout_used.load(); }

std::vector<std::uint8_t> read_file(const fs::path& path) {
  if (is_standard_stream(path)) {
    const std::vector<std::uint8_t>& bytes = standard_input();
    if (bytes.empty()) fail(path, "standard input is empty");
    return bytes;
  }
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) fail(path, "no such file");
  if (fs::is_directory(status)) fail(path, "is a directory, not a file");
  // Devices and pipes could be endless (/dev/zero): only regular files are read.
  if (!fs::is_regular_file(status)) fail(path, "not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open for reading");
  std::vector<std::uint8_t> bytes;
  // The reported size is only a hint (the file may change, /proc reports 0):
  // read until the end, growing as needed.
  const std::uintmax_t hint = fs::file_size(path, ec);
  std::size_t chunk = ec ? 4096 : std::size_t(hint) + 1;
  for (;;) {
    const std::size_t old = bytes.size();
    bytes.resize(old + chunk);
    in.read(reinterpret_cast<char*>(bytes.data() + old), std::streamsize(chunk));
    bytes.resize(old + std::size_t(in.gcount()));
    if (!in) break;
    chunk = std::max<std::size_t>(bytes.size(), 1 << 16);
  }
  if (in.bad()) fail(path, "read error");
  return bytes;
}

void write_file(const fs::path& path, std::span<const std::uint8_t> bytes) {
  if (is_standard_stream(path)) {
    if (stdout_used.exchange(true)) fail(path, "standard output already holds another output; give a file name");
    if (std::fwrite(bytes.data(), 1, bytes.size(), stdout) != bytes.size() || std::fflush(stdout) != 0)
      fail(path, "write error on standard output");
    return;
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) fail(path, "cannot open for writing");
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  out.close();
  if (!out) fail(path, "write error");
}

void write_file(const fs::path& path, std::string_view text) {
  write_file(path, std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

std::string extension(const fs::path& path) {
  if (is_standard_stream(path)) return sniff(standard_input());
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

std::string output_extension(const fs::path& path) { return is_standard_stream(path) ? ".npy" : extension(path); }

bool is_gzip_name(const fs::path& path, std::string* inner) {
  if (is_standard_stream(path)) return false;
  if (extension(path) != ".gz") return false;
  if (inner) *inner = extension(path.stem());
  return true;
}

namespace {
// zlib counts in 32-bit units: hands it the next chunk of at most 1 GiB once it used up the last.
void feed_input(z_stream& zs, std::span<const std::uint8_t> data, std::size_t& consumed) {
  if (zs.avail_in != 0 || consumed == data.size()) return;
  const std::size_t n = std::min<std::size_t>(data.size() - consumed, 1u << 30);
  zs.next_in = const_cast<Bytef*>(data.data() + consumed);
  zs.avail_in = uInt(n);
  consumed += n;
}
}  // namespace

std::vector<std::uint8_t> gunzip(const fs::path& path, std::span<const std::uint8_t> data, std::size_t max_bytes,
                                 bool prefix) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 32) != Z_OK) fail(path, "cannot initialize zlib");  // 32: gzip or zlib header
  std::vector<std::uint8_t> out;
  std::size_t consumed = 0;
  int rc = Z_OK;
  std::uint8_t buffer[1 << 16];
  for (;;) {
    feed_input(zs, data, consumed);
    zs.next_out = buffer;
    zs.avail_out = sizeof(buffer);
    rc = inflate(&zs, Z_NO_FLUSH);
    const std::size_t produced = sizeof(buffer) - zs.avail_out;
    if (out.size() + produced > max_bytes) {
      inflateEnd(&zs);
      if (prefix) {
        out.insert(out.end(), buffer, buffer + (max_bytes - out.size()));
        return out;
      }
      fail(path, "gzip data expands to more than the expected " + std::to_string(max_bytes) + " bytes");
    }
    out.insert(out.end(), buffer, buffer + produced);
    if (rc == Z_STREAM_END) {
      // Concatenated gzip members are legal (gzip -c a b): continue with the next one.
      if (zs.avail_in == 0 && consumed == data.size()) break;
      if (inflateReset(&zs) != Z_OK) break;
      continue;
    }
    if (rc == Z_BUF_ERROR && zs.avail_in == 0 && consumed == data.size()) {
      inflateEnd(&zs);
      if (prefix) return out;
      fail(path, "truncated gzip data");
    }
    if (rc != Z_OK && rc != Z_BUF_ERROR) {
      const std::string msg = zs.msg ? zs.msg : "error " + std::to_string(rc);
      inflateEnd(&zs);
      fail(path, "corrupt gzip data (" + msg + ")");
    }
  }
  inflateEnd(&zs);
  return out;
}

std::vector<std::uint8_t> gzip(std::span<const std::uint8_t> data) {
  z_stream zs{};
  if (deflateInit2(&zs, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error("gzip: cannot initialize zlib");
  std::vector<std::uint8_t> out;
  std::size_t consumed = 0;
  std::uint8_t buffer[1 << 16];
  int rc = Z_OK;
  while (rc != Z_STREAM_END) {
    feed_input(zs, data, consumed);
    zs.next_out = buffer;
    zs.avail_out = sizeof(buffer);
    rc = deflate(&zs, consumed == data.size() ? Z_FINISH : Z_NO_FLUSH);
    out.insert(out.end(), buffer, buffer + (sizeof(buffer) - zs.avail_out));
  }
  deflateEnd(&zs);
  return out;
}

std::size_t checked_mul(const fs::path& path, std::size_t a, std::size_t b) {
  if (b != 0 && a > std::numeric_limits<std::size_t>::max() / b)
    fail(path, "size " + std::to_string(a) + " x " + std::to_string(b) + " overflows");
  return a * b;
}

void swap_bytes(std::span<std::uint8_t> bytes, std::size_t width) {
  if (width < 2) return;
  for (std::size_t i = 0; i + width <= bytes.size(); i += width) std::reverse(bytes.begin() + i, bytes.begin() + i + width);
}

bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  // Out-of-range values are reported as errors too, not silently clamped.
  return ec == std::errc() && end == token.data() + token.size();
}

bool parse_size(std::string_view token, std::size_t& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

std::vector<std::string_view> split_fields(std::string_view line, bool commas) {
  std::vector<std::string_view> fields;
  auto is_sep = [&](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || (commas && c == ','); };
  if (commas) {
    // CSV keeps empty fields so that "1,,2" is an error rather than "1,2".
    std::size_t start = 0;
    for (std::size_t i = 0; i <= line.size(); ++i) {
      if (i == line.size() || line[i] == ',') {
        fields.push_back(trim(line.substr(start, i - start)));
        start = i + 1;
      }
    }
    return fields;
  }
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_sep(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_sep(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

bool LineReader::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  std::size_t end = text_.find('\n', pos_);
  if (end == std::string_view::npos) end = text_.size();
  line = text_.substr(pos_, end - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = end + 1;
  ++line_;
  return true;
}

std::string_view trim(std::string_view s) {
  auto ws = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; };
  while (!s.empty() && ws(s.front())) s.remove_prefix(1);
  while (!s.empty() && ws(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<TextRow> text_rows(std::string_view text, bool commas) {
  std::vector<TextRow> rows;
  LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    const std::string_view t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    rows.push_back({lines.line_number(), split_fields(t, commas)});
  }
  return rows;
}

double number(const std::filesystem::path& path, const TextRow& row, std::size_t column) {
  double v = 0;
  if (column >= row.fields.size())
    fail(path, "line " + std::to_string(row.line) + ": expected at least " + std::to_string(column + 1) + " numbers");
  if (!parse_double(row.fields[column], v))
    fail(path, "line " + std::to_string(row.line) + ": '" + std::string(row.fields[column].substr(0, 40)) + "' is not a number");
  if (!std::isfinite(v)) fail(path, "line " + std::to_string(row.line) + ": non-finite value");
  return v;
}

}  // namespace geods::io::detail
