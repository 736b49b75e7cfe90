#pragma once
/// \file
/// Exact geometric predicates on double coordinates: a floating-point filter, then exact expansion
/// arithmetic (Shewchuk's error-free transformations) when the filter cannot decide the sign.
/// The sign returned is the sign of the exact determinant of the given doubles, provided no
/// intermediate product, or its rounding error, underflows or overflows: coordinates, and
/// differences of coordinates, either zero or between about 1e-80 and 1e100 in magnitude (a product
/// of three differences, or of their rounding errors, must stay a normal double: three
/// differences of 1e-120 give 0).

namespace caliber::geometry {

/// Sign (-1, 0, +1) of det[a-d; b-d; c-d]: +1 when d lies below the plane through a, b, c
/// oriented so that a, b, c appear counter-clockwise from above.
int orient3d(const double* a, const double* b, const double* c, const double* d);

/// Sign (-1, 0, +1) of det[a-c; b-c] on 2-D points: +1 when a, b, c turn counter-clockwise.
int orient2d(const double* a, const double* b, const double* c);

namespace detail {
/// The exact forms alone (expansion arithmetic, no filter), which orient3d and orient2d call
/// where their filters cannot decide: the same contract.
int orient3d_exact(const double* a, const double* b, const double* c, const double* d);
int orient2d_exact(const double* a, const double* b, const double* c);
}  // namespace detail

}  // namespace caliber::geometry
