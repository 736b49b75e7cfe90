#pragma once
/// \file
/// The contact query's reduction of a pair's candidates to their local minima.

#include <algorithm>
#include <cstddef>
#include <vector>

#include "narrow/candidate.h"
#include "narrow/nearby_look.h"
#include "narrow/pair_context.h"
#include "util/assert.h"

namespace caliber::narrow {

/// The reduction's look at each candidate's neighbours in the list (detail::NearbyLook): the
/// AVX-512 form where this CPU has it, else the AVX2 form, else null (the portable form), chosen
/// when the library loads.
extern const detail::NearbyLook kNearbyLook;

/// A pair's candidates in the lists they were gathered in (a stage's, the workers'), read as their
/// concatenation in order: what a reduction reads where they are, not copied into one list first.
class CandidateLists {
 public:
  /// Appends `list` (kept by the caller, unchanged while this is read).
  void add(const std::vector<Candidate>& list) {
    if (list.empty()) return;
    mLists.push_back(&list);
    mEnd.push_back(size() + list.size());
  }
  [[nodiscard]] std::size_t size() const { return mEnd.empty() ? 0 : mEnd.back(); }
  /// Candidate g of the concatenation.
  [[nodiscard]] const Candidate& operator[](std::size_t g) const {
    const std::size_t k = list_of(g);
    return (*mLists[k])[g - begin_of(k)];
  }

  /// Reads the concatenation by position with no search while the positions stay in one list (a
  /// run read in order searches once a list).
  class Reader {
   public:
    explicit Reader(const CandidateLists& lists) : mLists(lists) {}
    const Candidate& operator()(std::size_t g) {
      if (g - mBegin >= mCount) {  // (also below mBegin: the difference wraps)
        const std::size_t k = mLists.list_of(g);
        mBegin = mLists.begin_of(k);
        mCount = mLists.mLists[k]->size();
        mData = mLists.mLists[k]->data();
      }
      return mData[g - mBegin];
    }

   private:
    const CandidateLists& mLists;
    const Candidate* mData = nullptr;
    std::size_t mBegin = 0, mCount = 0;
  };

 private:
  [[nodiscard]] std::size_t list_of(std::size_t g) const {
    CALIBER_ASSERT(g < size(), "a position in the lists");
    return static_cast<std::size_t>(std::upper_bound(mEnd.begin(), mEnd.end(), g) - mEnd.begin());
  }
  [[nodiscard]] std::size_t begin_of(std::size_t k) const { return k == 0 ? 0 : mEnd[k - 1]; }

  std::vector<const std::vector<Candidate>*> mLists;
  std::vector<std::size_t> mEnd;  ///< where each list ends in the concatenation
};

/// Quasi-LMD reduction: keeps a candidate unless a candidate that shares one of its triangles and
/// whose other triangle is vertex-adjacent to its own (ModelData::are_neighbours) is closer
/// (`closer`: ties to the lower ids). Each verdict depends only on the set of candidates, not on
/// their order, so they need no sorting first; the kept ones are returned in the input's order.
/// Linear in the candidates times the adjacency's degree, that degree taken at most 32 a vertex
/// (a vertex with more corners at it answers for its candidates by their closest); in
/// chunks of `grain` (0 read as 1) on the current executor (a grain as large as the input keeps it
/// on this thread). Both models need adjacency.
std::vector<Candidate> local_minima(const PairContext& ctx, const std::vector<Candidate>& candidates, std::size_t grain);
/// The same on the concatenation of `lists`.
std::vector<Candidate> local_minima(const PairContext& ctx, const CandidateLists& lists, std::size_t grain);

}  // namespace caliber::narrow
