#pragma once
/// \file
/// The invariants of a plan, checked in one pass (after Box2D's b2Validate functions): the debug
/// and sanitizer builds check every plan the engine makes (CALIBER_ASSERT), and tests call the
/// check on plans broken on purpose.

#include <cstddef>
#include <string>

#include "plans/plan.h"

namespace caliber::plans {

/// The first broken invariant of `plan` over `pairs` object pairs, in words (empty when none):
/// a weight-driven stage for each split pair, those pairs distinct and in range; every run-time
/// task has roots, a finite weight that is not negative (their sum, in a weighted plan) and roots
/// of pairs in range; a root's taboo list, its place on a list and its stage record exist and name
/// it; every pair that was not split has exactly one root at its CD tree's root, and every split
/// pair none there.
[[nodiscard]] std::string plan_problem(const Plan& plan, std::size_t pairs);

}  // namespace caliber::plans
