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

// An expansion is a nonoverlapping sequence of doubles whose exact sum is the value, smallest
// magnitude first, in an array the caller sizes for the most terms it can have (each function says
// how many), with its length beside it: no copies of unused room (an exact sign costs tens of
// operations where its terms are few, as they are where the coordinates' differences are exact).

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

/// The exact difference a - b in h (room for 2 terms); returns its length.
int diff(double a, double b, double* h) {
  double x, y;
  two_diff(a, b, x, y);
  int n = 0;
  if (y != 0.0) h[n++] = y;
  if (x != 0.0) h[n++] = x;
  return n;
}

/// h = h + b in place (Shewchuk's grow-expansion with zero elimination; room for n + 1 terms):
/// returns the new length.
int grow(double* h, int n, double b) {
  double q = b;
  int k = 0;
  for (int i = 0; i < n; ++i) {
    double sum, err;
    two_sum(q, h[i], sum, err);
    q = sum;
    if (err != 0.0) h[k++] = err;
  }
  if (q != 0.0 || k == 0) h[k++] = q;
  return k;
}

/// h = h + f in place, by growing h with each component of f (room for n + fn terms): returns
/// the new length.
int grow_by(double* h, int n, const double* f, int fn) {
  for (int i = 0; i < fn; ++i) n = grow(h, n, f[i]);
  return n;
}

/// h = e + f (room for en + fn terms): returns h's length.
int add(const double* e, int en, const double* f, int fn, double* h) {
  for (int i = 0; i < en; ++i) h[i] = e[i];
  return grow_by(h, en, f, fn);
}

/// e negated, in place.
void negate(double* e, int n) {
  for (int i = 0; i < n; ++i) e[i] = -e[i];
}

/// h = e * b (Shewchuk's scale-expansion with zero elimination; room for 2 en terms): returns
/// h's length.
int scale(const double* e, int en, double b, double* h) {
  int n = 0;
  if (en == 0 || b == 0.0) return 0;
  double q, hh;
  two_product(e[0], b, q, hh);
  if (hh != 0.0) h[n++] = hh;
  for (int i = 1; i < en; ++i) {
    double p1, p0, sum;
    two_product(e[i], b, p1, p0);
    two_sum(q, p0, sum, hh);
    if (hh != 0.0) h[n++] = hh;
    two_sum(p1, sum, q, hh);  // p1 and sum do not overlap badly: fast-two-sum would do, two-sum is safe
    if (hh != 0.0) h[n++] = hh;
  }
  if (q != 0.0 || n == 0) h[n++] = q;
  return n;
}

/// h = e * f, the sum of e scaled by each component of f (room for 2 en fn terms; kMostE bounds
/// en): returns h's length.
template <int kMostE>
int multiply(const double* e, int en, const double* f, int fn, double* h) {
  double term[2 * kMostE];
  int n = 0;
  for (int i = 0; i < fn; ++i) {
    const int tn = scale(e, en, f[i], term);
    n = grow_by(h, n, term, tn);
  }
  return n;
}

int sign(const double* e, int n) {
  for (int i = n - 1; i >= 0; --i) {
    if (e[i] > 0.0) return 1;
    if (e[i] < 0.0) return -1;
  }
  return 0;
}

/// a d - b c for expansions of at most two terms each (room for 16 terms): returns its length.
int cross(const double* a, int an, const double* d, int dn, const double* b, int bn, const double* c, int cn, double* h) {
  double ad[8], bc[8];
  const int adn = multiply<2>(a, an, d, dn, ad);
  const int bcn = multiply<2>(b, bn, c, cn, bc);
  negate(bc, bcn);
  return add(ad, adn, bc, bcn, h);
}

/// Whether the three 2-D points share a coordinate, or two of them coincide: their determinant has
/// a zero row or column, so it is 0 exactly (most exact zeros of meshes on a grid; the expansions'
/// answer, at once).
bool degenerate2d(const double* a, const double* b, const double* c) {
  for (int i = 0; i < 2; ++i) {
    if (a[i] == c[i] && b[i] == c[i]) return true;
  }
  return (a[0] == c[0] && a[1] == c[1]) || (b[0] == c[0] && b[1] == c[1]);
}

/// orient3d's degenerate2d: the four points share a coordinate, or one of a, b, c is d.
bool degenerate3d(const double* a, const double* b, const double* c, const double* d) {
  for (int i = 0; i < 3; ++i) {
    if (a[i] == d[i] && b[i] == d[i] && c[i] == d[i]) return true;
  }
  const auto same = [d](const double* p) { return p[0] == d[0] && p[1] == d[1] && p[2] == d[2]; };
  return same(a) || same(b) || same(c);
}

}  // namespace

namespace detail {

// The exact forms are kept out of line: the filters that call them stay small.
[[gnu::noinline]] int orient2d_exact(const double* a, const double* b, const double* c) {
  if (degenerate2d(a, b, c)) return 0;
  double acx[2], acy[2], bcx[2], bcy[2], det[16];
  const int acxn = diff(a[0], c[0], acx), acyn = diff(a[1], c[1], acy);
  const int bcxn = diff(b[0], c[0], bcx), bcyn = diff(b[1], c[1], bcy);
  return sign(det, cross(acx, acxn, bcy, bcyn, acy, acyn, bcx, bcxn, det));
}

[[gnu::noinline]] int orient3d_exact(const double* a, const double* b, const double* c, const double* d) {
  if (degenerate3d(a, b, c, d)) return 0;
  double ad[3][2], bd[3][2], cd[3][2];
  int adn[3], bdn[3], cdn[3];
  for (int i = 0; i < 3; ++i) {
    adn[i] = diff(a[i], d[i], ad[i]);
    bdn[i] = diff(b[i], d[i], bd[i]);
    cdn[i] = diff(c[i], d[i], cd[i]);
  }
  double m1[16], m2[16], m3[16];
  const int m1n = cross(bd[0], bdn[0], cd[1], cdn[1], cd[0], cdn[0], bd[1], bdn[1], m1);
  const int m2n = cross(cd[0], cdn[0], ad[1], adn[1], ad[0], adn[0], cd[1], cdn[1], m2);
  const int m3n = cross(ad[0], adn[0], bd[1], bdn[1], bd[0], bdn[0], ad[1], adn[1], m3);
  double t1[64], t2[64], t3[64], t12[128], det[192];
  const int t1n = multiply<2>(ad[2], adn[2], m1, m1n, t1);
  const int t2n = multiply<2>(bd[2], bdn[2], m2, m2n, t2);
  const int t3n = multiply<2>(cd[2], cdn[2], m3, m3n, t3);
  const int t12n = add(t1, t1n, t2, t2n, t12);
  return sign(det, add(t12, t12n, t3, t3n, det));
}

}  // namespace detail

int orient2d(const double* a, const double* b, const double* c) {
  const double detleft = (a[0] - c[0]) * (b[1] - c[1]);
  const double detright = (a[1] - c[1]) * (b[0] - c[0]);
  const double det = detleft - detright;
  const double errbound = kCcwErrBound * (std::fabs(detleft) + std::fabs(detright));
  if (det > errbound) return 1;
  if (-det > errbound) return -1;
  return detail::orient2d_exact(a, b, c);
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
  return detail::orient3d_exact(a, b, c, d);
}

}  // namespace caliber::geometry
