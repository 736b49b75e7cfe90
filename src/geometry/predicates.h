#pragma once
/// \file
/// Exact geometric predicates on double coordinates: a floating-point filter, then exact expansion
/// arithmetic (Shewchuk's error-free transformations) when the filter cannot decide the sign.
/// The sign returned is the sign of the exact determinant of the given doubles, provided no
/// intermediate product underflows (coordinates, and differences of coordinates, either zero or
/// above about 1e-140 in magnitude) or overflows (below about 1e100): far beyond any mesh's range.

namespace caliber::geometry {

/// Sign (-1, 0, +1) of det[a-d; b-d; c-d]: +1 when d lies below the plane through a, b, c
/// oriented so that a, b, c appear counter-clockwise from above.
int orient3d(const double* a, const double* b, const double* c, const double* d);

/// Sign (-1, 0, +1) of det[a-c; b-c] on 2-D points: +1 when a, b, c turn counter-clockwise.
int orient2d(const double* a, const double* b, const double* c);

}  // namespace caliber::geometry
