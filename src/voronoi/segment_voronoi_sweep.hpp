#pragma once
// Fortune's sweep for points and segments (internal to segment_voronoi.cpp).
// Input: snapped integer coordinates (|x| <= 2^25, held in doubles, so that
// differences and cross products of differences are exact in double).
#include <array>
#include <cstdint>
#include <vector>

#include "geods/core/vec.hpp"

namespace geods::voronoi::detail {

struct SweepInput {
  std::vector<Vec2d> points;                          // integer coordinates
  std::vector<std::array<std::uint32_t, 2>> segments;  // point ids
};

struct SweepVertex {
  long double x = 0, y = 0, r = 0;
};

struct SweepEdge {
  std::array<std::uint32_t, 2> site{};      // elementary site ids (points, then segments)
  std::array<std::uint32_t, 2> vertex{};    // kInfinity when unbounded
  std::array<std::int8_t, 2> side{0, 0};    // segment sites: +1 when the edge is right of first->second endpoint
};

struct SweepOutput {
  std::vector<SweepVertex> vertices;
  std::vector<SweepEdge> edges;
};

SweepOutput sweep_segment_voronoi(const SweepInput& input);

}  // namespace geods::voronoi::detail
