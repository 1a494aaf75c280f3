// Nearest-site queries: the slab structure of Theorem 8 and walking in the Delaunay graph.
#include "geods/voronoi/post_office.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "exact_compare.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
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

}  // namespace

std::uint32_t descend_to_nearest(const Voronoi2& diagram, const Vec2d& q, std::uint32_t start) {
  const std::span<const Vec2d> points = diagram.points();
  std::uint32_t current = diagram.representative(start);
  // Steepest descent on rounded distances first (strictly decreasing, so it ends),
  // then exact comparisons settle the last step.
  double current_d = (points[current] - q).squaredNorm();
  for (;;) {
    std::uint32_t best = current;
    for (std::uint32_t nb : diagram.neighbors(current)) {
      const double d = (points[nb] - q).squaredNorm();
      if (d < current_d) current_d = d, best = nb;
    }
    if (best == current) break;
    current = best;
  }
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

  // Each undirected edge that is not vertical, as its half-edge with the higher site
  // on its left (going up crosses a bisector towards the site with the larger y).
  struct Span {
    std::uint32_t edge;
    double x0, x1;
  };
  std::vector<Span> spans;
  lines_.resize(edges.size());
  xs_.reserve(vertices.size());
  for (const Vec2d& v : vertices) xs_.push_back(v[0]);
  for (std::uint32_t e = 0; e < edges.size(); ++e) {
    const std::uint32_t t = edges[e].twin;
    if (t < e) continue;
    const double ya = points[edges[e].site][1], yb = points[edges[t].site][1];
    if (ya == yb) {  // a vertical bisector: a slab boundary when it is a whole line
      if (edges[e].origin == Voronoi2::kInfinity && edges[e].target == Voronoi2::kInfinity)
        xs_.push_back(diagram.line_point(e)[0]);
      continue;
    }
    const std::uint32_t up = ya > yb ? e : t;
    const Vec2d d = diagram.direction(up);
    if (d[0] == 0) continue;  // rounding made a steep direction vertical: it spans no slab
    const Voronoi2::Edge& edge = edges[up];
    double x_from = edge.origin != Voronoi2::kInfinity ? vertices[edge.origin][0] : (d[0] > 0 ? -kInf : kInf);
    double x_to = edge.target != Voronoi2::kInfinity ? vertices[edge.target][0] : (d[0] > 0 ? kInf : -kInf);
    if (x_from > x_to) std::swap(x_from, x_to);
    if (x_from < x_to) spans.push_back({up, x_from, x_to});
    const Vec2d p = diagram.line_point(up);
    lines_[up] = {p[0], p[1], d[1] / d[0]};
  }
  std::sort(xs_.begin(), xs_.end());
  xs_.erase(std::unique(xs_.begin(), xs_.end()), xs_.end());
  const std::size_t slabs = xs_.size() + 1;

  // Count the crossings per slab (a difference array), then fill.
  const auto first_slab = [&](double x0) {
    return x0 == -kInf ? std::size_t(0) : std::size_t(std::lower_bound(xs_.begin(), xs_.end(), x0) - xs_.begin()) + 1;
  };
  const auto last_slab = [&](double x1) {
    return x1 == kInf ? xs_.size() : std::size_t(std::lower_bound(xs_.begin(), xs_.end(), x1) - xs_.begin());
  };
  // The spans in consecutive blocks, counted and filled block by block in parallel: each slab
  // gets its edges in the order of the spans whatever the number of blocks (the sort below
  // then sees the same input on any number of threads).
  std::vector<std::array<std::uint32_t, 2>> span_slabs(spans.size());  // first and last slab
  parallel_for(0, spans.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      span_slabs[i] = {std::uint32_t(first_slab(spans[i].x0)), std::uint32_t(last_slab(spans[i].x1))};
  });
  const std::size_t threads = std::size_t(num_threads());
  const std::size_t blocks =
      threads == 1 ? 1 : std::max<std::size_t>(1, std::min<std::size_t>(2 * threads, spans.size() / 4096));
  const auto block_begin = [&](std::size_t b) { return b * spans.size() / blocks; };
  // Per block and slab: how many of the block's spans cross the slab (from a difference
  // array; unsigned wrap-around is exact since every count fits), later where they go.
  std::vector<std::vector<std::uint32_t>> place(blocks);
  parallel_for_each_index(0, blocks, [&](std::size_t b) {
    std::vector<std::uint32_t>& c = place[b];
    c.assign(slabs + 1, 0);
    for (std::size_t i = block_begin(b); i < block_begin(b + 1); ++i) {
      ++c[span_slabs[i][0]];
      --c[span_slabs[i][1] + 1];
    }
    std::uint32_t running = 0;
    for (std::size_t s = 0; s < slabs; ++s) c[s] = running += c[s];
  }, 1);
  std::size_t total = 0;
  offsets_.assign(slabs + 1, 0);
  for (std::size_t s = 0; s < slabs; ++s) {
    for (std::size_t b = 0; b < blocks; ++b) total += place[b][s];
    if (total >= std::numeric_limits<std::uint32_t>::max())
      throw Error("SlabLocator: more than 2^32 edge-slab crossings (" + std::to_string(diagram.stats().distinct) +
                  " sites); use WalkLocator for this many sites");
    offsets_[s + 1] = std::uint32_t(total);
  }
  parallel_for(0, slabs, 1024, [&](std::size_t first, std::size_t last) {
    for (std::size_t s = first; s < last; ++s)
      for (std::uint32_t b = 0, at = offsets_[s]; b < blocks; ++b) at += std::exchange(place[b][s], at);
  });
  edge_.resize(total);
  below_.resize(total);
  parallel_for_each_index(0, blocks, [&](std::size_t b) {
    std::vector<std::uint32_t>& fill = place[b];
    for (std::size_t i = block_begin(b); i < block_begin(b + 1); ++i)
      for (std::size_t slab = span_slabs[i][0], last = span_slabs[i][1]; slab <= last; ++slab)
        edge_[fill[slab]++] = spans[i].edge;
  }, 1);

  // Sort each slab bottom to top at its middle; edges do not cross inside a slab.
  top_.assign(slabs, 0);
  const auto middle = [&](std::size_t s) { return slab_middle(s); };
  parallel_for(0, slabs, 64, [&](std::size_t b, std::size_t e) {
    for (std::size_t s = b; s < e; ++s) {
      const double x = middle(s);
      std::sort(edge_.begin() + offsets_[s], edge_.begin() + offsets_[s + 1],
                [&](std::uint32_t a, std::uint32_t c) { return edge_y(a, x) < edge_y(c, x); });
      for (std::uint32_t k = offsets_[s]; k < offsets_[s + 1]; ++k) below_[k] = diagram.opposite_site(edge_[k]);
      if (offsets_[s + 1] > offsets_[s]) top_[s] = edges[edge_[offsets_[s + 1] - 1]].site;
    }
  });
  // Slabs without edges lie inside one cell (several sites only when they are all on a horizontal line).
  std::uint32_t previous = diagram.representative(0);
  for (std::size_t s = 0; s < slabs; ++s)
    if (offsets_[s + 1] == offsets_[s]) previous = top_[s] = descend_to_nearest(diagram, Vec2d(middle(s), 0), previous);
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
  const auto& edges = diagram_->edges();
  for (std::size_t s = 0; s + 1 < offsets_.size(); ++s) {
    const double x = slab_middle(s);
    for (std::uint32_t k = offsets_[s]; k + 1 < offsets_[s + 1]; ++k) {
      if (edge_y(edge_[k], x) > edge_y(edge_[k + 1], x))
        throw Error("SlabLocator::validate: slab " + std::to_string(s) + " is not sorted");
      if (edges[edge_[k]].site != below_[k + 1])
        throw Error("SlabLocator::validate: slab " + std::to_string(s) + ": the cell between two edges differs");
    }
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
