// The derived case table, checked exhaustively: every case and every
// resolution of its ambiguous faces. A cell's contour on a face must depend
// only on that face's four corners and decision, and the two cells sharing a
// face must trace it in opposite directions; inside the cell every edge is
// used once by each side. Together: closed, oriented surfaces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <bit>
#include <tuple>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "geods/iso/case_table.hpp"

namespace geods::iso {
namespace {

using Segment = std::pair<int, int>;  // directed, cube edges

// The face shared by two cube edges, or -1 (also for a centre vertex, >= 12).
int common_face(int e1, int e2) {
  if (e1 >= 12 || e2 >= 12) return -1;
  for (int f = 0; f < 6; ++f) {
    const auto c = face_corners(f);
    int found = 0;
    for (int q = 0; q < 4; ++q) {
      const auto ec = edge_corners(e1), ed = edge_corners(e2);
      const int a = c[q], b = c[(q + 1) % 4];
      found += (std::min(a, b) == ec[0] && std::max(a, b) == ec[1]);
      found += (std::min(a, b) == ed[0] && std::max(a, b) == ed[1]);
    }
    if (found == 2) return f;
  }
  return -1;
}

// Corner c of a cell seen from the neighbour across face f: its coordinate on
// the face's axis flips.
int across(int corner, int f) { return corner ^ (1 << (f / 2)); }
int edge_across(int e, int f) {
  const auto c = edge_corners(e);
  const int a = across(c[0], f), b = across(c[1], f);
  for (int x = 0; x < 12; ++x) {
    const auto d = edge_corners(x);
    if (d[0] == std::min(a, b) && d[1] == std::max(a, b)) return x;
  }
  return -1;
}

TEST(IsoCaseTable, ConventionsAreConsistent) {
  for (int e = 0; e < 12; ++e) {
    const auto c = edge_corners(e);
    EXPECT_EQ(c[0] ^ c[1], 1 << (e / 4)) << e;
    EXPECT_LT(c[0], c[1]);
  }
  for (int f = 0; f < 6; ++f) {
    const auto c = face_corners(f);
    for (int q = 0; q < 4; ++q) {
      EXPECT_EQ((c[q] >> (f / 2)) & 1, f & 1);
      EXPECT_EQ(std::popcount(unsigned(c[q] ^ c[(q + 1) % 4])), 1);  // cyclic order
    }
    // The neighbour lists the shared samples in the same order.
    const auto n = face_corners(f ^ 1);
    for (int q = 0; q < 4; ++q) EXPECT_EQ(across(c[q], f), n[q]);
  }
}

TEST(IsoCaseTable, AmbiguousFacesAreTheDiagonalOnes) {
  for (int c = 0; c < 256; ++c)
    for (int f = 0; f < 6; ++f) {
      const auto fc = face_corners(f);
      const bool in[4] = {bool((c >> fc[0]) & 1), bool((c >> fc[1]) & 1), bool((c >> fc[2]) & 1),
                          bool((c >> fc[3]) & 1)};
      const bool diagonal = in[0] == in[2] && in[1] == in[3] && in[0] != in[1];
      EXPECT_EQ(bool((ambiguous_faces(c) >> f) & 1), diagonal) << c << " " << f;
    }
}

TEST(IsoCaseTable, EveryEntryIsClosedAndFacesAgreeWithNeighbours) {
  // Face state (face, its four inside bits, decision) -> directed segments.
  std::map<std::tuple<int, int, int>, std::set<Segment>> face_segments;
  int max_triangles = 0, with_centres = 0;
  for (int c = 0; c < 256; ++c) {
    for (int joined = 0; joined < 64; ++joined) {
      const auto tri = case_triangles(c, std::uint8_t(joined));
      ASSERT_EQ(tri.size() % 3, 0u);
      max_triangles = std::max(max_triangles, int(tri.size() / 3));
      std::map<Segment, int> directed;
      std::set<int> used;
      for (std::size_t t = 0; t < tri.size(); t += 3) {
        ASSERT_TRUE(tri[t] != tri[t + 1] && tri[t + 1] != tri[t + 2] && tri[t] != tri[t + 2]) << c;
        for (int k = 0; k < 3; ++k) {
          ++directed[{tri[t + k], tri[t + (k + 1) % 3]}];
          used.insert(tri[t + k]);
        }
      }
      // Centre vertices: each fans one loop of crossed edges.
      const auto centres = case_centres(c, std::uint8_t(joined));
      EXPECT_LE(centres.size(), kMaxCentres);
      for (std::size_t i = 0; i < kMaxCentres; ++i) {
        EXPECT_EQ(used.count(int(12 + i)) == 1, i < centres.size()) << c << " centre " << i;
      }
      for (const std::uint16_t mask : centres) {
        for (int e = 0; e < 12; ++e) {
          if ((mask >> e) & 1) {
            EXPECT_TRUE(used.count(e)) << c;
          }
        }
      }
      // Exactly the crossed edges carry vertices.
      for (int e = 0; e < 12; ++e) {
        const auto ec = edge_corners(e);
        EXPECT_EQ(used.count(e) == 1, ((c >> ec[0]) & 1) != ((c >> ec[1]) & 1)) << c << " edge " << e;
      }
      with_centres += !centres.empty();
      std::map<int, std::set<Segment>> on_face;
      for (const auto& [s, n] : directed) {
        ASSERT_EQ(n, 1) << "case " << c << ": edge " << s.first << "-" << s.second << " used twice one way";
        const int f = common_face(s.first, s.second);
        const bool has_twin = directed.count({s.second, s.first}) == 1;
        // Inside the cell an edge has both sides; on a face only this cell's side.
        if (f < 0) {
          EXPECT_TRUE(has_twin) << "case " << c << ": open interior edge";
        } else {
          EXPECT_FALSE(has_twin) << "case " << c << ": a triangle lies in face " << f;
          on_face[f].insert(s);
        }
      }
      for (int f = 0; f < 6; ++f) {
        const auto fc = face_corners(f);
        int bits = 0;
        for (int q = 0; q < 4; ++q) bits |= ((c >> fc[q]) & 1) << q;
        const int decision = ((ambiguous_faces(c) >> f) & 1) ? (joined >> f) & 1 : 0;
        const auto key = std::make_tuple(f, bits, decision);
        const auto [it, fresh] = face_segments.emplace(key, on_face[f]);
        if (!fresh) {
          EXPECT_EQ(it->second, on_face[f]) << "case " << c << " face " << f << ": depends on other faces";
        }
      }
    }
  }
  EXPECT_EQ(max_triangles, max_case_triangles());
  // Centres are the exception (some ambiguous configurations only).
  EXPECT_GT(with_centres, 0);
  EXPECT_LT(with_centres, 64 * 256 / 10);
  std::printf("table entries with a centre vertex: %d of %d\n", with_centres, 64 * 256);
  // The neighbour across face f (its face f^1, same corner bits) runs each segment the other way.
  for (const auto& [key, segs] : face_segments) {
    const auto [f, bits, decision] = key;
    const auto other = face_segments.find({f ^ 1, bits, decision});
    ASSERT_NE(other, face_segments.end());
    std::set<Segment> mirrored;
    for (const auto& [a, b] : segs) mirrored.insert({edge_across(b, f), edge_across(a, f)});
    EXPECT_EQ(mirrored, other->second) << "face " << f << " bits " << bits << " decision " << decision;
  }
}

TEST(IsoCaseTable, AsymptoticDeciderFollowsTheSaddle) {
  // Inside corners 00 and 11; the saddle (v00 v11 - v10 v01) / (v00 + v11 - v10 - v01).
  EXPECT_TRUE(face_joins_inside(1, -0.5, 1, -0.5));    // saddle 0.25 > 0
  EXPECT_FALSE(face_joins_inside(0.2, -1, 0.2, -1));   // saddle < 0
  EXPECT_TRUE(face_joins_inside(1, -1, 1, -1));        // saddle exactly 0 counts as inside
  // Inside corners 10 and 01.
  EXPECT_TRUE(face_joins_inside(-0.5, 1, -0.5, 1));
  EXPECT_FALSE(face_joins_inside(-1, 0.2, -1, 0.2));
  EXPECT_TRUE(face_joins_inside(-1, 1, -1, 1));
}

}  // namespace
}  // namespace geods::iso
