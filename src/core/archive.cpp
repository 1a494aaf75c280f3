#include "geods/core/archive.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>

namespace geods {

namespace {

static_assert(std::endian::native == std::endian::little,
              "geods archives are little-endian; this host is not (convert the files first)");

constexpr char kMagic[8] = {'G', 'E', 'O', 'D', 'S', 'A', 'R', 'C'};
constexpr std::uint32_t kContainerVersion = 1;
constexpr std::uint32_t kByteOrderMark = 0x01020304;
constexpr std::size_t kNameBytes = 32;
constexpr std::uint64_t kAlign = 64;

struct FileHeader {
  char magic[8];
  std::uint32_t container_version;
  std::uint32_t byte_order;
  char kind[kNameBytes];
  std::uint32_t kind_version;
  std::uint32_t sections;
  std::uint64_t table_checksum;
};
static_assert(sizeof(FileHeader) == 64);

struct SectionRecord {
  char name[kNameBytes];
  std::uint32_t type;
  std::uint32_t element_bytes;
  std::uint64_t offset;
  std::uint64_t count;
  std::uint64_t checksum;
};
static_assert(sizeof(SectionRecord) == 64);

// 64-bit multiply-xor hash, 8 bytes a step: fast enough to check files as they
// are mapped (memory bandwidth bound), strong enough to catch flipped bits.
std::uint64_t checksum(const void* data, std::uint64_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t h = 0x9e3779b97f4a7c15ull ^ bytes;
  std::uint64_t i = 0;
  for (; i + 8 <= bytes; i += 8) {
    std::uint64_t w;
    std::memcpy(&w, p + i, 8);
    h = (h ^ w) * 0xff51afd7ed558ccdull;
    h ^= h >> 32;
  }
  std::uint64_t tail = 0;
  if (bytes > i) std::memcpy(&tail, p + i, bytes - i);
  h = (h ^ tail) * 0xc4ceb9fe1a85ec53ull;
  return h ^ (h >> 29);
}

std::uint64_t round_up(std::uint64_t x) { return (x + kAlign - 1) / kAlign * kAlign; }

std::string fixed_string(const char* s, std::size_t n) { return std::string(s, std::find(s, s + n, '\0')); }

void check_name(std::string_view what, std::string_view name) {
  if (name.empty() || name.size() >= kNameBytes || name.find('\0') != std::string_view::npos)
    throw Error("archive " + std::string(what) + " '" + std::string(name) + "': 1 to " +
                std::to_string(kNameBytes - 1) + " bytes, no NUL");
}

const FileHeader& read_header(const MappedFile& file) {
  auto fail = [&](const std::string& what) { return Error(file.path().string() + ": " + what); };
  if (file.size() < sizeof(FileHeader)) throw fail("not a geods archive (too short for the header)");
  const auto& h = *reinterpret_cast<const FileHeader*>(file.data());
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) throw fail("not a geods archive (bad magic)");
  if (h.byte_order != kByteOrderMark) throw fail("geods archive of another byte order");
  if (h.container_version != kContainerVersion)
    throw fail("geods archive container version " + std::to_string(h.container_version) +
               ", this geods reads version " + std::to_string(kContainerVersion));
  return h;
}

}  // namespace

ArchiveWriter::ArchiveWriter(std::string kind, std::uint32_t kind_version)
    : kind_(std::move(kind)), kind_version_(kind_version) {
  check_name("kind", kind_);
}

void ArchiveWriter::add_bytes(std::string_view name, std::uint32_t type, std::uint32_t element_bytes,
                              const void* data, std::uint64_t count) {
  check_name("section", name);
  for (const Section& s : sections_)
    if (s.name == name) throw Error("archive section '" + std::string(name) + "' added twice");
  sections_.push_back({std::string(name), type, element_bytes, data, count});
}

void ArchiveWriter::write(const std::filesystem::path& path) const {
  FileHeader header{};
  std::memcpy(header.magic, kMagic, sizeof kMagic);
  header.container_version = kContainerVersion;
  header.byte_order = kByteOrderMark;
  std::memcpy(header.kind, kind_.data(), kind_.size());
  header.kind_version = kind_version_;
  header.sections = std::uint32_t(sections_.size());

  std::vector<SectionRecord> table(sections_.size());
  std::uint64_t offset = round_up(sizeof(FileHeader) + table.size() * sizeof(SectionRecord));
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    const Section& s = sections_[i];
    SectionRecord& r = table[i];
    std::memcpy(r.name, s.name.data(), s.name.size());
    r.type = s.type;
    r.element_bytes = s.element_bytes;
    r.offset = offset;
    r.count = s.count;
    r.checksum = checksum(s.data, s.count * s.element_bytes);
    offset = round_up(offset + s.count * s.element_bytes);
  }
  header.table_checksum = checksum(table.data(), table.size() * sizeof(SectionRecord));

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(path.string() + ": cannot open for writing");
  std::uint64_t written = 0;
  auto put = [&](const void* data, std::uint64_t bytes) {
    if (bytes == 0) return;
    out.write(static_cast<const char*>(data), std::streamsize(bytes));
    written += bytes;
  };
  auto pad = [&] {
    static constexpr char zeros[kAlign] = {};
    put(zeros, round_up(written) - written);
  };
  put(&header, sizeof header);
  put(table.data(), table.size() * sizeof(SectionRecord));
  for (const Section& s : sections_) {
    pad();
    put(s.data, s.count * s.element_bytes);
  }
  out.flush();
  if (!out) throw Error(path.string() + ": cannot write");
}

Archive::Kind Archive::peek(const std::filesystem::path& path) {
  const auto file = MappedFile::open(path);
  const FileHeader& h = read_header(*file);
  return {fixed_string(h.kind, kNameBytes), h.kind_version};
}

Archive Archive::open(const std::filesystem::path& path, std::string_view kind, std::uint32_t kind_version,
                      Verify verify) {
  auto file = MappedFile::open(path);
  auto fail = [&](const std::string& what) { return Error(path.string() + ": " + what); };
  const FileHeader& h = read_header(*file);
  const std::string file_kind = fixed_string(h.kind, kNameBytes);
  if (file_kind != kind)
    throw fail("holds a geods archive of kind " + file_kind + ", expected kind " + std::string(kind));
  if (h.kind_version != kind_version)
    throw fail(file_kind + " format version " + std::to_string(h.kind_version) + ", this geods reads version " +
               std::to_string(kind_version));
  const std::uint64_t size = file->size();
  if (h.sections > (size - sizeof(FileHeader)) / sizeof(SectionRecord)) throw fail("truncated archive (section table)");
  const auto* table = reinterpret_cast<const SectionRecord*>(file->data() + sizeof(FileHeader));
  if (checksum(table, std::uint64_t(h.sections) * sizeof(SectionRecord)) != h.table_checksum)
    throw fail("corrupt archive (section table checksum)");

  std::vector<Entry> entries;
  entries.reserve(h.sections);
  std::uint64_t end = sizeof(FileHeader) + std::uint64_t(h.sections) * sizeof(SectionRecord);
  for (std::uint32_t i = 0; i < h.sections; ++i) {
    const SectionRecord& r = table[i];
    Entry e{fixed_string(r.name, kNameBytes), r.type, r.element_bytes, r.offset, r.count};
    const std::string where = "section '" + e.name + "'";
    if (e.element_bytes == 0 || (e.type != kRecordType && (e.type > std::uint32_t(DType::f64) ||
                                                           dtype_size(DType(e.type)) != e.element_bytes)))
      throw fail("corrupt archive (" + where + " has a bad element type)");
    if (e.offset % kAlign != 0) throw fail("corrupt archive (" + where + " offset)");
    if (e.offset > size || e.count > (size - e.offset) / e.element_bytes)
      throw fail("truncated archive (" + where + ")");
    if (verify != Verify::structure_only && checksum(file->data() + e.offset, e.count * e.element_bytes) != r.checksum)
      throw fail("corrupt archive (" + where + " checksum)");
    for (const Entry& other : entries)
      if (other.name == e.name) throw fail("corrupt archive (" + where + " twice)");
    end = std::max(end, e.offset + e.count * e.element_bytes);
    entries.push_back(std::move(e));
  }
  if (size > end) throw fail("trailing bytes after the archive");
  return Archive(std::move(file), std::move(entries));
}

bool Archive::has(std::string_view name) const {
  return std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == name; });
}

const Archive::Entry& Archive::entry(std::string_view name, std::uint32_t type, std::uint32_t element_bytes) const {
  for (const Entry& e : entries_) {
    if (e.name != name) continue;
    if (e.type != type || e.element_bytes != element_bytes)
      throw error("section '" + e.name + "' holds " + std::to_string(e.element_bytes) + "-byte elements of type " +
                  std::to_string(e.type) + ", expected " + std::to_string(element_bytes) + "-byte elements of type " +
                  std::to_string(type));
    return e;
  }
  throw error("missing section '" + std::string(name) + "'");
}

void Archive::fail_count(std::string_view name, std::uint64_t count, std::uint64_t expected) const {
  throw error("section '" + std::string(name) + "' holds " + std::to_string(count) + " elements, expected " +
              std::to_string(expected));
}

DType Archive::dtype(std::string_view name) const {
  const std::uint32_t code = value<std::uint32_t>(name);
  if (code > std::uint32_t(DType::f64)) throw error("section '" + std::string(name) + "' holds no element type");
  return DType(code);
}

Error Archive::error(const std::string& what) const { return Error(path().string() + ": " + what); }

}  // namespace geods
