#include "geometry/predicates.h"

#include <cmath>

// The exact fallback uses error-free transformations (two-sum, Dekker's two-product) that are
// only exact when the compiler neither fuses multiply-adds nor reassociates: the library is built
// with -ffp-contract=off and without -ffast-math (see CMakeLists.txt).
#if defined(__FAST_MATH__)
#error "caliber's exact predicates must not be compiled with -ffast-math"
#endif

namespace caliber::geometry {
namespace {

constexpr double kEpsilon = 1.1102230246251565e-16;  // 2^-53, half an ulp of 1
constexpr double kSplitter = 134217729.0;            // 2^27 + 1
constexpr double kO3dErrBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;
constexpr double kCcwErrBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;

/// A nonoverlapping expansion: the exact value is the sum of v[0..n), smallest magnitude first.
struct Expansion {
  static constexpr int kCapacity = 256;
  double v[kCapacity];
  int n = 0;
};

inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

inline void two_diff(double a, double b, double& x, double& y) {
  x = a - b;
  const double bv = a - x;
  const double av = x + bv;
  y = (a - av) + (bv - b);
}

inline void split(double a, double& hi, double& lo) {
  const double c = kSplitter * a;
  const double abig = c - a;
  hi = c - abig;
  lo = a - hi;
}

inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  double ahi, alo, bhi, blo;
  split(a, ahi, alo);
  split(b, bhi, blo);
  const double err1 = x - ahi * bhi;
  const double err2 = err1 - alo * bhi;
  const double err3 = err2 - ahi * blo;
  y = alo * blo - err3;
}

/// The exact difference a - b as an expansion of up to two terms.
Expansion diff(double a, double b) {
  Expansion e;
  double x, y;
  two_diff(a, b, x, y);
  if (y != 0.0) e.v[e.n++] = y;
  if (x != 0.0) e.v[e.n++] = x;
  return e;
}

/// h = e + b (Shewchuk's grow-expansion with zero elimination).
void grow(const Expansion& e, double b, Expansion& h) {
  double q = b;
  h.n = 0;
  for (int i = 0; i < e.n; ++i) {
    double sum, err;
    two_sum(q, e.v[i], sum, err);
    q = sum;
    if (err != 0.0) h.v[h.n++] = err;
  }
  if (q != 0.0 || h.n == 0) h.v[h.n++] = q;
}

/// e + f, by growing e with each component of f.
Expansion add(const Expansion& e, const Expansion& f) {
  Expansion buffers[2];
  const Expansion* current = &e;
  int next = 0;
  for (int i = 0; i < f.n; ++i) {
    grow(*current, f.v[i], buffers[next]);
    current = &buffers[next];
    next ^= 1;
  }
  Expansion result;
  result.n = current->n;
  for (int i = 0; i < current->n; ++i) result.v[i] = current->v[i];
  return result;
}

Expansion negate(Expansion e) {
  for (int i = 0; i < e.n; ++i) e.v[i] = -e.v[i];
  return e;
}

/// h = e * b (Shewchuk's scale-expansion with zero elimination).
void scale(const Expansion& e, double b, Expansion& h) {
  h.n = 0;
  if (e.n == 0 || b == 0.0) return;
  double q, hh;
  two_product(e.v[0], b, q, hh);
  if (hh != 0.0) h.v[h.n++] = hh;
  for (int i = 1; i < e.n; ++i) {
    double p1, p0, sum;
    two_product(e.v[i], b, p1, p0);
    two_sum(q, p0, sum, hh);
    if (hh != 0.0) h.v[h.n++] = hh;
    two_sum(p1, sum, q, hh);  // p1 and sum do not overlap badly: fast-two-sum would do, two-sum is safe
    if (hh != 0.0) h.v[h.n++] = hh;
  }
  if (q != 0.0 || h.n == 0) h.v[h.n++] = q;
}

Expansion multiply(const Expansion& e, const Expansion& f) {
  Expansion result;
  Expansion term;
  for (int i = 0; i < f.n; ++i) {
    scale(e, f.v[i], term);
    result = add(result, term);
  }
  return result;
}

int sign(const Expansion& e) {
  for (int i = e.n - 1; i >= 0; --i) {
    if (e.v[i] > 0.0) return 1;
    if (e.v[i] < 0.0) return -1;
  }
  return 0;
}

int orient2d_exact(const double* a, const double* b, const double* c) {
  const Expansion acx = diff(a[0], c[0]), acy = diff(a[1], c[1]);
  const Expansion bcx = diff(b[0], c[0]), bcy = diff(b[1], c[1]);
  return sign(add(multiply(acx, bcy), negate(multiply(acy, bcx))));
}

int orient3d_exact(const double* a, const double* b, const double* c, const double* d) {
  const Expansion adx = diff(a[0], d[0]), ady = diff(a[1], d[1]), adz = diff(a[2], d[2]);
  const Expansion bdx = diff(b[0], d[0]), bdy = diff(b[1], d[1]), bdz = diff(b[2], d[2]);
  const Expansion cdx = diff(c[0], d[0]), cdy = diff(c[1], d[1]), cdz = diff(c[2], d[2]);
  const Expansion m1 = add(multiply(bdx, cdy), negate(multiply(cdx, bdy)));
  const Expansion m2 = add(multiply(cdx, ady), negate(multiply(adx, cdy)));
  const Expansion m3 = add(multiply(adx, bdy), negate(multiply(bdx, ady)));
  return sign(add(add(multiply(adz, m1), multiply(bdz, m2)), multiply(cdz, m3)));
}

}  // namespace

int orient2d(const double* a, const double* b, const double* c) {
  const double detleft = (a[0] - c[0]) * (b[1] - c[1]);
  const double detright = (a[1] - c[1]) * (b[0] - c[0]);
  const double det = detleft - detright;
  const double errbound = kCcwErrBound * (std::fabs(detleft) + std::fabs(detright));
  if (det > errbound) return 1;
  if (-det > errbound) return -1;
  return orient2d_exact(a, b, c);
}

int orient3d(const double* a, const double* b, const double* c, const double* d) {
  const double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
  const double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
  const double adz = a[2] - d[2], bdz = b[2] - d[2], cdz = c[2] - d[2];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::fabs(bdxcdy) + std::fabs(cdxbdy)) * std::fabs(adz) +
                           (std::fabs(cdxady) + std::fabs(adxcdy)) * std::fabs(bdz) +
                           (std::fabs(adxbdy) + std::fabs(bdxady)) * std::fabs(cdz);
  const double errbound = kO3dErrBound * permanent;
  if (det > errbound) return 1;
  if (-det > errbound) return -1;
  return orient3d_exact(a, b, c, d);
}

}  // namespace caliber::geometry
