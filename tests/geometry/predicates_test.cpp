#include "geometry/predicates.h"

#include <cmath>
#include <array>
#include <random>

#include <gmp.h>
#include <gtest/gtest.h>

namespace caliber::geometry {
namespace {

using i128 = __int128;

/// Exact orient3d on integer coordinates (|x| < 2^26 keeps every product inside 128 bits).
int orient3d_int(const std::int64_t* a, const std::int64_t* b, const std::int64_t* c, const std::int64_t* d) {
  const i128 adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
  const i128 bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
  const i128 cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
  const i128 det = adz * (bdx * cdy - cdx * bdy) + bdz * (cdx * ady - adx * cdy) + cdz * (adx * bdy - bdx * ady);
  return det > 0 ? 1 : (det < 0 ? -1 : 0);
}

TEST(Predicates, Orient3dBasicSigns) {
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
  const double above[3] = {0, 0, 1}, below[3] = {0, 0, -1}, on[3] = {0.3, 0.3, 0};
  // Shewchuk's convention: positive when d lies below the plane of counter-clockwise a, b, c.
  EXPECT_EQ(orient3d(a, b, c, below), 1);
  EXPECT_EQ(orient3d(a, b, c, above), -1);
  EXPECT_EQ(orient3d(a, b, c, on), 0);
}

TEST(Predicates, Orient2dBasicSigns) {
  const double a[2] = {0, 0}, b[2] = {1, 0}, left[2] = {0.5, 1}, right[2] = {0.5, -1}, on[2] = {3, 0};
  EXPECT_EQ(orient2d(a, b, left), 1);
  EXPECT_EQ(orient2d(a, b, right), -1);
  EXPECT_EQ(orient2d(a, b, on), 0);
}

TEST(Predicates, Orient3dDetectsOneUlpOffThePlane) {
  // The plane x + y + z = 1; the origin is on one side.
  const double p[3] = {1.0, 0.0, 0.0}, q[3] = {0.0, 1.0, 0.0}, r[3] = {0.0, 0.0, 1.0};
  const double origin[3] = {0.0, 0.0, 0.0};
  const int origin_side = orient3d(p, q, r, origin);
  ASSERT_NE(origin_side, 0);
  const double on[3] = {0.5, 0.5, 0.0};
  EXPECT_EQ(orient3d(p, q, r, on), 0);
  // A tiny positive z puts the point strictly beyond the plane (exactness holds while no product
  // underflows: see predicates.h).
  const double beyond[3] = {0.5, 0.5, 1e-200};
  EXPECT_EQ(orient3d(p, q, r, beyond), -origin_side);
  // One ulp less in y puts it strictly on the origin's side.
  const double before[3] = {0.5, std::nextafter(0.5, 0.0), 0.0};
  EXPECT_EQ(orient3d(p, q, r, before), origin_side);
}

TEST(Predicates, Orient3dMatchesIntegerArithmeticOnNearlyCoplanarPoints) {
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<std::int64_t> coord(-(1 << 20), 1 << 20);
  std::uniform_int_distribution<std::int64_t> small(-3, 3);
  std::uniform_int_distribution<int> scale_exp(-40, 40);
  int zeros = 0, nonzeros = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    std::int64_t a[3], b[3], c[3], d[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = coord(rng);
      b[k] = coord(rng);
      c[k] = coord(rng);
    }
    // d = a + (b - a) + (c - a) + tiny perturbation: on or one unit off the plane.
    for (int k = 0; k < 3; ++k) d[k] = b[k] + c[k] - a[k] + (iter % 2 == 0 ? 0 : small(rng));
    const int want = orient3d_int(a, b, c, d);
    // Scale by a power of two: exact in floating point, sign unchanged.
    const double s = std::ldexp(1.0, scale_exp(rng));
    double fa[3], fb[3], fc[3], fd[3];
    for (int k = 0; k < 3; ++k) {
      fa[k] = static_cast<double>(a[k]) * s;
      fb[k] = static_cast<double>(b[k]) * s;
      fc[k] = static_cast<double>(c[k]) * s;
      fd[k] = static_cast<double>(d[k]) * s;
    }
    ASSERT_EQ(orient3d(fa, fb, fc, fd), want) << "iteration " << iter;
    (want == 0 ? zeros : nonzeros)++;
  }
  EXPECT_GT(zeros, 5000);
  EXPECT_GT(nonzeros, 5000);
}

TEST(Predicates, Orient2dMatchesIntegerArithmetic) {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::int64_t> coord(-(1 << 25), 1 << 25);
  std::uniform_int_distribution<std::int64_t> small(-2, 2);
  for (int iter = 0; iter < 20000; ++iter) {
    std::int64_t a[2], b[2], c[2];
    for (int k = 0; k < 2; ++k) {
      a[k] = coord(rng);
      b[k] = coord(rng);
    }
    for (int k = 0; k < 2; ++k) c[k] = 2 * b[k] - a[k] + small(rng);
    const i128 det = static_cast<i128>(a[0] - c[0]) * (b[1] - c[1]) - static_cast<i128>(a[1] - c[1]) * (b[0] - c[0]);
    const int want = det > 0 ? 1 : (det < 0 ? -1 : 0);
    const double fa[2] = {static_cast<double>(a[0]) * 0.125, static_cast<double>(a[1]) * 0.125};
    const double fb[2] = {static_cast<double>(b[0]) * 0.125, static_cast<double>(b[1]) * 0.125};
    const double fc[2] = {static_cast<double>(c[0]) * 0.125, static_cast<double>(c[1]) * 0.125};
    ASSERT_EQ(orient2d(fa, fb, fc), want) << "iteration " << iter;
  }
}

/// A rational of GMP's, freed with its scope.
struct Rational {
  mpq_t q;
  Rational() { mpq_init(q); }
  explicit Rational(double x) {
    mpq_init(q);
    mpq_set_d(q, x);  // exact: every finite double is a rational
  }
  Rational(const Rational&) = delete;
  Rational& operator=(const Rational&) = delete;
  ~Rational() { mpq_clear(q); }
};

/// u - w into out.
void sub(const Rational& u, const Rational& w, Rational& out) { mpq_sub(out.q, u.q, w.q); }

/// The exact sign of det[a-d; b-d; c-d] (three coordinates each), in rationals.
int orient3d_rational(const double* a, const double* b, const double* c, const double* d) {
  Rational m[3][3], t, u, det;
  for (int k = 0; k < 3; ++k) {
    const Rational ak(a[k]), bk(b[k]), ck(c[k]), dk(d[k]);
    sub(ak, dk, m[0][k]);
    sub(bk, dk, m[1][k]);
    sub(ck, dk, m[2][k]);
  }
  // det = sum over the columns j of m[0][j] times its cofactor.
  for (int j = 0; j < 3; ++j) {
    const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
    mpq_mul(t.q, m[1][j1].q, m[2][j2].q);
    mpq_mul(u.q, m[1][j2].q, m[2][j1].q);
    mpq_sub(t.q, t.q, u.q);
    mpq_mul(t.q, t.q, m[0][j].q);
    mpq_add(det.q, det.q, t.q);
  }
  return mpq_sgn(det.q);
}

/// The exact sign of det[a-c; b-c] (two coordinates each), in rationals.
int orient2d_rational(const double* a, const double* b, const double* c) {
  const Rational a0(a[0]), a1(a[1]), b0(b[0]), b1(b[1]), c0(c[0]), c1(c[1]);
  Rational acx, acy, bcx, bcy, l, r;
  sub(a0, c0, acx);
  sub(a1, c1, acy);
  sub(b0, c0, bcx);
  sub(b1, c1, bcy);
  mpq_mul(l.q, acx.q, bcy.q);
  mpq_mul(r.q, acy.q, bcx.q);
  return mpq_cmp(l.q, r.q) > 0 ? 1 : (mpq_cmp(l.q, r.q) < 0 ? -1 : 0);
}

/// Random doubles of magnitudes 2^-40 to 2^40 (some 0), and points within rounding of the plane
/// (or line) through others, so that the differences round and the filter cannot decide: every
/// sign as GMP's rationals give it.
TEST(Predicates, EverySignIsTheRationalOneWhereDifferencesRound) {
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-40, 40);
  const auto coordinate = [&] { return rng() % 16 == 0 ? 0.0 : std::ldexp(unit(rng), exponent(rng)); };
  int signs3[3] = {}, signs2[3] = {};
  for (int iter = 0; iter < 20000; ++iter) {
    double a[3], b[3], c[3], d[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = coordinate();
      b[k] = coordinate();
      c[k] = coordinate();
    }
    // d on the plane through a, b, c, rounded, and sometimes nudged by an ulp in one coordinate.
    const double s = unit(rng), t = unit(rng);
    for (int k = 0; k < 3; ++k) d[k] = a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]);
    if (iter % 3 == 0) d[iter % 9 / 3] = std::nextafter(d[iter % 9 / 3], iter % 2 == 0 ? 1e300 : -1e300);
    const int want3 = orient3d_rational(a, b, c, d);
    ASSERT_EQ(orient3d(a, b, c, d), want3) << "iteration " << iter;
    ++signs3[want3 + 1];
    // c2 on the line through a and b (x, y), rounded.
    const double c2[2] = {a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])};
    const int want2 = orient2d_rational(a, b, c2);
    ASSERT_EQ(orient2d(a, b, c2), want2) << "iteration " << iter;
    ++signs2[want2 + 1];
  }
  // Both signs many times, and some exact zeros.
  EXPECT_GT(signs3[0], 2000);
  EXPECT_GT(signs3[2], 2000);
  EXPECT_GT(signs2[0], 2000);
  EXPECT_GT(signs2[2], 2000);
  EXPECT_GT(signs2[1] + signs3[1], 100);
}

/// Points on a small grid (coordinates -1, 0, 1, 2 times a random scale, some nonzero ones moved
/// by an ulp):
/// shared coordinates, repeated points, collinear and coplanar sets at every turn, where the
/// expansions' shortcuts for a zero row or column apply; every sign as GMP's rationals give it.
TEST(Predicates, EverySignIsTheRationalOneOnAGrid) {
  std::mt19937_64 rng(12);
  std::uniform_int_distribution<int> step(-1, 2);
  std::uniform_real_distribution<double> scale(0.1, 10.0);
  int signs[3] = {};
  for (int iter = 0; iter < 20000; ++iter) {
    const double s = scale(rng);
    double p[4][3];
    for (auto& point : p) {
      for (double& x : point) {
        x = step(rng) * s;
        // (Not a zero: an ulp from 0 is far below the predicates' range, predicates.h.)
        if (x != 0.0 && rng() % 8 == 0) x = std::nextafter(x, rng() % 2 == 0 ? 1e300 : -1e300);
      }
    }
    const int want3 = orient3d_rational(p[0], p[1], p[2], p[3]);
    ASSERT_EQ(orient3d(p[0], p[1], p[2], p[3]), want3) << "iteration " << iter;
    const int want2 = orient2d_rational(p[0], p[1], p[2]);
    ASSERT_EQ(orient2d(p[0], p[1], p[2]), want2) << "iteration " << iter;
    ++signs[want3 + 1];
    ++signs[want2 + 1];
  }
  EXPECT_GT(signs[0], 5000);
  EXPECT_GT(signs[1], 5000);
  EXPECT_GT(signs[2], 5000);
}

/// The exact form on points whose expansions run long (found by a search for the most terms: the
/// cross products take all 16 places, the final sum 118 of its 192): the sign is the rational
/// one, and under the sanitizers' build a place too few is an error. (Its smallest coordinates,
/// about 1e-121, lie below the documented range; the sign is exact all the same.)
TEST(Predicates, LongExpansionsFitTheirPlaces) {
  const double p[4][3] = {{0x1.7045ded9ed89p+216, 0x1.8095efe3686ccp+299, 0x1.9a66e05f2bc39p-401},
                          {0x1.c13ec9e8dbfb6p+312, 0x1.8c5f2b95b773ap+122, -0x1.1915d9ba92e93p-1},
                          {0x1.9a66e05c156b7p-387, -0x1.d20a694bc6332p-238, -0x1.5958f7d100603p+321},
                          {0x1.25eda4b65ad69p-172, 0x1.5b8911a835c8fp+202, 0x1.6b8b6f9069516p+188}};
  const int want = orient3d_rational(p[0], p[1], p[2], p[3]);
  ASSERT_NE(want, 0);
  EXPECT_EQ(detail::orient3d_exact(p[0], p[1], p[2], p[3]), want);
  EXPECT_EQ(detail::orient3d_exact(p[1], p[0], p[2], p[3]), -want);
}

TEST(Predicates, ExactWhereDifferencesAreInexact) {
  // Coordinates whose differences are not representable: 1 and 1e-20 apart (the difference rounds).
  const double a[3] = {1.0, 0.0, 0.0}, b[3] = {0.0, 1.0, 0.0}, c[3] = {0.0, 0.0, 1.0};
  const double d[3] = {1.0 - 1e-20, 1e-20, 0.0};  // rounds to (1, 1e-20, 0): off the plane x+y+z=1 by 1e-20
  EXPECT_EQ(orient3d(a, b, c, d), -orient3d(a, b, c, std::array<double, 3>{0.0, 0.0, 0.0}.data()));
}

}  // namespace
}  // namespace caliber::geometry
