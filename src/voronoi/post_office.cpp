// Nearest-site queries: the slab structure of Theorem 8 and walking in the Delaunay graph.
#include "geods/voronoi/post_office.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "exact_compare.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/huge_page_allocator.hpp"
#include "geods/core/morton.hpp"
#include "geods/core/parallel.hpp"

namespace geods::voronoi {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void check_query(const Vec2d& q) {
  if (!std::isfinite(q[0]) || !std::isfinite(q[1]))
    throw Error("nearest site: non-finite query point (" + format_number(q[0]) + ", " + format_number(q[1]) + ")");
  check_query_range<2>(std::span<const double>(q.data(), 2), "nearest site");
}

// An edge the slabs store, as its half-edge with the higher site on its left (going up
// crosses the bisector towards the site with the larger y), its direction's slope and
// its x range (an infinite end at -inf or +inf).
struct SlabEdge {
  std::uint32_t half_edge;
  double slope, from, to;
};

// The undirected edge {e, twin} as the slabs store it; nothing for a vertical bisector
// (sites at equal y) or a direction that rounding made vertical, or an edge of no width.
std::optional<SlabEdge> slab_edge(const Voronoi2& diagram, std::uint32_t e) {
  const auto& edges = diagram.edges();
  const std::uint32_t t = edges[e].twin;
  const double ya = diagram.points()[edges[e].site][1], yb = diagram.points()[edges[t].site][1];
  if (ya == yb) return std::nullopt;
  const std::uint32_t up = ya > yb ? e : t;
  const Vec2d d = diagram.direction(up);
  if (d[0] == 0) return std::nullopt;
  const auto& vertices = diagram.vertices();
  const Voronoi2::Edge& edge = edges[up];
  const double from = edge.origin != Voronoi2::kInfinity ? vertices[edge.origin][0] : (d[0] > 0 ? -kInf : kInf);
  const double to = edge.target != Voronoi2::kInfinity ? vertices[edge.target][0] : (d[0] > 0 ? kInf : -kInf);
  if (from == to) return std::nullopt;
  return SlabEdge{up, d[1] / d[0], std::min(from, to), std::max(from, to)};
}

// The first and last slab between the slab boundaries xs (sorted, distinct) that an edge
// spanning x in [from, to] crosses: from the one right of `from` to the one left of `to`.
std::array<std::uint32_t, 2> crossed_slabs(const std::vector<double>& xs, double from, double to) {
  const auto at = [&](double x) { return std::uint32_t(std::lower_bound(xs.begin(), xs.end(), x) - xs.begin()); };
  return {from == -kInf ? 0 : at(from) + 1, to == kInf ? std::uint32_t(xs.size()) : at(to)};
}

}  // namespace

std::uint32_t descend_to_nearest(const Voronoi2& diagram, const Vec2d& q, std::uint32_t start) {
  const std::span<const Vec2d> points = diagram.points();
  std::uint32_t current = diagram.representative(start);
  // Steepest descent on rounded distances first (strictly decreasing, so it ends),
  // then exact comparisons settle the last step.
  double current_d = (points[current] - q).squaredNorm();
  double neighbour_d;  // after the loop: the least rounded distance of a neighbour of current
  for (;;) {
    std::uint32_t best = current;
    neighbour_d = kInf;
    for (std::uint32_t nb : diagram.neighbors(current)) {
      const double d = (points[nb] - q).squaredNorm();
      neighbour_d = std::min(neighbour_d, d);
      if (d < current_d) current_d = d, best = nb;
    }
    if (best == current) break;
    current = best;
  }
  // A rounded squared distance is within 4u (relative) of the exact one, or a few subnormal
  // units where it underflows: neighbours farther than that are farther exactly, and the
  // exact comparisons below could not move. (Overflow or NaN fails the test.)
  constexpr double kRounding = 1 + 10 * std::numeric_limits<double>::epsilon();
  if (neighbour_d > current_d * kRounding + 8 * std::numeric_limits<double>::denorm_min()) return current;
  for (bool moved = true; moved;) {
    moved = false;
    for (std::uint32_t nb : diagram.neighbors(current))
      if (detail::compare_distance(q, points[nb], points[current]) < 0) {
        current = nb;
        moved = true;
        break;
      }
  }
  return current;
}

// ---------------------------------------------------------------- SlabLocator

SlabLocator::SlabLocator(const Voronoi2& diagram) : diagram_(&diagram) {
  const auto& edges = diagram.edges();
  const auto& vertices = diagram.vertices();
  const std::span<const Vec2d> points = diagram.points();

  std::vector<SlabEdge> spans;
  lines_.resize(edges.size());
  xs_.reserve(vertices.size());
  for (const Vec2d& v : vertices) xs_.push_back(v[0]);
  for (std::uint32_t e = 0; e < edges.size(); ++e) {
    if (edges[e].twin < e) continue;
    // A vertical bisector that is a whole line is a slab boundary.
    if (points[edges[e].site][1] == points[edges[edges[e].twin].site][1] && edges[e].origin == Voronoi2::kInfinity &&
        edges[e].target == Voronoi2::kInfinity)
      xs_.push_back(diagram.line_point(e)[0]);
    const std::optional<SlabEdge> span = slab_edge(diagram, e);
    if (!span) continue;
    spans.push_back(*span);
    const Vec2d p = diagram.line_point(span->half_edge);
    lines_[span->half_edge] = {p[0], p[1], span->slope};
  }
  std::sort(xs_.begin(), xs_.end());
  xs_.erase(std::unique(xs_.begin(), xs_.end()), xs_.end());
  const std::size_t slabs = xs_.size() + 1;

  std::vector<std::array<std::uint32_t, 2>> span_slabs(spans.size());  // first and last slab
  parallel_for(0, spans.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) span_slabs[i] = crossed_slabs(xs_, spans[i].from, spans[i].to);
  });
  // Crossings per slab from a difference array (unsigned wrap-around is exact: every count fits).
  offsets_.assign(slabs + 1, 0);
  for (const auto& [first, last] : span_slabs) {
    ++offsets_[first];
    --offsets_[last + 1];
  }
  std::size_t total = 0;
  for (std::uint32_t s = 0, crossing = 0; s < slabs; ++s) {
    crossing += offsets_[s];
    offsets_[s] = std::uint32_t(total);
    total += crossing;
    if (total >= std::numeric_limits<std::uint32_t>::max())
      throw Error("SlabLocator: more than 2^32 edge-slab crossings (" + std::to_string(diagram.stats().distinct) +
                  " sites); use WalkLocator for this many sites");
  }
  offsets_[slabs] = std::uint32_t(total);
  edge_.resize(total);
  below_.resize(total);
  // In huge pages: faulted in 4 KiB at a time, the ~n^1.5 entries took half the time of
  // the derivation below (20k sites: 80 -> 38 ms on one thread).
  advise_huge_pages(edge_);
  advise_huge_pages(below_);
  top_.assign(slabs, 0);

  // Each slab's edges sorted bottom to top at its middle; edges do not cross inside a slab.
  // Slab s differs from slab s - 1 only by the edges that end or start at the line between
  // them, so it is derived from it: the edges that go on, in their order, merged with the
  // few that start (O(size) instead of a sort's O(size log size) comparisons, each reading
  // two lines). Runs of kRun slabs are derived in parallel, each from a sort of its first
  // slab: the runs do not depend on the number of threads, so neither do the slabs.
  constexpr std::size_t kRun = 1024;
  const std::size_t runs = (slabs + kRun - 1) / kRun;
  std::vector<std::vector<std::uint32_t>> run_first(runs);  // the edges of each run's first slab
  struct Stored {
    std::uint32_t last_slab, below;  // the edge's last slab and the site below it
  };
  std::vector<Stored> stored(edges.size());  // by half-edge, for those the slabs hold
  std::vector<std::uint32_t> start_at(slabs + 1, 0);  // slab s's starting edges: starting[start_at[s], start_at[s + 1])
  for (std::size_t i = 0; i < spans.size(); ++i) {
    const auto [first, last] = span_slabs[i];
    stored[spans[i].half_edge] = {last, diagram.opposite_site(spans[i].half_edge)};
    ++start_at[first + 1];
    for (std::size_t r = (first + kRun - 1) / kRun; r * kRun <= last; ++r) run_first[r].push_back(spans[i].half_edge);
  }
  for (std::size_t s = 0; s < slabs; ++s) start_at[s + 1] += start_at[s];
  std::vector<std::uint32_t> starting(spans.size());
  {
    std::vector<std::uint32_t> next(start_at.begin(), start_at.end() - 1);
    for (std::size_t i = 0; i < spans.size(); ++i) starting[next[span_slabs[i][0]]++] = spans[i].half_edge;
  }
  parallel_for_each_index(0, runs, [&](std::size_t r) {
    std::vector<std::pair<double, std::uint32_t>> fresh;  // the starting edges of a slab, by height
    for (std::size_t s = r * kRun; s < std::min(slabs, (r + 1) * kRun); ++s) {
      const double x = slab_middle(s);
      const auto by_height = [&](std::uint32_t a, std::uint32_t c) { return edge_y(a, x) < edge_y(c, x); };
      std::uint32_t* const out = edge_.data() + offsets_[s];
      if (s == r * kRun) {
        std::copy(run_first[r].begin(), run_first[r].end(), out);
        std::sort(out, out + run_first[r].size(), by_height);
      } else {
        fresh.clear();
        for (std::uint32_t k = start_at[s]; k < start_at[s + 1]; ++k)
          fresh.push_back({edge_y(starting[k], x), starting[k]});
        std::sort(fresh.begin(), fresh.end());
        std::uint32_t* w = out;
        auto next_fresh = fresh.begin();
        double last_y = -kInf;
        bool sorted = true;  // false where rounding at this x reorders edges that go on
        for (std::uint32_t k = offsets_[s - 1]; k < offsets_[s]; ++k) {
          const std::uint32_t e = edge_[k];
          if (stored[e].last_slab < s) continue;  // ends at the line before this slab
          const double y = edge_y(e, x);
          for (; next_fresh != fresh.end() && next_fresh->first < y; ++next_fresh) *w++ = next_fresh->second;
          sorted = sorted && last_y <= y;
          last_y = y;
          *w++ = e;
        }
        for (; next_fresh != fresh.end(); ++next_fresh) *w++ = next_fresh->second;
        if (!sorted) std::sort(out, w, by_height);
      }
      for (std::uint32_t k = offsets_[s]; k < offsets_[s + 1]; ++k) below_[k] = stored[edge_[k]].below;
      if (offsets_[s + 1] > offsets_[s]) top_[s] = edges[edge_[offsets_[s + 1] - 1]].site;
    }
  }, 1);
  // Slabs without edges lie inside one cell (several sites only when they are all on a horizontal line).
  std::uint32_t previous = diagram.representative(0);
  for (std::size_t s = 0; s < slabs; ++s)
    if (offsets_[s + 1] == offsets_[s])
      previous = top_[s] = descend_to_nearest(diagram, Vec2d(slab_middle(s), 0), previous);
}

double SlabLocator::slab_middle(std::size_t s) const {
  if (xs_.empty()) return 0.0;
  if (s == 0) return xs_.front() - (1 + std::abs(xs_.front()));
  if (s == xs_.size()) return xs_.back() + (1 + std::abs(xs_.back()));
  return (xs_[s - 1] + xs_[s]) / 2;
}

std::uint32_t SlabLocator::locate(const Vec2d& q) const {
  check_query(q);
  const std::size_t s = std::size_t(std::upper_bound(xs_.begin(), xs_.end(), q[0]) - xs_.begin());
  const auto first = edge_.begin() + offsets_[s], last = edge_.begin() + offsets_[s + 1];
  const auto above = std::partition_point(first, last, [&](std::uint32_t e) { return edge_y(e, q[0]) <= q[1]; });
  return above == last ? top_[s] : below_[std::size_t(above - edge_.begin())];
}

std::uint32_t SlabLocator::nearest(const Vec2d& q) const { return descend_to_nearest(*diagram_, q, locate(q)); }

std::vector<std::uint32_t> SlabLocator::nearest_batch(std::span<const Vec2d> queries) const {
  std::vector<std::uint32_t> out(queries.size());
  parallel_for_each_index(0, queries.size(), [&](std::size_t i) { out[i] = nearest(queries[i]); }, 256);
  return out;
}

SlabLocatorStats SlabLocator::stats() const {
  SlabLocatorStats s;
  s.slabs = top_.size();
  s.crossings = edge_.size();
  for (std::size_t k = 0; k < s.slabs; ++k) s.max_crossings = std::max<std::size_t>(s.max_crossings, offsets_[k + 1] - offsets_[k]);
  s.bytes = xs_.size() * sizeof(double) + lines_.size() * sizeof(Line) + (offsets_.size() + edge_.size() + below_.size() + top_.size()) * sizeof(std::uint32_t);
  return s;
}

void SlabLocator::validate() const {
  // Each slab holds the edges that cross it (counted as the constructor counts them) sorted
  // bottom to top at its middle, each with the sites on either side. (That the site above one
  // edge is the site below the next holds only up to the rounding of the Voronoi vertices:
  // slabs narrower than that hold edges of both sides of a vertex computed twice.)
  const auto& edges = diagram_->edges();
  std::vector<std::uint32_t> crossing(offsets_.size(), 0);  // a difference array, as in the constructor
  for (std::uint32_t e = 0; e < edges.size(); ++e) {
    if (edges[e].twin < e) continue;
    if (const std::optional<SlabEdge> span = slab_edge(*diagram_, e)) {
      const auto [first, last] = crossed_slabs(xs_, span->from, span->to);
      ++crossing[first];
      --crossing[last + 1];
    }
  }
  std::uint32_t count = 0;
  for (std::size_t s = 0; s + 1 < offsets_.size(); ++s) {
    const auto fail = [&](const std::string& what) {
      throw Error("SlabLocator::validate: slab " + std::to_string(s) + " " + what);
    };
    count += crossing[s];
    if (offsets_[s + 1] - offsets_[s] != count)
      fail("holds " + std::to_string(offsets_[s + 1] - offsets_[s]) + " edges, " + std::to_string(count) + " cross it");
    const double x = slab_middle(s);
    for (std::uint32_t k = offsets_[s]; k < offsets_[s + 1]; ++k) {
      const std::optional<SlabEdge> span = slab_edge(*diagram_, edge_[k]);
      if (!span || span->half_edge != edge_[k] || !(span->from <= x && x <= span->to))
        fail("holds an edge that does not cross it");
      if (k + 1 < offsets_[s + 1] && edge_y(edge_[k], x) > edge_y(edge_[k + 1], x)) fail("is not sorted");
      if (below_[k] != diagram_->opposite_site(edge_[k])) fail("has a wrong site below an edge");
    }
    if (offsets_[s + 1] > offsets_[s] && top_[s] != edges[edge_[offsets_[s + 1] - 1]].site)
      fail("has a wrong site above its top edge");
  }
}

// ---------------------------------------------------------------- WalkLocator

WalkLocator::WalkLocator(const Voronoi2& diagram) : diagram_(&diagram) {
  std::vector<std::uint32_t> sites;
  for (std::uint32_t i = 0; i < diagram.size(); ++i)
    if (diagram.representative(i) == i) sites.push_back(i);
  const std::size_t count = std::max<std::size_t>(1, std::size_t(2 * std::cbrt(double(sites.size()))));
  for (std::size_t k = 0; k < count; ++k) samples_.push_back(sites[k * sites.size() / count]);
}

std::uint32_t WalkLocator::nearest(const Vec2d& q) const {
  check_query(q);
  const std::span<const Vec2d> points = diagram_->points();
  std::uint32_t start = samples_.front();
  double best = kInf;
  for (std::uint32_t s : samples_)
    if (const double d = (points[s] - q).squaredNorm(); d < best) best = d, start = s;
  return descend_to_nearest(*diagram_, q, start);
}

std::uint32_t WalkLocator::nearest(const Vec2d& q, std::uint32_t hint) const {
  check_query(q);
  if (hint >= diagram_->size()) throw Error("WalkLocator::nearest: hint " + std::to_string(hint) + " out of range");
  return descend_to_nearest(*diagram_, q, hint);
}

std::vector<std::uint32_t> WalkLocator::nearest_batch(std::span<const Vec2d> queries) const {
  for (const Vec2d& q : queries) check_query(q);
  const std::vector<std::uint32_t> order = morton_order(std::vector<Vec2d>(queries.begin(), queries.end()));
  std::vector<std::uint32_t> out(queries.size());
  constexpr std::size_t kChunk = 256;
  const std::size_t chunks = (queries.size() + kChunk - 1) / kChunk;
  parallel_for_each_index(0, chunks, [&](std::size_t c) {
    const std::size_t begin = c * kChunk, end = std::min(queries.size(), begin + kChunk);
    std::uint32_t previous = nearest(queries[order[begin]]);
    out[order[begin]] = previous;
    for (std::size_t k = begin + 1; k < end; ++k)
      out[order[k]] = previous = descend_to_nearest(*diagram_, queries[order[k]], previous);
  }, 1);
  return out;
}

}  // namespace geods::voronoi
