#include "geods/shape/collection.hpp"

#include <fmt/format.h>
#include <zip.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/io/mesh_io.hpp"

namespace geods::shape {

namespace fs = std::filesystem;

namespace {

// Largest member read from an archive: far above any furniture model, a bound against zip bombs.
constexpr std::uint64_t kMaxMember = std::uint64_t(1) << 31;

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return std::string(s);
}

void append_utf8(std::string& out, std::uint32_t c) {
  if (c < 0x80) {
    out += char(c);
  } else if (c < 0x800) {
    out += char(0xc0 | (c >> 6)), out += char(0x80 | (c & 0x3f));
  } else {
    out += char(0xe0 | (c >> 12)), out += char(0x80 | ((c >> 6) & 0x3f)), out += char(0x80 | (c & 0x3f));
  }
}

// Java .properties: key=value, key:value or key value; '#'/'!' comments;
// a trailing backslash continues the line; \uXXXX and \t \n \r \f escapes.
std::map<std::string, std::string> parse_properties(const std::string& text) {
  std::map<std::string, std::string> out;
  std::vector<std::string> logical;
  std::string current;
  bool continued = false;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::string_view v = line;
    if (!continued) {
      const std::string t = trim(v);
      if (t.empty() || t[0] == '#' || t[0] == '!') continue;
    } else {
      while (!v.empty() && std::isspace(static_cast<unsigned char>(v.front()))) v.remove_prefix(1);
    }
    std::size_t slashes = 0;
    for (auto it = v.rbegin(); it != v.rend() && *it == '\\'; ++it) ++slashes;
    continued = slashes % 2 == 1;
    current += continued ? v.substr(0, v.size() - 1) : v;
    if (!continued) logical.push_back(std::move(current)), current.clear();
  }
  if (!current.empty()) logical.push_back(current);
  for (const std::string& l : logical) {
    std::string key, value;
    std::string* target = &key;
    bool separated = false;
    std::size_t i = 0;
    while (i < l.size() && std::isspace(static_cast<unsigned char>(l[i]))) ++i;
    for (; i < l.size(); ++i) {
      char c = l[i];
      if (!separated && (c == '=' || c == ':' || std::isspace(static_cast<unsigned char>(c)))) {
        separated = true;
        target = &value;
        while (i + 1 < l.size() && std::isspace(static_cast<unsigned char>(l[i + 1]))) ++i;
        if (!(c == '=' || c == ':') && i + 1 < l.size() && (l[i + 1] == '=' || l[i + 1] == ':')) {
          ++i;
          while (i + 1 < l.size() && std::isspace(static_cast<unsigned char>(l[i + 1]))) ++i;
        }
        continue;
      }
      if (c == '\\' && i + 1 < l.size()) {
        c = l[++i];
        if (c == 'u' && i + 4 < l.size()) {
          std::uint32_t code = 0;
          const auto [p, ec] = std::from_chars(l.data() + i + 1, l.data() + i + 5, code, 16);
          if (ec == std::errc() && p == l.data() + i + 5) {
            append_utf8(*target, code);
            i += 4;
            continue;
          }
        }
        *target += c == 't' ? '\t' : c == 'n' ? '\n' : c == 'r' ? '\r' : c == 'f' ? '\f' : c;
        continue;
      }
      *target += c;
    }
    out[key] = value;
  }
  return out;
}

std::string percent_decode(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    unsigned value = 0;
    if (s[i] == '%' && i + 2 < s.size() &&
        std::from_chars(s.data() + i + 1, s.data() + i + 3, value, 16).ptr == s.data() + i + 3) {
      out += char(value);
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

}  // namespace

// ---------------------------------------------------------------- zip archives (libzip; one handle, one reader at a time)
struct ShapeCollection::Zip {
  fs::path path;
  zip_t* archive = nullptr;
  std::mutex mutex;
  std::map<std::string, zip_uint64_t> index;  // member name -> index

  explicit Zip(const fs::path& p) : path(p) {
    int code = 0;
    archive = zip_open(p.c_str(), ZIP_RDONLY, &code);
    if (!archive) {
      zip_error_t error;
      zip_error_init_with_code(&error, code);
      const std::string what = zip_error_strerror(&error);
      zip_error_fini(&error);
      throw Error(fmt::format("{}: not a readable zip archive ({})", p.string(), what));
    }
    const zip_int64_t n = zip_get_num_entries(archive, 0);
    for (zip_int64_t i = 0; i < n; ++i)
      if (const char* name = zip_get_name(archive, zip_uint64_t(i), 0)) index.emplace(name, zip_uint64_t(i));
  }
  ~Zip() {
    if (archive) zip_discard(archive);
  }
  Zip(const Zip&) = delete;
  Zip& operator=(const Zip&) = delete;

  std::vector<std::uint8_t> read(const std::string& name) {
    const auto it = index.find(name);
    if (it == index.end()) throw Error(fmt::format("{}: no member '{}'", path.string(), name));
    std::lock_guard lock(mutex);
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_stat_index(archive, it->second, 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE))
      throw Error(fmt::format("{}: member '{}': {}", path.string(), name, zip_strerror(archive)));
    if (st.size > kMaxMember)
      throw Error(fmt::format("{}: member '{}' inflates to {} bytes, more than 2 GiB", path.string(), name, st.size));
    zip_file_t* file = zip_fopen_index(archive, it->second, 0);
    if (!file) throw Error(fmt::format("{}: member '{}': {}", path.string(), name, zip_strerror(archive)));
    std::vector<std::uint8_t> bytes(st.size);
    const zip_int64_t got = st.size ? zip_fread(file, bytes.data(), st.size) : 0;
    const std::string error = got < 0 ? zip_file_strerror(file) : "";
    zip_fclose(file);
    if (got < 0 || zip_uint64_t(got) != st.size)
      throw Error(fmt::format("{}: member '{}' is corrupt ({})", path.string(), name,
                              got < 0 ? error : fmt::format("{} of {} bytes", got, st.size)));
    return bytes;
  }
};

// ---------------------------------------------------------------- labels
std::vector<std::pair<std::string, std::string>> read_labels_csv(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open the labels file");
  std::vector<std::pair<std::string, std::string>> rows;
  std::size_t number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const char c = t[i];
      if (c == '"') {
        if (quoted && i + 1 < t.size() && t[i + 1] == '"') fields.back() += '"', ++i;
        else quoted = !quoted;
      } else if (c == ',' && !quoted) {
        fields.emplace_back();
      } else {
        fields.back() += c;
      }
    }
    if (quoted || fields.size() != 2)
      throw Error(fmt::format("{}:{}: expected a row 'path,label', got '{}'", path.string(), number, t));
    for (auto& f : fields) f = trim(f);
    if (rows.empty() && number > 0 && lower(fields[0]) == "path" && lower(fields[1]) == "label") continue;
    if (fields[0].empty()) throw Error(fmt::format("{}:{}: empty path", path.string(), number));
    rows.emplace_back(fields[0], fields[1]);
  }
  return rows;
}

// ---------------------------------------------------------------- opening
ShapeCollection ShapeCollection::open(const fs::path& path, const fs::path& labels_csv) {
  ShapeCollection c;
  c.path_ = path;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    c.kind_ = CollectionKind::directory;
    for (auto it = fs::recursive_directory_iterator(path, fs::directory_options::skip_permission_denied, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
      if (it->is_regular_file(ec) && io::is_mesh_name(it->path()))
        c.entries_.push_back({fs::relative(it->path(), path).generic_string(), {}, {}});
    if (ec) throw Error(fmt::format("{}: cannot list the directory ({})", path.string(), ec.message()));
    std::sort(c.entries_.begin(), c.entries_.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  } else if (!fs::exists(path, ec)) {
    throw Error(path.string() + ": no such file or directory");
  } else {
    const std::string ext = lower(path.extension().string());
    if (ext != ".zip" && ext != ".sh3f")
      throw Error(path.string() + ": not a collection (expected a directory, a .zip or a .sh3f furniture library)");
    c.zip_ = std::make_shared<Zip>(path);
    if (ext == ".zip") {
      c.kind_ = CollectionKind::zip;
      for (const auto& [name, index] : c.zip_->index)
        if (name.back() != '/' && io::is_mesh_name(name)) c.entries_.push_back({name, {}, {}});
    } else {
      c.kind_ = CollectionKind::sh3f;
      const std::string catalog_name = "PluginFurnitureCatalog.properties";
      if (!c.zip_->index.count(catalog_name))
        throw Error(path.string() + ": a furniture library without " + catalog_name);
      const std::vector<std::uint8_t> bytes = c.zip_->read(catalog_name);
      const auto properties = parse_properties(std::string(bytes.begin(), bytes.end()));
      std::map<int, CollectionEntry> models;  // by N, in catalog order
      for (const auto& [key, value] : properties) {
        const std::size_t hash = key.find('#');
        if (hash == std::string::npos || key.substr(0, hash) != "model") continue;
        int n = 0;
        if (std::from_chars(key.data() + hash + 1, key.data() + key.size(), n).ptr != key.data() + key.size()) continue;
        std::string member = value;
        while (!member.empty() && member.front() == '/') member.erase(member.begin());
        if (!c.zip_->index.count(member) && c.zip_->index.count(percent_decode(member))) member = percent_decode(member);
        if (!c.zip_->index.count(member)) {
          c.warnings_.push_back(fmt::format("{}: model#{} '{}' is not in the archive", path.string(), n, value));
          continue;
        }
        auto field = [&](const char* what) {
          const auto it = properties.find(fmt::format("{}#{}", what, n));
          return it == properties.end() ? std::string() : it->second;
        };
        models[n] = CollectionEntry{member, field("category"), field("name")};
      }
      for (auto& [n, e] : models) c.entries_.push_back(std::move(e));
      if (c.entries_.empty()) throw Error(path.string() + ": the catalog lists no model of the archive");
    }
  }
  if (!labels_csv.empty()) {
    std::map<std::string, std::size_t> by_name;
    for (std::size_t i = 0; i < c.entries_.size(); ++i) by_name[c.entries_[i].name] = i;
    std::size_t matched = 0;
    for (auto [name, label] : read_labels_csv(labels_csv)) {
      if (name.rfind("./", 0) == 0) name.erase(0, 2);
      const auto it = by_name.find(name);
      if (it == by_name.end()) {
        c.warnings_.push_back(fmt::format("{}: '{}' is not in the collection", labels_csv.string(), name));
        continue;
      }
      c.entries_[it->second].label = label;
      ++matched;
    }
    if (matched == 0 && !c.entries_.empty())
      throw Error(fmt::format("{}: no row names a mesh of {}", labels_csv.string(), path.string()));
  }
  return c;
}

TriMesh ShapeCollection::read(std::size_t i) const {
  if (i >= entries_.size()) throw Error(fmt::format("{}: no entry {}", path_.string(), i));
  const std::string& name = entries_[i].name;
  if (!zip_) return io::read_mesh(path_ / fs::path(name));
  const std::vector<std::uint8_t> bytes = zip_->read(name);
  return io::read_mesh_from_memory(bytes, path_ / fs::path(name));
}

// ---------------------------------------------------------------- indexing
CollectionIndex index_collection(const ShapeCollection& collection, const DescriptorOptions& options,
                                 const ProgressCallback& progress) {
  CollectionIndex out{ShapeDatabase(options), {}};
  const std::size_t n = collection.size(), dim = out.database.dimension();
  std::vector<float> rows(n * dim);
  std::vector<std::string> errors(n);
  std::vector<char> ok(n, 0);
  Progress bar(progress, "describing shapes", double(n));
  std::atomic<std::size_t> done{0};
  std::mutex report;
  parallel_for(0, n, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      try {
        const std::vector<float> d = describe(collection.read(i), options);
        std::copy(d.begin(), d.end(), rows.begin() + std::ptrdiff_t(i * dim));
        ok[i] = 1;
      } catch (const Error& error) {
        errors[i] = error.what();
      }
      const std::size_t finished = ++done;
      std::lock_guard lock(report);
      bar.update(double(finished));
    }
  });
  bar.finish();
  std::vector<std::string> names, labels;
  std::vector<float> kept;
  for (std::size_t i = 0; i < n; ++i) {
    const CollectionEntry& entry = collection.entries()[i];
    if (!ok[i]) {
      out.skipped.push_back({entry.name, errors[i]});
      continue;
    }
    names.push_back(entry.name);
    labels.push_back(entry.label);
    kept.insert(kept.end(), rows.begin() + std::ptrdiff_t(i * dim), rows.begin() + std::ptrdiff_t((i + 1) * dim));
  }
  out.database.add_descriptors(names, kept, labels);
  return out;
}

}  // namespace geods::shape
