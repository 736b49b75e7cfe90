#pragma once
/// \file
/// A 4-ary min-heap of (key, value) entries: what the distance traversal keeps its waiting nodes
/// in. Against std::push_heap / std::pop_heap (binary, a compare per level whose branch goes either
/// way) it has half the levels, reads one group of four children a level (one cache line of
/// 16-byte entries when aligned) and takes their smallest with conditional moves; popping moves
/// the hole down to a leaf along the smallest children before placing the last entry (no compare
/// against it on the way down).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace caliber::util {

template <class Value>
class MinHeap4 {
 public:
  struct Entry {
    double key;
    Value value;
  };

  [[nodiscard]] bool empty() const { return mSize == 0; }
  [[nodiscard]] std::size_t size() const { return mSize; }
  /// The entry with the smallest key (the heap must not be empty).
  [[nodiscard]] const Entry& top() const { return mData[kRoot]; }
  /// Forgets every entry (keeps the memory).
  void clear() { mSize = 0; }

  void push(double key, Value value) {
    if (kRoot + mSize == mData.size()) mData.resize(std::max<std::size_t>(64, 2 * mData.size()));
    std::size_t hole = kRoot + mSize++;
    while (hole > kRoot) {
      const std::size_t parent = parent_of(hole);
      if (!(key < mData[parent].key)) break;
      mData[hole] = mData[parent];
      hole = parent;
    }
    mData[hole] = Entry{key, value};
  }

  /// Removes the entry with the smallest key and returns it (the heap must not be empty).
  Entry pop() {
    const Entry out = mData[kRoot];
    const Entry last = mData[kRoot + --mSize];
    if (mSize == 0) return out;
    const std::size_t end = kRoot + mSize;
    std::size_t hole = kRoot;
    // Down to a leaf along the smallest child.
    for (;;) {
      const std::size_t first = first_child(hole);
      if (first >= end) break;
      std::size_t best = first;
      if (first + 4 <= end) {
        // Smallest of four without branches: two pairs, then their winners.
        const std::size_t m01 = mData[first + 1].key < mData[first].key ? first + 1 : first;
        const std::size_t m23 = mData[first + 3].key < mData[first + 2].key ? first + 3 : first + 2;
        best = mData[m23].key < mData[m01].key ? m23 : m01;
      } else {
        for (std::size_t c = first + 1; c < end; ++c) best = mData[c].key < mData[best].key ? c : best;
      }
      mData[hole] = mData[best];
      hole = best;
    }
    // Then up, as a push would, to where `last` belongs.
    while (hole > kRoot) {
      const std::size_t parent = parent_of(hole);
      if (!(last.key < mData[parent].key)) break;
      mData[hole] = mData[parent];
      hole = parent;
    }
    mData[hole] = last;
    return out;
  }

 private:
  // The root sits at index 3, so that the four children of slot i, 4i - 8 .. 4i - 5, start at a
  // multiple of four: one 64-byte line of 16-byte entries where the vector is 64-byte aligned.
  static constexpr std::size_t kRoot = 3;
  static std::size_t first_child(std::size_t i) { return 4 * i - 8; }
  static std::size_t parent_of(std::size_t i) { return (i + 8) / 4; }

  std::vector<Entry> mData = std::vector<Entry>(64);
  std::size_t mSize = 0;
};

}  // namespace caliber::util
