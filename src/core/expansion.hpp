#pragma once
// Shewchuk's floating-point expansions: a number held exactly as a sum of
// doubles that do not overlap, smallest first. Sums and products of doubles
// are computed without any rounding error, so the sign of a determinant built
// from them is exact.
//
// Exactness needs every intermediate value to stay clear of overflow and of
// underflow below 2^-1074; predicates.cpp checks the inputs before using these.
// Each Expansion<N> has room for N components, fixed at compile time from the
// shape of the formula, so the exact paths never allocate.
#include <algorithm>
#include <cmath>
#include <utility>

namespace geods::exact {

/// a + b = sum + error, both doubles, exactly (Knuth's branch-free TwoSum).
struct TwoTerm {
  double head;  // the rounded result
  double tail;  // its rounding error
};

inline TwoTerm two_sum(double a, double b) {
  const double s = a + b;
  const double bv = s - a;
  const double av = s - bv;
  return {s, (a - av) + (b - bv)};
}

inline TwoTerm two_diff(double a, double b) {
  const double d = a - b;
  const double bv = a - d;
  const double av = d + bv;
  return {d, (a - av) + (bv - b)};
}

/// Valid only when |a| >= |b| (or a == 0); three flops instead of six.
inline TwoTerm fast_two_sum(double a, double b) {
  const double s = a + b;
  return {s, b - (s - a)};
}

#ifdef __FMA__
inline TwoTerm two_product(double a, double b) {
  const double p = a * b;
  return {p, std::fma(a, b, -p)};
}
#else
// Without hardware FMA in the target (plain x86-64), std::fma is a library
// call; Dekker's product with Veltkamp's splitting is exact too and inlines.
// The splitting needs |a| < 2^996, which the callers' input window ensures.
inline TwoTerm split(double a) {
  const double c = 134217729.0 * a;  // 2^27 + 1
  const double big = c - a;
  const double hi = c - big;
  return {hi, a - hi};
}

// a * b with b already split (b == bs.head + bs.tail): scaling an expansion
// splits its factor once.
inline TwoTerm two_product_presplit(double a, double b, TwoTerm bs) {
  const double p = a * b;
  const TwoTerm as = split(a);
  const double err1 = p - as.head * bs.head;
  const double err2 = err1 - as.tail * bs.head;
  const double err3 = err2 - as.head * bs.tail;
  return {p, as.tail * bs.tail - err3};
}

inline TwoTerm two_product(double a, double b) { return two_product_presplit(a, b, split(b)); }
#endif

template <int N>
struct Expansion {
  static constexpr int capacity = N;
  double c[N];   // components by increasing magnitude, no zeros
  int size = 0;  // 0 means the value zero

  /// The sign of the value: its largest component has it.
  double top() const { return size == 0 ? 0.0 : c[size - 1]; }
  /// A double near the value (the rounded sum of the components).
  double estimate() const {
    double s = 0.0;
    for (int i = 0; i < size; ++i) s += c[i];
    return s;
  }
};

inline Expansion<1> exact(double a) {
  Expansion<1> e;
  if (a != 0.0) e.c[e.size++] = a;
  return e;
}

inline Expansion<2> from_two_term(TwoTerm t) {
  Expansion<2> e;
  if (t.tail != 0.0) e.c[e.size++] = t.tail;
  if (t.head != 0.0) e.c[e.size++] = t.head;
  return e;
}

/// a * b as an expansion.
inline Expansion<2> product(double a, double b) { return from_two_term(two_product(a, b)); }

/// Shewchuk's Two_Two_Diff: (a.head + a.tail) - (b.head + b.tail) as four
/// nonoverlapping components, smallest first, some possibly zero; the last
/// approximates the value, as his stage-C error bounds assume.
struct FourTerm {
  double c[4];
};

inline FourTerm two_two_diff(TwoTerm a, TwoTerm b) {
  const TwoTerm low = two_diff(a.tail, b.tail);
  const TwoTerm mid = two_sum(a.head, low.head);  // a - b.tail = mid + low.tail
  const TwoTerm low2 = two_diff(mid.tail, b.head);
  const TwoTerm high = two_sum(mid.head, low2.head);
  return {{low.tail, low2.tail, high.tail, high.head}};
}

inline Expansion<4> from_four_term(const FourTerm& t) {
  Expansion<4> e;
  for (const double x : t.c)
    if (x != 0.0) e.c[e.size++] = x;
  return e;
}

namespace detail {

// Shewchuk's FAST-EXPANSION-SUM-ZEROELIM: merge e and f (f scaled by
// f_sign = +-1, which is exact) by magnitude, then accumulate with two_sum.
// Two_sum instead of the first fast_two_sum: same result, no precondition.
inline int sum(const double* e, int ne, const double* f, int nf, double f_sign, double* h) {
  int i = 0, j = 0, n = 0;
  double q;
  if (ne == 0 && nf == 0) return 0;
  if (j == nf || (i < ne && std::abs(e[i]) < std::abs(f[j]))) {
    q = e[i++];
  } else {
    q = f_sign * f[j++];
  }
  const auto add = [&](double x) {
    const TwoTerm t = two_sum(q, x);
    if (t.tail != 0.0) h[n++] = t.tail;
    q = t.head;
  };
  while (i < ne && j < nf) {
    const double x = e[i], y = f_sign * f[j];
    if (std::abs(x) < std::abs(y)) {
      add(x);
      ++i;
    } else {
      add(y);
      ++j;
    }
  }
  for (; i < ne; ++i) add(e[i]);
  for (; j < nf; ++j) add(f_sign * f[j]);
  if (q != 0.0) h[n++] = q;
  return n;
}

// Shewchuk's SCALE-EXPANSION-ZEROELIM: e * b.
inline int scale(const double* e, int ne, double b, double* h) {
  if (ne == 0 || b == 0.0) return 0;
#ifdef __FMA__
  const auto times_b = [b](double a) { return two_product(a, b); };
#else
  const auto times_b = [b, bs = split(b)](double a) { return two_product_presplit(a, b, bs); };
#endif
  int n = 0;
  TwoTerm p = times_b(e[0]);
  if (p.tail != 0.0) h[n++] = p.tail;
  double q = p.head;
  for (int i = 1; i < ne; ++i) {
    p = times_b(e[i]);
    const TwoTerm s = two_sum(q, p.tail);
    if (s.tail != 0.0) h[n++] = s.tail;
    const TwoTerm r = fast_two_sum(p.head, s.head);
    if (r.tail != 0.0) h[n++] = r.tail;
    q = r.head;
  }
  if (q != 0.0) h[n++] = q;
  return n;
}

}  // namespace detail

template <int N, int M>
Expansion<N + M> operator+(const Expansion<N>& e, const Expansion<M>& f) {
  Expansion<N + M> h;
  h.size = detail::sum(e.c, e.size, f.c, f.size, 1.0, h.c);
  return h;
}

template <int N, int M>
Expansion<N + M> operator-(const Expansion<N>& e, const Expansion<M>& f) {
  Expansion<N + M> h;
  h.size = detail::sum(e.c, e.size, f.c, f.size, -1.0, h.c);
  return h;
}

template <int N>
Expansion<2 * N> operator*(const Expansion<N>& e, double b) {
  Expansion<2 * N> h;
  h.size = detail::scale(e.c, e.size, b, h.c);
  return h;
}

/// e * f: e scaled by each component of f, summed.
template <int N, int M>
Expansion<2 * N * M> operator*(const Expansion<N>& e, const Expansion<M>& f) {
  Expansion<2 * N * M> h, other;
  Expansion<2 * N * M>* sum = &h;
  Expansion<2 * N * M>* next = &other;
  double part[2 * N];
  for (int j = 0; j < f.size; ++j) {
    const int n = detail::scale(e.c, e.size, f.c[j], part);
    next->size = detail::sum(sum->c, sum->size, part, n, 1.0, next->c);
    std::swap(sum, next);
  }
  if (sum != &h) {
    std::copy_n(other.c, other.size, h.c);
    h.size = other.size;
  }
  return h;
}

}  // namespace geods::exact
