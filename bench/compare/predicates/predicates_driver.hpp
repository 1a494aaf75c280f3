#pragma once
// The predicates comparison: the same input tuples and the same timing loop for every
// library; each program only supplies an adapter (see compare_predicates_*.cpp).
//
// Predicates (all signs in geods' = Shewchuk's convention):
//   orient2d (3 points), incircle (4), orient3d (4), insphere (5).
// Input sets, identical for every library (fixed seeds, compare::SplitMix64):
//   uniform     random tuples of workload points (del2_uniform.f64 / del3_uniform.f64):
//               the floating-point filter decides (almost) every call.
//   degenerate  exactly degenerate tuples on integer coordinates: collinear triples and
//               co-circular rectangle corners taken from del2_grid.f64; coplanar quadruples and
//               co-spherical box corners on an integer lattice in 3D. Every sign is 0: the filter
//               can never decide, every call takes the exact path.
//   near        the same constructions computed in floating point from uniform workload points
//               (c = a + t (b - a), rectangle and box corners), so rounding leaves them nearly
//               degenerate: signs are hard, the plain double determinant gets many wrong.
// Sanity ("ok"): degenerate: every sign is 0; uniform: the sign equals the plain determinant's
// wherever |det| > 1e-9 (far beyond its rounding error for coordinates in [0,1));
// near: no in-program oracle, run.py compares "sign_hash" (FNV-1a of all signs) across libraries.
//
// Adapter interface (struct Lib):
//   static constexpr const char* anchor;
//   using P2 = ...; using P3 = ...;                 the library's own point types
//   static P2 p2(const double*); static P3 p3(const double*);
//   static int orient2d(const P2&, const P2&, const P2&);                 sign -1/0/+1
//   static int incircle(const P2&, const P2&, const P2&, const P2&);
//   static int orient3d(const P3&, const P3&, const P3&, const P3&);
//   static int insphere(const P3&, const P3&, const P3&, const P3&, const P3&);
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common.hpp"

namespace compare::predicates {

enum class Pred { orient2d, incircle, orient3d, insphere };

inline const char* name(Pred p) {
  switch (p) {
    case Pred::orient2d: return "orient2d";
    case Pred::incircle: return "incircle";
    case Pred::orient3d: return "orient3d";
    case Pred::insphere: return "insphere";
  }
  return "?";
}
inline int dim(Pred p) { return p == Pred::orient2d || p == Pred::incircle ? 2 : 3; }
inline int arity(Pred p) {
  switch (p) {
    case Pred::orient2d: return 3;
    case Pred::incircle: return 4;
    case Pred::orient3d: return 4;
    case Pred::insphere: return 5;
  }
  return 0;
}

// ----------------------------------------------------------------------------- plain determinants
// The reference for the "uniform" check (and the same formulas as geods::*_fast).

inline double det_orient2d(const double* a, const double* b, const double* c) {
  return (a[0] - c[0]) * (b[1] - c[1]) - (a[1] - c[1]) * (b[0] - c[0]);
}
inline double det_incircle(const double* a, const double* b, const double* c, const double* d) {
  double adx = a[0] - d[0], ady = a[1] - d[1], bdx = b[0] - d[0], bdy = b[1] - d[1];
  double cdx = c[0] - d[0], cdy = c[1] - d[1];
  double alift = adx * adx + ady * ady, blift = bdx * bdx + bdy * bdy, clift = cdx * cdx + cdy * cdy;
  return alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy) + clift * (adx * bdy - bdx * ady);
}
inline double det_orient3d(const double* a, const double* b, const double* c, const double* d) {
  double adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
  double bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
  double cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
  return adx * (bdy * cdz - bdz * cdy) + bdx * (cdy * adz - cdz * ady) + cdx * (ady * bdz - adz * bdy);
}
inline double det_insphere(const double* a, const double* b, const double* c, const double* d,
                           const double* e) {
  double aex = a[0] - e[0], aey = a[1] - e[1], aez = a[2] - e[2];
  double bex = b[0] - e[0], bey = b[1] - e[1], bez = b[2] - e[2];
  double cex = c[0] - e[0], cey = c[1] - e[1], cez = c[2] - e[2];
  double dex = d[0] - e[0], dey = d[1] - e[1], dez = d[2] - e[2];
  double ab = aex * bey - bex * aey, bc = bex * cey - cex * bey, cd = cex * dey - dex * cey;
  double da = dex * aey - aex * dey, ac = aex * cey - cex * aey, bd = bex * dey - dex * bey;
  double abc = aez * bc - bez * ac + cez * ab, bcd = bez * cd - cez * bd + dez * bc;
  double cda = cez * da + dez * ac + aez * cd, dab = dez * ab + aez * bd + bez * da;
  double alift = aex * aex + aey * aey + aez * aez, blift = bex * bex + bey * bey + bez * bez;
  double clift = cex * cex + cey * cey + cez * cez, dlift = dex * dex + dey * dey + dez * dez;
  return (dlift * abc - clift * dab) + (blift * cda - alift * bcd);
}
inline double det(Pred p, const double* t) {
  int d = dim(p);
  switch (p) {
    case Pred::orient2d: return det_orient2d(t, t + d, t + 2 * d);
    case Pred::incircle: return det_incircle(t, t + d, t + 2 * d, t + 3 * d);
    case Pred::orient3d: return det_orient3d(t, t + d, t + 2 * d, t + 3 * d);
    case Pred::insphere: return det_insphere(t, t + d, t + 2 * d, t + 3 * d, t + 4 * d);
  }
  return 0;
}

// ----------------------------------------------------------------------------- input sets

struct Inputs {
  std::string variant;        // e.g. "incircle/degenerate"
  Pred pred;
  std::vector<double> coords;  // calls × arity × dim, tuple after tuple
  bool all_zero = false;       // every sign must be 0
  bool check_uniform = false;  // compare with the plain determinant where it is safe
  std::size_t calls() const { return coords.size() / static_cast<std::size_t>(arity(pred) * dim(pred)); }
};

/// Workload points shared by all sets (loaded once).
struct Workload {
  std::vector<double> del2_uniform, del2_grid, del3_uniform;
  explicit Workload(const Args& args)
      : del2_uniform(read_raw<double>(args.path("del2_uniform.f64"))),
        del2_grid(read_raw<double>(args.path("del2_grid.f64"))),
        del3_uniform(read_raw<double>(args.path("del3_uniform.f64"))) {
    if (del2_grid.size() != 2'000'000) die("del2_grid.f64 must hold 1000 x 1000 points");
  }
};

inline std::uint64_t seed_of(Pred p, int set) { return 0x9ED5'0000ULL + 16 * static_cast<int>(p) + set; }

/// uniform: random tuples of workload points.
inline Inputs make_uniform(const Workload& w, Pred p, std::size_t calls) {
  Inputs in{std::string(name(p)) + "/uniform", p, {}, false, true};
  const std::vector<double>& pts = dim(p) == 2 ? w.del2_uniform : w.del3_uniform;
  const int d = dim(p), k = arity(p);
  const std::size_t n = pts.size() / static_cast<std::size_t>(d);
  SplitMix64 rng(seed_of(p, 0));
  in.coords.reserve(calls * static_cast<std::size_t>(k * d));
  for (std::size_t i = 0; i < calls; ++i)
    for (int j = 0; j < k; ++j) {
      std::size_t idx = rng.below(n);
      for (int c = 0; c < d; ++c) in.coords.push_back(pts[idx * static_cast<std::size_t>(d) + static_cast<std::size_t>(c)]);
    }
  return in;
}

/// Random order of the first k of 0..n-1 (Fisher–Yates prefix).
template <std::size_t N>
inline std::array<int, N> shuffled(SplitMix64& rng) {
  std::array<int, N> a{};
  for (std::size_t i = 0; i < N; ++i) a[i] = static_cast<int>(i);
  for (std::size_t i = N - 1; i > 0; --i) std::swap(a[i], a[rng.below(i + 1)]);
  return a;
}

/// degenerate: exactly degenerate integer tuples (2D from del2_grid.f64, 3D on a lattice).
inline Inputs make_degenerate(const Workload& w, Pred p, std::size_t calls) {
  Inputs in{std::string(name(p)) + "/degenerate", p, {}, true, false};
  SplitMix64 rng(seed_of(p, 1));
  auto grid_point = [&](std::int64_t x, std::int64_t y) {  // coordinates read from the workload file
    std::size_t k = static_cast<std::size_t>(x + 1000 * y);
    in.coords.push_back(w.del2_grid[2 * k]);
    in.coords.push_back(w.del2_grid[2 * k + 1]);
  };
  auto inside = [](std::int64_t v, std::int64_t hi) { return v >= 0 && v < hi; };
  while (in.calls() < calls) {
    if (p == Pred::orient2d) {  // a, a + i u, a + j u: collinear
      std::int64_t x = rng.range(0, 999), y = rng.range(0, 999);
      std::int64_t dx = rng.range(-8, 8), dy = rng.range(-8, 8), i = rng.range(-20, 20), j = rng.range(-20, 20);
      if ((dx == 0 && dy == 0) || i == 0 || j == 0 || i == j) continue;
      std::int64_t px[3] = {x, x + i * dx, x + j * dx}, py[3] = {y, y + i * dy, y + j * dy};
      bool ok = true;
      for (int m = 0; m < 3; ++m) ok = ok && inside(px[m], 1000) && inside(py[m], 1000);
      if (!ok) continue;
      auto order = shuffled<3>(rng);
      for (int m : order) grid_point(px[m], py[m]);
    } else if (p == Pred::incircle) {  // corners of a (rotated) lattice rectangle: co-circular
      std::int64_t x = rng.range(0, 999), y = rng.range(0, 999);
      std::int64_t ux = rng.range(-10, 10), uy = rng.range(-10, 10), s = rng.range(1, 4);
      if (ux == 0 && uy == 0) continue;
      std::int64_t vx = -s * uy, vy = s * ux;
      std::int64_t px[4] = {x, x + ux, x + ux + vx, x + vx}, py[4] = {y, y + uy, y + uy + vy, y + vy};
      bool ok = true;
      for (int m = 0; m < 4; ++m) ok = ok && inside(px[m], 1000) && inside(py[m], 1000);
      if (!ok) continue;
      auto order = shuffled<4>(rng);
      for (int m : order) grid_point(px[m], py[m]);
    } else if (p == Pred::orient3d) {  // a + i u + j v: coplanar lattice points
      std::int64_t a[3], u[3], v[3];
      for (int c = 0; c < 3; ++c) a[c] = rng.range(0, 255), u[c] = rng.range(-6, 6), v[c] = rng.range(-6, 6);
      std::int64_t n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      if (n[0] == 0 && n[1] == 0 && n[2] == 0) continue;  // u, v parallel
      for (int m = 0; m < 4; ++m) {
        std::int64_t i = m == 0 ? 0 : rng.range(-5, 5), j = m == 0 ? 0 : rng.range(-5, 5);
        for (int c = 0; c < 3; ++c) in.coords.push_back(static_cast<double>(a[c] + i * u[c] + j * v[c]));
      }
    } else {  // insphere: 5 of the 8 corners of a rotated lattice box: co-spherical
      std::int64_t a[3], u[3];
      for (int c = 0; c < 3; ++c) a[c] = rng.range(0, 255), u[c] = rng.range(-4, 4);
      if (u[0] == 0 && u[1] == 0) continue;
      std::int64_t s = rng.range(1, 3), t = rng.range(1, 2);
      std::int64_t v[3] = {-s * u[1], s * u[0], 0};  // u . v = 0
      std::int64_t w[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      for (auto& c : w) c *= t;
      auto order = shuffled<8>(rng);
      for (int m = 0; m < 5; ++m) {
        int corner = order[static_cast<std::size_t>(m)];
        std::int64_t i = corner & 1, j = (corner >> 1) & 1, l = (corner >> 2) & 1;
        for (int c = 0; c < 3; ++c) in.coords.push_back(static_cast<double>(a[c] + i * u[c] + j * v[c] + l * w[c]));
      }
    }
  }
  return in;
}

/// near: the degenerate constructions evaluated in floating point from uniform workload points.
inline Inputs make_near(const Workload& w, Pred p, std::size_t calls) {
  Inputs in{std::string(name(p)) + "/near", p, {}, false, false};
  SplitMix64 rng(seed_of(p, 2));
  const std::vector<double>& pts = dim(p) == 2 ? w.del2_uniform : w.del3_uniform;
  const std::size_t d = static_cast<std::size_t>(dim(p)), n = pts.size() / d;
  auto pick = [&](double* out) {
    std::size_t idx = rng.below(n);
    for (std::size_t c = 0; c < d; ++c) out[c] = pts[idx * d + c];
  };
  auto push = [&](const double* q) { in.coords.insert(in.coords.end(), q, q + d); };
  for (std::size_t call = 0; call < calls; ++call) {
    double a[3], b[3], c[3];
    pick(a), pick(b), pick(c);
    if (p == Pred::orient2d) {  // c on segment ab, rounded
      double t = rng.uniform(), q[2] = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
      auto order = shuffled<3>(rng);
      const double* pt[3] = {a, b, q};
      for (int m : order) push(pt[m]);
    } else if (p == Pred::incircle) {  // rectangle a, a+u, a+u+v, a+v with v = s rot90(u)
      double s = 0.2 + 0.8 * rng.uniform(), u[2] = {b[0] - a[0], b[1] - a[1]}, v[2] = {-s * u[1], s * u[0]};
      double q[4][2] = {{a[0], a[1]}, {a[0] + u[0], a[1] + u[1]}, {a[0] + u[0] + v[0], a[1] + u[1] + v[1]},
                        {a[0] + v[0], a[1] + v[1]}};
      auto order = shuffled<4>(rng);
      for (int m : order) push(q[m]);
    } else if (p == Pred::orient3d) {  // d = a + s (b - a) + t (c - a), rounded
      double s = rng.uniform() - 0.5, t = rng.uniform() - 0.5, q[3];
      for (std::size_t k = 0; k < 3; ++k) q[k] = a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]);
      push(a), push(b), push(c), push(q);
    } else {  // 5 corners of the box spanned by u = b - a, v ⟂ u, w = u × v (same lengths)
      double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, r[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      double v[3] = {u[1] * r[2] - u[2] * r[1], u[2] * r[0] - u[0] * r[2], u[0] * r[1] - u[1] * r[0]};
      double w3[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      double lu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      double lv = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      double lw = std::sqrt(w3[0] * w3[0] + w3[1] * w3[1] + w3[2] * w3[2]);
      if (lu == 0 || lv == 0 || lw == 0) {
        --call;
        continue;
      }
      double sv = (0.5 + 0.5 * rng.uniform()) * lu / lv, sw = (0.5 + 0.5 * rng.uniform()) * lu / lw;
      for (std::size_t k = 0; k < 3; ++k) v[k] *= sv, w3[k] *= sw;
      auto order = shuffled<8>(rng);
      for (int m = 0; m < 5; ++m) {
        int corner = order[static_cast<std::size_t>(m)];
        double q[3];
        for (std::size_t k = 0; k < 3; ++k)
          q[k] = a[k] + (corner & 1 ? u[k] : 0.0) + (corner & 2 ? v[k] : 0.0) + (corner & 4 ? w3[k] : 0.0);
        push(q);
      }
    }
  }
  return in;
}

// ----------------------------------------------------------------------------- measurement

template <class Lib>
struct Converted {
  std::vector<typename Lib::P2> p2;
  std::vector<typename Lib::P3> p3;
};

/// Evaluates the predicate on calls [lo, hi) into signs.
template <class Lib>
void evaluate(Pred p, const Converted<Lib>& pts, std::int8_t* signs, std::size_t lo, std::size_t hi) {
  switch (p) {
    case Pred::orient2d:
      for (std::size_t i = lo; i < hi; ++i) {
        const auto* t = &pts.p2[3 * i];
        signs[i] = static_cast<std::int8_t>(Lib::orient2d(t[0], t[1], t[2]));
      }
      break;
    case Pred::incircle:
      for (std::size_t i = lo; i < hi; ++i) {
        const auto* t = &pts.p2[4 * i];
        signs[i] = static_cast<std::int8_t>(Lib::incircle(t[0], t[1], t[2], t[3]));
      }
      break;
    case Pred::orient3d:
      for (std::size_t i = lo; i < hi; ++i) {
        const auto* t = &pts.p3[4 * i];
        signs[i] = static_cast<std::int8_t>(Lib::orient3d(t[0], t[1], t[2], t[3]));
      }
      break;
    case Pred::insphere:
      for (std::size_t i = lo; i < hi; ++i) {
        const auto* t = &pts.p3[5 * i];
        signs[i] = static_cast<std::int8_t>(Lib::insphere(t[0], t[1], t[2], t[3], t[4]));
      }
      break;
  }
}

template <class Lib>
void measure(const Args& args, const Inputs& in) {
  const std::size_t calls = in.calls(), k = static_cast<std::size_t>(arity(in.pred));
  const std::size_t d = static_cast<std::size_t>(dim(in.pred));
  Converted<Lib> pts;  // the library's own point type, built before timing
  for (std::size_t i = 0; i < calls * k; ++i) {
    if (d == 2) pts.p2.push_back(Lib::p2(&in.coords[2 * i]));
    else pts.p3.push_back(Lib::p3(&in.coords[3 * i]));
  }
  std::vector<std::int8_t> signs(calls, 2);
  double query_s = median_time_s(args.reps, [&] {
    if (args.threads == 1) {
      evaluate<Lib>(in.pred, pts, signs.data(), 0, calls);
    } else {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, calls, 4096),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          evaluate<Lib>(in.pred, pts, signs.data(), r.begin(), r.end());
                        });
    }
    do_not_optimize(signs.data());
  });

  std::size_t pos = 0, neg = 0, zero = 0, checked = 0, wrong = 0;
  for (std::size_t i = 0; i < calls; ++i) {
    int s = signs[i];
    pos += s > 0, neg += s < 0, zero += s == 0;
    if (in.all_zero) {
      ++checked;
      wrong += s != 0;
    } else if (in.check_uniform) {
      double v = det(in.pred, &in.coords[i * k * d]);
      if (std::abs(v) > 1e-9) {
        ++checked;
        wrong += s != (v > 0 ? 1 : -1);
      }
    }
  }
  Record rec("predicates", Lib::anchor, in.variant, args.threads);
  rec.timing(0.0, query_s, calls, args.reps)
      .set("calls_per_s", static_cast<double>(calls) / query_s)
      .set("ns_per_call", 1e9 * query_s / static_cast<double>(calls))
      .set("pos", static_cast<unsigned long long>(pos))
      .set("neg", static_cast<unsigned long long>(neg))
      .set("zero", static_cast<unsigned long long>(zero))
      .set("sign_hash", hex64(fnv1a(signs.data(), signs.size())))
      .set("checked", static_cast<unsigned long long>(checked))
      .set("wrong", static_cast<unsigned long long>(wrong))
      .print(wrong == 0);
}

/// The whole comparison for one library: every predicate × every input set.
template <class Lib>
int run(int argc, char** argv) {
  Args args = parse_args(argc, argv);
  ThreadLimit limit(args.threads);
  Workload w(args);
  const std::size_t n_uniform = args.scaled(2'000'000), n_hard = args.scaled(200'000);
  for (Pred p : {Pred::orient2d, Pred::incircle, Pred::orient3d, Pred::insphere}) {
    std::string pn = name(p);
    if (args.wants(pn + "/uniform")) measure<Lib>(args, make_uniform(w, p, n_uniform));
    if (args.wants(pn + "/degenerate")) measure<Lib>(args, make_degenerate(w, p, n_hard));
    if (args.wants(pn + "/near")) measure<Lib>(args, make_near(w, p, n_hard));
  }
  return 0;
}

}  // namespace compare::predicates
