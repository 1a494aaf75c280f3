// Delaunay3's second insertion technique (seed §5.3.1, Figure 48): flips, after
// Joe ("Construction of three-dimensional Delaunay triangulations using local
// transformations", 1991) and Edelsbrunner-Shah ("Incremental topological
// flipping works for regular triangulations", 1996).
//
// A point inside the hull splits the tetrahedron holding it 1-4 (on a face or
// an edge: every tetrahedron whose closed volume holds it, 2-6 or n-2n); a point
// outside is joined to every hull triangle it sees (the ghost tetrahedra
// beyond them become real ones, and the horizon edges new ghosts), so the
// tetrahedralization covers the convex hull again. Then the faces of the new
// point's link go on a stack; a popped face is Delaunay unless the point lies in
// the (perturbed) circumsphere of the tetrahedron behind it, the same test
// as the cavity's; a non-Delaunay face is flipped:
//  - 2-3 if the segment from the point to the opposite vertex crosses the face,
//  - 3-2 if it passes beyond one edge and that edge has three tetrahedra,
//  - 4-4 if it passes through an edge that has four (the five points of two of
//    them coplanar; on the hull, two coplanar hull triangles change their
//    diagonal: the ghost takes part as the fourth vertex),
//  - else it stays on the stack's past: another flip removes it later (the
//    stack order of Edelsbrunner-Shah). Every new tetrahedron holds the point
//    and its link face goes on the stack.
// With the exact predicates and the symbolic perturbation the flips end at the
// unique perturbed Delaunay tetrahedralization, the cavity's. Should a link
// face still be non-Delaunay when the stack is empty (a degenerate
// configuration the flips cannot untangle: none is known, nor a proof that
// none exists, as the perturbation does not remove coplanarities), the
// insertion is finished by the cavity step from the point's star (counted in
// stats().flip_repairs). That step is right from any state of the flips (the
// star and its conflicting neighbours are the old cavity); the tests reach it
// by stopping the flips early (flip_budget).
#include <algorithm>

#include "delaunay3_mesh.hpp"
#include "geods/core/error.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kNone = Tet3Mesh::kNone;
constexpr std::uint32_t kGhost = Tet3Mesh::kGhost;
constexpr std::uint32_t kGhostBit = Tet3Mesh::kGhostBit;
using Quad = std::array<std::uint32_t, 4>;

bool same(const Vec3d& a, const Vec3d& b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

bool has_ghost(const Quad& q) { return ((q[0] | q[1] | q[2] | q[3]) & kGhostBit) != 0; }

Quad quad_of(const std::uint32_t* T, std::uint32_t t) {
  const std::uint32_t* v = &T[8 * std::size_t(t)];
  return {v[0], v[1], v[2], v[3]};
}

Quad with(Quad q, int k, std::uint32_t v) {
  q[k] = v;
  return q;
}

int index_of(const Quad& q, std::uint32_t v) {
  for (int k = 0; k < 4; ++k)
    if (q[k] == v) return k;
  return -1;
}

/// The ghost tetrahedron on the far side of a finite q's face opposite k: k
/// becomes the ghost and two other entries swap (the ghost's side).
Quad ghost_beyond(Quad q, int k) {
  q[k] = kGhost;
  std::swap(q[(k + 1) % 4], q[(k + 2) % 4]);
  return q;
}

}  // namespace

std::uint32_t Tet3Mesh::insert_by_flips(std::uint32_t pv) {
  const Vec3d& p = coords[pv];
  const auto orient_of = [&](const Quad& q) { return orient(coords[q[0]], coords[q[1]], coords[q[2]], coords[q[3]]); };

  // Replaces the slots `old` by the tetrahedra `fresh` (positively oriented,
  // filling the same region): linked to each other and across the old set's
  // boundary, matched by their faces' vertices; every new face opposite pv
  // goes on the flip stack.
  const auto replace = [&](const std::uint32_t* old, std::size_t old_count, const Quad* fresh, std::size_t fresh_count) {
    std::uint8_t* M = mark.data();
    for (std::size_t k = 0; k < old_count; ++k) M[old[k]] = 3;
    faces.clear();
    for (std::size_t k = 0; k < old_count; ++k)
      for (int f = 0; f < 4; ++f) {
        const std::uint32_t a = tets[8 * std::size_t(old[k]) + 4 + f];
        if (M[a >> 2] == 3) continue;
        FaceKey& e = faces.emplace_back();
        int m = 0;
        for (int j = 0; j < 4; ++j)
          if (j != f) e.key[m++] = tets[8 * std::size_t(old[k]) + j];
        std::sort(e.key.begin(), e.key.end());
        e.adjacency = a;
        e.outer = true;
      }
    for (std::size_t k = 0; k < old_count; ++k) {
      M[old[k]] = 0;
      free_slot(old[k]);
    }
    std::uint32_t newest = kNone;
    for (std::size_t k = 0; k < fresh_count; ++k) {
      const std::uint32_t s = new_slot();
      std::copy_n(fresh[k].data(), 4, &tets[8 * std::size_t(s)]);
      for (int f = 0; f < 4; ++f) {
        FaceKey& e = faces.emplace_back();
        int m = 0;
        for (int j = 0; j < 4; ++j)
          if (j != f) e.key[m++] = fresh[k][j];
        std::sort(e.key.begin(), e.key.end());
        e.adjacency = 4 * s + std::uint32_t(f);
        e.outer = false;
      }
      const int i = index_of(fresh[k], pv);
      flip_stack.push_back(4 * s + std::uint32_t(i));
      if (newest == kNone || !has_ghost(fresh[k])) newest = s;
    }
    std::sort(faces.begin(), faces.end(), [](const FaceKey& a, const FaceKey& b) { return a.key < b.key; });
    for (std::size_t k = 0; k < faces.size(); k += 2) {
      if (k + 1 >= faces.size() || faces[k].key != faces[k + 1].key || (faces[k].outer && faces[k + 1].outer) ||
          (k + 2 < faces.size() && faces[k + 2].key == faces[k].key))
        throw Error("Delaunay3: flip insertion found an unmatched face (internal error)");
      const std::uint32_t a = faces[k].adjacency, b = faces[k + 1].adjacency;
      tets[entry(a)] = b;
      tets[entry(b)] = a;
    }
    last = newest;
  };

  // The star of pv over a set of slots: each face of theirs towards a slot
  // outside the set (marked 1 inside) joined to pv.
  std::vector<Quad> fresh;
  const auto star_of_set = [&](const std::vector<std::uint32_t>& set) {
    fresh.clear();
    for (const std::uint32_t c : set)
      for (int f = 0; f < 4; ++f)
        if (mark[tets[8 * std::size_t(c) + 4 + f] >> 2] != 1) fresh.push_back(with(quad_of(tets.data(), c), f, pv));
    for (const std::uint32_t c : set) mark[c] = 0;
    replace(set.data(), set.size(), fresh.data(), fresh.size());
  };

  flip_stack.clear();
  flip_skipped.clear();
  const std::uint32_t t = walk(p, last, walk_steps, random);
  if (!is_ghost(t)) {
    const Quad q = quad_of(tets.data(), t);
    for (int k = 0; k < 4; ++k)
      if (same(coords[q[k]], p)) {
        last = t;
        return q[k];
      }
    double o[4];
    int zeros = 0;
    for (int k = 0; k < 4; ++k) zeros += (o[k] = orient_of(with(q, k, pv))) == 0;
    if (zeros == 0) {
      // 1-4: new k is q with p for vertex k; its face k is q's, its face j
      // new j's face k.
      const std::uint32_t s[4] = {t, new_slot(), new_slot(), new_slot()};
      std::uint32_t outer[4];
      for (int k = 0; k < 4; ++k) outer[k] = tets[8 * std::size_t(t) + 4 + k];
      for (int k = 0; k < 4; ++k) {
        std::uint32_t* w = &tets[8 * std::size_t(s[k])];
        std::copy_n(q.data(), 4, w);
        w[k] = pv;
        for (int j = 0; j < 4; ++j) w[4 + j] = j == k ? outer[k] : 4 * s[j] + std::uint32_t(k);
        tets[entry(outer[k])] = 4 * s[k] + std::uint32_t(k);
        flip_stack.push_back(4 * s[k] + std::uint32_t(k));
      }
      last = t;
      ++flip_counts[flip_14];
    } else {
      // On a face or an edge: every tetrahedron whose closed volume holds p,
      // reached across the faces p lies on (ghosts through their hull triangle).
      cavity.assign(1, t);
      mark[t] = 1;
      for (std::size_t k = 0; k < cavity.size(); ++k) {
        const std::uint32_t c = cavity[k];
        if (is_ghost(c)) continue;
        const Quad cq = quad_of(tets.data(), c);
        for (int f = 0; f < 4; ++f) {
          if (orient_of(with(cq, f, pv)) != 0) continue;
          const std::uint32_t n = tets[8 * std::size_t(c) + 4 + f] >> 2;
          if (mark[n] != 1) mark[n] = 1, cavity.push_back(n);
        }
      }
      star_of_set(cavity);
      ++flip_counts[flip_split];
    }
  } else {
    // Outside the hull: the ghosts whose hull triangle p sees, connected across their hull edges.
    stack.clear();
    cavity.assign(1, t);
    mark[t] = 1;
    for (std::size_t k = 0; k < cavity.size(); ++k) {
      const std::uint32_t c = cavity[k];
      const int g = ghost_index(c);
      for (int f = 0; f < 4; ++f) {
        if (f == g) continue;
        const std::uint32_t n = tets[8 * std::size_t(c) + 4 + f] >> 2;
        if (mark[n] != 0) continue;
        const Quad nq = quad_of(tets.data(), n);
        if (orient_of(with(nq, index_of(nq, kGhost), pv)) > 0) {
          mark[n] = 1;
          cavity.push_back(n);
        } else {
          mark[n] = 2;
          stack.push_back(n);
        }
      }
    }
    for (const std::uint32_t n : stack) mark[n] = 0;
    stack.clear();
    star_of_set(cavity);
    ++flip_counts[flip_hull];
  }

  // The flips.
  Quad made[4];
  std::uint32_t gone[4];
  std::size_t flips_made = 0;
  while (!flip_stack.empty()) {
    if (flips_made == flip_budget) {  // (tests: leave the rest to the repair below)
      flip_skipped.insert(flip_skipped.end(), flip_stack.begin(), flip_stack.end());
      break;
    }
    const std::uint32_t code = flip_stack.back();
    flip_stack.pop_back();
    const std::uint32_t t0 = code >> 2;
    const int i = int(code & 3);
    if (tets[8 * std::size_t(t0) + i] != pv) continue;  // flipped away since
    const std::uint32_t a = tets[8 * std::size_t(t0) + 4 + i], n = a >> 2;
    const std::uint32_t x = tets[opposite(a)];
    if (x == kGhost) continue;  // a hull triangle of a finite tetrahedron: p is inside
    if (!conflict(coords.data(), tets.data(), n, p)) continue;
    const Quad tq = quad_of(tets.data(), t0);
    const int g = index_of(tq, kGhost);
    // sign[k]: the orientation of tq with vertex k replaced by x (the new
    // tetrahedron of a 2-3 flip that keeps the face's other two vertices).
    int negative = -1, zero = -1, negatives = 0, zeros = 0;
    if (g >= 0) {
      // A ghost face (two hull triangles beside each other): p is coplanar with
      // the other one (it sees no hull triangle any more), only a 4-4 can apply.
      if (orient_of(with(tq, g, x)) == 0) zero = g, zeros = 1;
      else negatives = 2;
    } else {
      for (int k = 0; k < 4; ++k) {
        if (k == i) continue;
        const double s = orient_of(with(tq, k, x));
        if (s < 0) negative = k, ++negatives;
        if (s == 0) zero = k, ++zeros;
      }
    }
    bool done = false;
    if (negatives == 0 && zeros == 0 && g < 0) {
      // 2-3: new m is tq with x for vertex k = ks[m]; its face k is tq's, its
      // face i (opposite p) n's face without tq[k], its face ks[m2] new m2's face k.
      const Quad nq = quad_of(tets.data(), n);
      int ks[3], m = 0;
      for (int k = 0; k < 4; ++k)
        if (k != i) ks[m++] = k;
      std::uint32_t at_t[3], at_n[3];
      for (m = 0; m < 3; ++m) {
        at_t[m] = tets[8 * std::size_t(t0) + 4 + ks[m]];
        at_n[m] = tets[8 * std::size_t(n) + 4 + index_of(nq, tq[ks[m]])];
      }
      const std::uint32_t s[3] = {t0, n, new_slot()};
      for (m = 0; m < 3; ++m) {
        std::uint32_t* w = &tets[8 * std::size_t(s[m])];
        std::copy_n(tq.data(), 4, w);
        w[ks[m]] = x;
        for (int m2 = 0; m2 < 3; ++m2)
          if (m2 != m) w[4 + ks[m2]] = 4 * s[m2] + std::uint32_t(ks[m]);
        w[4 + ks[m]] = at_t[m], tets[entry(at_t[m])] = 4 * s[m] + std::uint32_t(ks[m]);
        w[4 + i] = at_n[m], tets[entry(at_n[m])] = 4 * s[m] + std::uint32_t(i);
        flip_stack.push_back(4 * s[m] + std::uint32_t(i));
      }
      last = t0;
      ++flip_counts[flip_23];
      done = true;
    } else if (negatives == 0 && zeros == 0) {  // (a ghost 2-3: not expected once p sees no hull triangle)
      gone[0] = t0, gone[1] = n;
      int m = 0;
      for (int k = 0; k < 4; ++k)
        if (k != i) made[m++] = with(tq, k, x);
      replace(gone, 2, made, 3);
      ++flip_counts[flip_23];
      done = true;
    } else if (negatives == 1 && zeros == 0) {
      // 3-2 about the edge of the face without vertex `negative`, if the third
      // tetrahedron around it (across tq's face `negative`) has x.
      const std::uint32_t a3 = tets[8 * std::size_t(t0) + 4 + negative];
      if (tets[opposite(a3)] == x) {
        // New m is tq with x for the edge's vertex k = ks[m]: its face k is tq's,
        // its face i n's face without tq[k], its face `negative` the third's face
        // without tq[k], its face ks[1 - m] the other new one's face k.
        const std::uint32_t t3 = a3 >> 2;
        const Quad nq = quad_of(tets.data(), n), t3q = quad_of(tets.data(), t3);
        int ks[2], m = 0;
        for (int k = 0; k < 4; ++k)
          if (k != i && k != negative) ks[m++] = k;
        std::uint32_t at_t[2], at_n[2], at_3[2];
        for (m = 0; m < 2; ++m) {
          at_t[m] = tets[8 * std::size_t(t0) + 4 + ks[m]];
          at_n[m] = tets[8 * std::size_t(n) + 4 + index_of(nq, tq[ks[m]])];
          at_3[m] = tets[8 * std::size_t(t3) + 4 + index_of(t3q, tq[ks[m]])];
        }
        free_slot(t3);
        const std::uint32_t s[2] = {t0, n};
        for (m = 0; m < 2; ++m) {
          std::uint32_t* w = &tets[8 * std::size_t(s[m])];
          std::copy_n(tq.data(), 4, w);
          w[ks[m]] = x;
          w[4 + ks[1 - m]] = 4 * s[1 - m] + std::uint32_t(ks[m]);
          w[4 + ks[m]] = at_t[m], tets[entry(at_t[m])] = 4 * s[m] + std::uint32_t(ks[m]);
          w[4 + i] = at_n[m], tets[entry(at_n[m])] = 4 * s[m] + std::uint32_t(i);
          w[4 + negative] = at_3[m], tets[entry(at_3[m])] = 4 * s[m] + std::uint32_t(negative);
          flip_stack.push_back(4 * s[m] + std::uint32_t(i));
        }
        last = t0;
        ++flip_counts[flip_32];
        done = true;
      }
    } else if (negatives == 0 && zeros == 1) {
      // 4-4 about the edge e = {u, v} of the face without vertex `zero` (p, x, u, v
      // coplanar): tq, its neighbour across face `zero` (p, f, u, v), n, and n's
      // neighbour across its face without tq[zero] (x, f, u, v).
      const std::uint32_t a2 = tets[8 * std::size_t(t0) + 4 + zero], t2 = a2 >> 2;
      const std::uint32_t f = tets[opposite(a2)];
      const Quad nq = quad_of(tets.data(), n);
      const std::uint32_t a4 = tets[8 * std::size_t(n) + 4 + index_of(nq, tq[zero])], n2 = a4 >> 2;
      if (tets[opposite(a4)] == f && n2 != t2) {
        int e[2], m = 0;
        for (int k = 0; k < 4; ++k)
          if (k != i && k != zero) e[m++] = k;
        const std::uint32_t u = tq[e[0]], v = tq[e[1]];
        const Quad t2q = quad_of(tets.data(), t2);
        made[0] = with(tq, e[1], x);                    // p, x, tq[zero], u
        made[1] = with(tq, e[0], x);                    // p, x, tq[zero], v
        made[2] = with(t2q, index_of(t2q, v), x);       // p, x, f, u
        made[3] = with(t2q, index_of(t2q, u), x);       // p, x, f, v
        bool valid = true;
        for (int k = 0; k < 4 && valid; ++k)
          if (!has_ghost(made[k])) valid = orient_of(made[k]) > 0;
        if (valid) {
          // The ghost ones from the finite one beside them (sharing p, x and u or v).
          if (g >= 0) {
            made[0] = ghost_beyond(made[2], index_of(made[2], f));
            made[1] = ghost_beyond(made[3], index_of(made[3], f));
          } else if (f == kGhost) {
            made[2] = ghost_beyond(made[0], index_of(made[0], tq[zero]));
            made[3] = ghost_beyond(made[1], index_of(made[1], tq[zero]));
          }
          gone[0] = t0, gone[1] = n, gone[2] = n2, gone[3] = t2;
          replace(gone, 4, made, 4);
          ++flip_counts[flip_44];
          done = true;
        }
      }
    }
    flips_made += done;
    if (!done) {
      ++flip_counts[flip_unflippable];
      flip_skipped.push_back(code);
    }
  }

  // A face skipped and never flipped away that is still not Delaunay: finish
  // with the cavity step from the star (the tetrahedra holding pv, and those
  // in conflict with it beyond).
  for (const std::uint32_t code : flip_skipped) {
    const std::uint32_t t0 = code >> 2;
    const int i = int(code & 3);
    if (tets[8 * std::size_t(t0) + i] != pv) continue;
    const std::uint32_t a = tets[8 * std::size_t(t0) + 4 + i];
    if (tets[opposite(a)] == kGhost || !conflict(coords.data(), tets.data(), a >> 2, p)) continue;
    stack.clear();
    cavity.assign(1, t0);
    mark[t0] = 1;
    for (std::size_t k = 0; k < cavity.size(); ++k) {
      const std::uint32_t c = cavity[k];
      for (int f = 0; f < 4; ++f) {
        const std::uint32_t nb = tets[8 * std::size_t(c) + 4 + f] >> 2;
        if (mark[nb] != 0) continue;
        const bool in = index_of(quad_of(tets.data(), nb), pv) >= 0 || conflict(coords.data(), tets.data(), nb, p);
        mark[nb] = in ? 1 : 2;
        (in ? cavity : stack).push_back(nb);
      }
    }
    for (const std::uint32_t nb : stack) mark[nb] = 0;
    stack.clear();
    star_of_set(cavity);
    flip_stack.clear();
    ++flip_counts[flip_repair];
    break;
  }
  return kNone;
}

}  // namespace geods::voronoi
