#pragma once
/// \file
/// The distance bound (PairContext::gap, before groups) of a visit's four child pairs at once, in
/// AVX2. Each tier is computed in every lane, with the scalar bound's operations in its order,
/// and the next tier is skipped only once every lane is beyond the reach; so a lane gives the
/// scalar's value, bit for bit, wherever that is within the reach the scalar was given, and beyond
/// it both are some value beyond the reach (the scalar stops at the first tier that proves it).
/// Tested against the scalar bound.

#include "narrow/prepared.h"

namespace caliber::narrow::detail {

/// The constants the bound's allowances use (PairContext's).
struct BoundConstants {
  double hair;          ///< added to |axis . axis| products (rounding in rotated axes)
  double apart_shrink;  ///< factor on frames_apart's separation
};

/// out[2i + j] = the bound between ai and bj, before groups (beyond `reach` where that is).
using Gaps2x2 = void (*)(const BoundConstants& constants, const NearA& a0, const NearA& a1, const NearB& b0, const NearB& b1,
                         double reach, double out[4]);

/// The AVX2 form, or (wide_registers) the same form built for AVX-512VL too (32 vector
/// registers; the same values); nullptr where this build or this CPU has none.
Gaps2x2 gaps_2x2_form(bool wide_registers);

}  // namespace caliber::narrow::detail
