#pragma once
/// \file
/// A priority queue of (key, value) entries with nonnegative double keys, by buckets: what the
/// distance traversal keeps its waiting nodes in. A key's bucket is the top 20 bits of its IEEE
/// representation (sign, exponent and 8 bits of mantissa), which orders nonnegative doubles, so a
/// bucket holds keys within a factor 1 + 1/256 of each other. pop() takes an entry of the lowest
/// nonempty bucket (the last one pushed there), found through a bitmap of nonempty buckets in
/// three levels and a few top words: pushing and popping cost a few instructions whatever the
/// number waiting, where a heap pays a compare per level (a branch either way, and a cache line)
/// on every pop. Entries come out nearest bucket first, in no particular order within a bucket; a
/// user that needs the exact order must not rely on it (the distance traversal prunes each popped
/// node against the best distance found so far, so any order gives the same answer). Buckets of a
/// sixteenth (16 bits) were too coarse on pairs far apart: turbine x blade took many more node
/// tests.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstddef>
#include <cstring>
#include <iterator>
#include <memory>
#include <vector>

namespace caliber::util {

template <class Value>
class GapBuckets {
 public:
  struct Entry {
    double key;
    Value value;
  };

  GapBuckets() = default;

  /// The bucket of a key: by its representation where it is >= +0 (or +infinity); a key with
  /// the sign bit set (-0, or a negative lower bound) goes to bucket 0, the nearest, not past
  /// every positive one.
  static std::uint32_t bucket_of(double key) {
    std::uint64_t bits;
    std::memcpy(&bits, &key, sizeof bits);
    return (bits >> 63) != 0 ? 0u : static_cast<std::uint32_t>(bits >> (64 - kBits));
  }
  /// The smallest nonnegative key bucket b holds (bucket 0 also holds the keys with the sign bit
  /// set, all below its floor 0: a lower bound, so they come out no later than they should).
  static double floor_of(std::uint32_t b) {
    const std::uint64_t bits = std::uint64_t{b} << (64 - kBits);
    double key;
    std::memcpy(&key, &bits, sizeof key);
    return key;
  }

  [[nodiscard]] bool empty() const { return mCount == 0; }
  /// The lowest nonempty bucket (the queue must not be empty): kept up to date by push and pop,
  /// so asking costs a load (the distance traversal asks up to three times a visit).
  [[nodiscard]] std::uint32_t min_bucket() const { return mMin; }

 private:
  /// The lowest nonempty bucket, found through the bitmaps (the queue must not be empty).
  [[nodiscard]] std::uint32_t scan_min_bucket() const {
    std::uint32_t i2 = 0;
    while (mTop[i2] == 0) ++i2;
    const auto i1 = i2 * 64 + static_cast<std::uint32_t>(std::countr_zero(mTop[i2]));
    const auto i0 = i1 * 64 + static_cast<std::uint32_t>(std::countr_zero(mMiddle[i1]));
    return i0 * 64 + static_cast<std::uint32_t>(std::countr_zero(mBottom[i0]));
  }

 public:
  /// Bytes held by the entries' store (the largest number pushed between two clears).
  [[nodiscard]] std::size_t footprint() const { return mPool.capacity() * sizeof(Node); }

  /// Forgets every entry (keeps the memory): the bitmaps' nonzero words zeroed through the levels
  /// above them, a word at a time (not a bucket at a time: a distance traversal leaves hundreds
  /// of entries waiting, and emptying them bucket by bucket took a noticeable part of its time).
  void clear() {
    for (std::size_t t = 0; t < std::size(mTop); ++t) {
      for (std::uint64_t top = mTop[t]; top != 0; top &= top - 1) {
        const std::size_t m = t * 64 + static_cast<std::size_t>(std::countr_zero(top));
        for (std::uint64_t middle = mMiddle[m]; middle != 0; middle &= middle - 1) {
          mBottom[m * 64 + static_cast<std::size_t>(std::countr_zero(middle))] = 0;
        }
        mMiddle[m] = 0;
      }
      mTop[t] = 0;
    }
    mCount = 0;
    mMin = kBuckets;
    mPool.clear();
  }

  void push(double key, Value value) {
    if (!mHeads) allocate();
    const std::uint32_t b = bucket_of(key);
    const bool fresh = ((mBottom[b / 64] >> (b % 64)) & 1) == 0;
    mPool.push_back(Node{Entry{key, value}, fresh ? kNone : mHeads[b]});
    if (fresh) mark(b);
    mMin = std::min(mMin, b);
    mHeads[b] = static_cast<std::uint32_t>(mPool.size() - 1);
  }

  /// Removes an entry of the lowest nonempty bucket and returns it (the queue must not be empty).
  Entry pop() {
    const std::uint32_t b = mMin;
    const Node& node = mPool[mHeads[b]];
    mHeads[b] = node.next;
    if (node.next == kNone) {
      unmark(b);
      mMin = empty() ? kBuckets : scan_min_bucket();
    }
    return node.entry;
  }

 private:
  static constexpr int kBits = 20;
  static constexpr std::uint32_t kBuckets = 1u << kBits;
  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  struct Node {
    Entry entry;
    std::uint32_t next;  ///< the entry pushed before it into its bucket, or kNone
  };

  /// The buckets' tables, at the first push (a traversal that never queues anything, and the
  /// scratch of every other kind of query, never pays for them): 4 MiB of heads never touched
  /// until used, 130 KiB of bitmaps.
  void allocate() {
    mHeads = std::make_unique_for_overwrite<std::uint32_t[]>(kBuckets);
    mBottom.assign(kBuckets / 64, 0);
    mMiddle.assign(kBuckets / 4096, 0);
  }
  void mark(std::uint32_t b) {
    ++mCount;
    mBottom[b / 64] |= std::uint64_t{1} << (b % 64);
    mMiddle[b / 4096] |= std::uint64_t{1} << ((b / 64) % 64);
    mTop[b / 262144] |= std::uint64_t{1} << ((b / 4096) % 64);
  }
  void unmark(std::uint32_t b) {
    --mCount;
    if ((mBottom[b / 64] &= ~(std::uint64_t{1} << (b % 64))) != 0) return;
    if ((mMiddle[b / 4096] &= ~(std::uint64_t{1} << ((b / 64) % 64))) != 0) return;
    mTop[b / 262144] &= ~(std::uint64_t{1} << ((b / 4096) % 64));
  }

  std::vector<Node> mPool;  ///< every entry pushed since clear(), popped or not
  /// Per nonempty bucket: its last entry in mPool (never initialized: read only where the bucket's
  /// bit says it was written since it was last emptied).
  std::unique_ptr<std::uint32_t[]> mHeads;
  std::vector<std::uint64_t> mBottom;          ///< bit b: bucket b is nonempty
  std::vector<std::uint64_t> mMiddle;          ///< bit w: word w of mBottom is nonzero
  std::uint64_t mTop[kBuckets / 262144] = {};  ///< bit m: word m of mMiddle is nonzero
  std::uint32_t mCount = 0;                    ///< nonempty buckets
  std::uint32_t mMin = kBuckets;               ///< the lowest nonempty bucket; kBuckets when none
};

}  // namespace caliber::util
