#include "geods/io/polygon_io.hpp"

#include <gdal.h>
#include <ogr_api.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "geods/core/error.hpp"

namespace geods::io {
namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void check_finite(const Vec2d& p, const std::filesystem::path& path) {
  if (!p.allFinite()) throw Error(path.string() + ": a coordinate is not finite");
}

void add_ring(PolygonSet& out, std::vector<Vec2d> ring) {
  std::vector<Vec2d> r;
  for (const Vec2d& p : ring)
    if (r.empty() || r.back() != p) r.push_back(p);
  while (r.size() > 1 && r.front() == r.back()) r.pop_back();
  if (r.size() >= 3) out.rings.push_back(std::move(r));
}

void add_chain(PolygonSet& out, const std::vector<Vec2d>& chain) {
  for (std::size_t i = 0; i + 1 < chain.size(); ++i)
    out.segments.push_back({chain[i][0], chain[i][1], chain[i + 1][0], chain[i + 1][1]});
}

void add_geometry(PolygonSet& out, OGRGeometryH g, const std::filesystem::path& path) {
  if (g == nullptr) return;
  const OGRwkbGeometryType type = wkbFlatten(OGR_G_GetGeometryType(g));
  auto coords = [&](OGRGeometryH line) {
    std::vector<Vec2d> pts;
    const int n = OGR_G_GetPointCount(line);
    for (int i = 0; i < n; ++i) {
      const Vec2d p(OGR_G_GetX(line, i), OGR_G_GetY(line, i));
      check_finite(p, path);
      pts.push_back(p);
    }
    return pts;
  };
  switch (type) {
    case wkbPoint: {
      const Vec2d p(OGR_G_GetX(g, 0), OGR_G_GetY(g, 0));
      check_finite(p, path);
      out.points.push_back(p);
      break;
    }
    case wkbLineString: add_chain(out, coords(g)); break;
    case wkbLinearRing: add_ring(out, coords(g)); break;
    case wkbPolygon:
      for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i) add_ring(out, coords(OGR_G_GetGeometryRef(g, i)));
      break;
    case wkbMultiPoint:
    case wkbMultiLineString:
    case wkbMultiPolygon:
    case wkbGeometryCollection:
      for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i) add_geometry(out, OGR_G_GetGeometryRef(g, i), path);
      break;
    default: throw Error(path.string() + ": unsupported geometry type " + OGRGeometryTypeToName(type));
  }
}

void read_wkt(PolygonSet& out, const std::filesystem::path& path) {
  const std::string text = read_text(path);
  std::size_t pos = 0;
  while (true) {
    while (pos < text.size() && (std::isspace(static_cast<unsigned char>(text[pos])) || text[pos] == ';')) ++pos;
    if (pos >= text.size()) break;
    std::string rest = text.substr(pos);
    char* cursor = rest.data();
    OGRGeometryH g = nullptr;
    if (OGR_G_CreateFromWkt(&cursor, nullptr, &g) != OGRERR_NONE || g == nullptr)
      throw Error(path.string() + ": not valid WKT at byte " + std::to_string(pos));
    try {
      add_geometry(out, g, path);
    } catch (...) {
      OGR_G_DestroyGeometry(g);
      throw;
    }
    OGR_G_DestroyGeometry(g);
    pos += static_cast<std::size_t>(cursor - rest.data());
  }
}

void read_ogr(PolygonSet& out, const std::filesystem::path& path) {
  GDALAllRegister();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  GDALDatasetH ds = GDALOpenEx(path.string().c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr);
  CPLPopErrorHandler();
  if (ds == nullptr) throw Error(path.string() + ": cannot read as a vector map (GDAL/OGR)");
  try {
    for (int l = 0; l < GDALDatasetGetLayerCount(ds); ++l) {
      OGRLayerH layer = GDALDatasetGetLayer(ds, l);
      OGR_L_ResetReading(layer);
      while (OGRFeatureH f = OGR_L_GetNextFeature(layer)) {
        try {
          add_geometry(out, OGR_F_GetGeometryRef(f), path);
        } catch (...) {
          OGR_F_Destroy(f);
          throw;
        }
        OGR_F_Destroy(f);
      }
    }
  } catch (...) {
    GDALClose(ds);
    throw;
  }
  GDALClose(ds);
}

void read_cin(PolygonSet& out, const std::filesystem::path& path) {
  std::istringstream in(read_text(path));
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag) || tag[0] == '#') continue;
    if (tag == "s") {
      std::array<double, 4> s{};
      if (!(ls >> s[0] >> s[1] >> s[2] >> s[3])) throw Error(path.string() + ": line " + std::to_string(number) + ": expected s x0 y0 x1 y1");
      check_finite(Vec2d(s[0], s[1]), path);
      check_finite(Vec2d(s[2], s[3]), path);
      out.segments.push_back(s);
    } else if (tag == "p") {
      Vec2d p;
      if (!(ls >> p[0] >> p[1])) throw Error(path.string() + ": line " + std::to_string(number) + ": expected p x y");
      check_finite(p, path);
      out.points.push_back(p);
    } else {
      throw Error(path.string() + ": line " + std::to_string(number) + ": expected a line starting with s or p");
    }
  }
}

// SVG: <polygon points>, <polyline points>, <path d> with M L H V Z (either case).
void read_svg(PolygonSet& out, const std::filesystem::path& path) {
  const std::string text = read_text(path);
  const std::regex element(R"re(<(polygon|polyline|path)\b[^>]*?\b(points|d)\s*=\s*"([^"]*)")re");
  const std::regex number(R"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), element); it != std::sregex_iterator(); ++it) {
    const std::string kind = (*it)[1], data = (*it)[3];
    if (kind != "path") {
      std::vector<double> v;
      for (auto n = std::sregex_iterator(data.begin(), data.end(), number); n != std::sregex_iterator(); ++n) v.push_back(std::stod(n->str()));
      std::vector<Vec2d> pts;
      for (std::size_t i = 0; i + 1 < v.size(); i += 2) pts.emplace_back(v[i], -v[i + 1]);  // SVG's y points down
      for (const auto& p : pts) check_finite(p, path);
      if (kind == "polygon") add_ring(out, pts);
      else add_chain(out, pts);
      continue;
    }
    std::vector<Vec2d> chain;
    Vec2d cur(0, 0), start(0, 0);
    char cmd = 0;
    std::size_t i = 0;
    auto flush = [&](bool closed) {
      if (closed) add_ring(out, chain);
      else add_chain(out, chain);
      chain.clear();
    };
    auto read_number = [&](double& x) {
      std::smatch m;
      const std::string rest = data.substr(i);
      if (!std::regex_search(rest, m, number) || !std::all_of(rest.begin(), rest.begin() + m.position(0), [](char c) {
            return std::isspace(static_cast<unsigned char>(c)) || c == ',';
          }))
        return false;
      x = std::stod(m.str());
      i += static_cast<std::size_t>(m.position(0) + m.length(0));
      return true;
    };
    while (i < data.size()) {
      const char c = data[i];
      if (std::isalpha(static_cast<unsigned char>(c))) {
        cmd = c;
        ++i;
        if (cmd == 'Z' || cmd == 'z') {
          flush(true);
          cur = start;
        } else if (std::string("MLHVmlhv").find(cmd) == std::string::npos) {
          throw Error(path.string() + ": SVG path command '" + std::string(1, cmd) + "' is not supported (only M L H V Z)");
        }
        continue;
      }
      if (std::isspace(static_cast<unsigned char>(c)) || c == ',') {
        ++i;
        continue;
      }
      double a = 0, b = 0;
      const bool rel = std::islower(static_cast<unsigned char>(cmd));
      switch (std::toupper(static_cast<unsigned char>(cmd))) {
        case 'M':
        case 'L':
          if (!read_number(a) || !read_number(b)) throw Error(path.string() + ": bad SVG path data");
          cur = rel ? Vec2d(cur + Vec2d(a, b)) : Vec2d(a, b);
          if (std::toupper(static_cast<unsigned char>(cmd)) == 'M') {
            if (chain.size() > 1) flush(false);
            chain.clear();
            start = cur;
            cmd = rel ? 'l' : 'L';
          }
          break;
        case 'H':
          if (!read_number(a)) throw Error(path.string() + ": bad SVG path data");
          cur[0] = rel ? cur[0] + a : a;
          break;
        case 'V':
          if (!read_number(a)) throw Error(path.string() + ": bad SVG path data");
          cur[1] = rel ? cur[1] + a : a;
          break;
        default: throw Error(path.string() + ": bad SVG path data");
      }
      check_finite(cur, path);
      chain.emplace_back(cur[0], -cur[1]);  // SVG's y points down
    }
    if (chain.size() > 1) flush(false);
  }
}

}  // namespace

std::vector<double> PolygonSet::all_segments() const {
  std::vector<double> out;
  for (const auto& r : rings)
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Vec2d a = r[i], b = r[(i + 1) % r.size()];
      out.insert(out.end(), {a[0], a[1], b[0], b[1]});
    }
  for (const auto& s : segments) out.insert(out.end(), s.begin(), s.end());
  return out;
}

PolygonSet read_polygons(const std::filesystem::path& path) {
  PolygonSet out;
  if (!std::filesystem::exists(path)) throw Error(path.string() + ": no such file");
  const std::string ext = lower_extension(path);
  if (ext == ".wkt") read_wkt(out, path);
  else if (ext == ".cin") read_cin(out, path);
  else if (ext == ".svg") read_svg(out, path);
  else if (ext == ".geojson" || ext == ".json" || ext == ".shp" || ext == ".gpkg" || ext == ".kml") read_ogr(out, path);
  else throw Error(path.string() + ": unknown map format (accepted: .wkt .geojson .json .shp .gpkg .kml .cin .svg)");
  if (out.empty()) throw Error(path.string() + ": no polygons, lines or points");
  return out;
}

}  // namespace geods::io
