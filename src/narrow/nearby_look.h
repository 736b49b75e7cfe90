#pragma once
/// \file
/// The contact reduction's first look (local_minima.cpp): whether one of the candidates next to a
/// candidate in the list dominates it, for every candidate, in lanes where the CPU has AVX-512 or
/// AVX2. The traversals list nearby pairs together, so that look settles most candidates (88 % of
/// two_small's, 93-94 % of funnel's and front_car's) before the lookups of their neighbours' pairs,
/// and with no branch on each neighbour (the scalar look's were mispredicted about half the time).

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>

namespace caliber::narrow::detail {

/// One candidate as the look reads it: its triangles, its distance and each triangle's welded
/// corners.
struct NearbyCandidate {
  std::uint32_t ta, tb;
  double distance;
  const std::uint32_t* corners_a;
  const std::uint32_t* corners_b;
};

/// A run of a pair's candidates as the look reads them, a column per field, each with kPad places
/// before the run's first candidate and after its last: the list's candidates there, or where the
/// list ends, pads that dominate none (distance +inf, every id all ones). The run's candidate i is
/// at place i + kPad of every column.
class NearbyColumns {
 public:
  /// The look reads the candidates from kPad places before a candidate to kPad - 1 after it.
  static constexpr std::size_t kPad = 8;
  /// Columns of a u32 field: the triangles of A and B, the welded corners of each.
  enum Field { kTriA, kTriB, kCornerA0, kCornerA1, kCornerA2, kCornerB0, kCornerB1, kCornerB2, kFields };

  /// Room for runs of up to `capacity` candidates; a run of that many, padded on both sides, its
  /// places left to set.
  explicit NearbyColumns(std::size_t capacity)
      : mCount(capacity),
        mStride(capacity + 2 * kPad),
        mDistance(new double[mStride]),
        mKey(new std::uint64_t[mStride]),
        mIds(new std::uint32_t[mStride * kFields]) {
    for (std::size_t p = 0; p != kPad; ++p) {
      pad(p);
      pad(capacity + kPad + p);
    }
  }
  /// Candidate i of the run (-kPad <= i < size() + kPad: the places around it too).
  void set(std::ptrdiff_t i, const NearbyCandidate& c) {
    const auto p = static_cast<std::size_t>(i + static_cast<std::ptrdiff_t>(kPad));
    mDistance[p] = c.distance;
    mKey[p] = (std::uint64_t{c.ta} << 32) | c.tb;
    mIds[kTriA * mStride + p] = c.ta;
    mIds[kTriB * mStride + p] = c.tb;
    for (int k = 0; k < 3; ++k) {
      mIds[(kCornerA0 + k) * mStride + p] = c.corners_a[k];
      mIds[(kCornerB0 + k) * mStride + p] = c.corners_b[k];
    }
  }
  /// The run of candidates first .. first + count - 1 (count at most the capacity) of a list of
  /// `total`, with the list's kPad on each side: get(g) gives candidate g (a NearbyCandidate).
  template <class Get>
  void load(std::size_t first, std::size_t count, std::size_t total, Get&& get) {
    mCount = count;
    for (std::size_t p = 0; p != count + 2 * kPad; ++p) {
      const std::size_t g = first + p - kPad;  // (wraps past the list's start: then >= total)
      if (first + p >= kPad && g < total) {
        set(static_cast<std::ptrdiff_t>(p) - static_cast<std::ptrdiff_t>(kPad), get(g));
      } else {
        pad(p);
      }
    }
  }
  [[nodiscard]] std::size_t size() const { return mCount; }
  /// The columns from place 0 (candidate i at i + kPad).
  [[nodiscard]] const double* distance() const { return mDistance.get(); }
  [[nodiscard]] const std::uint64_t* key() const { return mKey.get(); }
  [[nodiscard]] const std::uint32_t* ids(Field f) const { return mIds.get() + f * mStride; }

 private:
  void pad(std::size_t p) {
    mDistance[p] = std::numeric_limits<double>::infinity();
    mKey[p] = ~std::uint64_t{0};
    for (std::size_t f = 0; f != kFields; ++f) mIds[f * mStride + p] = ~std::uint32_t{0};
  }

  std::size_t mCount, mStride;
  // (Not value-initialized: every place is set, by set, load or the pads.)
  std::unique_ptr<double[]> mDistance;
  std::unique_ptr<std::uint64_t[]> mKey;
  std::unique_ptr<std::uint32_t[]> mIds;
};

/// Whether the candidate at place o dominates the one at place p (places of the columns): it is
/// closer (distance, then key: local_minima's order) and shares one triangle, its other triangle
/// distinct from the candidate's and sharing a welded vertex with it (ModelData::are_neighbours).
inline bool nearby_dominates(const NearbyColumns& c, std::size_t o, std::size_t p) {
  const double* d = c.distance();
  const std::uint64_t* key = c.key();
  const bool closer = d[o] != d[p] ? d[o] < d[p] : key[o] < key[p];
  const auto adjacent = [&](NearbyColumns::Field tri, NearbyColumns::Field first_corner) {
    if (c.ids(tri)[o] == c.ids(tri)[p]) return false;
    bool shared = false;
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < 3; ++j) {
        const auto fk = static_cast<NearbyColumns::Field>(first_corner + k);
        const auto fj = static_cast<NearbyColumns::Field>(first_corner + j);
        shared |= c.ids(fk)[o] == c.ids(fj)[p];
      }
    }
    return shared;
  };
  using F = NearbyColumns;
  return closer && ((c.ids(F::kTriB)[o] == c.ids(F::kTriB)[p] && adjacent(F::kTriA, F::kCornerA0)) ||
                    (c.ids(F::kTriA)[o] == c.ids(F::kTriA)[p] && adjacent(F::kTriB, F::kCornerB0)));
}

/// For each candidate i in [lo, hi): dominated[i] = 1 where one of the candidates in the list from
/// kPad places before it to kPad - 1 after it dominates it (nearby_dominates; none dominates
/// itself), else 0. Sixteen places: one window of AVX-512's lanes, two of AVX2's.
using NearbyLook = void (*)(const NearbyColumns& c, std::size_t lo, std::size_t hi, char* dominated);

/// The portable form.
inline void nearby_look_portable(const NearbyColumns& c, std::size_t lo, std::size_t hi, char* dominated) {
  for (std::size_t i = lo; i < hi; ++i) {
    const std::size_t p = i + NearbyColumns::kPad;
    bool found = false;
    // Nearest first: the first found settles it.
    for (std::size_t d = 1; d <= NearbyColumns::kPad && !found; ++d) {
      found = nearby_dominates(c, p - d, p) || (d < NearbyColumns::kPad && nearby_dominates(c, p + d, p));
    }
    dominated[i] = found ? 1 : 0;
  }
}

/// The form in `lanes` lanes: 16, built for AVX-512F; 8, for AVX2 (the same verdicts as the
/// portable form, no branch on them); nullptr where the CPU (or this build) lacks what it needs.
NearbyLook nearby_look_form(int lanes);

}  // namespace caliber::narrow::detail
