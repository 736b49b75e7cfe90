// The BVH build's cut of a node's triangles: a binned surface-area heuristic (partition.h).

#include "bvh/partition.h"

#include <algorithm>
#include <array>
#include <limits>

#include <Eigen/Core>

#include "parallel/executor.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace caliber::bvh {
namespace {

constexpr std::size_t kItemGrain = 4096;
constexpr float kFar = std::numeric_limits<float>::max();

// Four float lanes: SSE2 where the target has it (every x86-64), a plain array elsewhere, with
// the same results (minimum and maximum as SSE's minps and maxps take them).
#if defined(__SSE2__)
using F4 = __m128;
inline F4 load(const float* p) { return _mm_load_ps(p); }
inline void store(float* p, F4 v) { _mm_store_ps(p, v); }
inline F4 splat(float x) { return _mm_set1_ps(x); }
inline F4 lane_min(F4 a, F4 b) { return _mm_min_ps(a, b); }
inline F4 lane_max(F4 a, F4 b) { return _mm_max_ps(a, b); }
inline F4 sub(F4 a, F4 b) { return _mm_sub_ps(a, b); }
inline F4 mul(F4 a, F4 b) { return _mm_mul_ps(a, b); }
inline void truncate(F4 v, std::int32_t out[4]) { _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_cvttps_epi32(v)); }
#else
struct F4 {
  float v[4];
};
inline F4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
inline void store(float* p, F4 a) { std::copy(a.v, a.v + 4, p); }
inline F4 splat(float x) { return {{x, x, x, x}}; }
template <class Op>
inline F4 each(F4 a, F4 b, Op op) {
  return {{op(a.v[0], b.v[0]), op(a.v[1], b.v[1]), op(a.v[2], b.v[2]), op(a.v[3], b.v[3])}};
}
inline F4 lane_min(F4 a, F4 b) {
  return each(a, b, [](float x, float y) { return x < y ? x : y; });
}
inline F4 lane_max(F4 a, F4 b) {
  return each(a, b, [](float x, float y) { return x > y ? x : y; });
}
inline F4 sub(F4 a, F4 b) {
  return each(a, b, [](float x, float y) { return x - y; });
}
inline F4 mul(F4 a, F4 b) {
  return each(a, b, [](float x, float y) { return x * y; });
}
inline void truncate(F4 a, std::int32_t out[4]) {
  for (int k = 0; k < 4; ++k) out[k] = static_cast<std::int32_t>(a.v[k]);
}
#endif

/// A box being grown (lane 3 unused), and how many triangles it holds.
struct Bin {
  alignas(16) float lo[4] = {kFar, kFar, kFar, kFar};
  alignas(16) float hi[4] = {-kFar, -kFar, -kFar, -kFar};
  std::uint32_t count = 0;

  void add(const float l[4], const float h[4]) {
    store(lo, lane_min(load(lo), load(l)));
    store(hi, lane_max(load(hi), load(h)));
  }
  void add(const Bin& b) {
    add(b.lo, b.hi);
    count += b.count;
  }
  /// Half the box's surface area (0 while empty).
  [[nodiscard]] double half_area() const {
    if (count == 0) return 0.0;
    const double x = double(hi[0]) - lo[0], y = double(hi[1]) - lo[1], z = double(hi[2]) - lo[2];
    return x * y + y * z + z * x;
  }
};

/// Each axis's bin of a centroid: (c - lo) times the axis's scale, within [0, kPartitionBins - 1],
/// truncated (an axis without extent has scale 0: every centroid in bin 0).
class Binning {
 public:
  explicit Binning(const CentroidBounds& b) : mLo(load(b.lo)) {
    alignas(16) float scale[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int k = 0; k < 3; ++k) {
      const double extent = double(b.hi[k]) - b.lo[k];
      const double max_scale = std::numeric_limits<float>::max();
      scale[k] = extent > 0.0 ? static_cast<float>(std::min(kPartitionBins / extent, max_scale)) : 0.0f;
      mExtent[k] = extent;
    }
    mScale = load(scale);
  }
  void bins(const PartitionItem& item, std::int32_t out[4]) const {
    const F4 t = mul(sub(load(item.centroid), mLo), mScale);
    truncate(lane_min(lane_max(t, splat(0.0f)), splat(float(kPartitionBins - 1))), out);
  }
  [[nodiscard]] double extent(int k) const { return mExtent[k]; }

 private:
  F4 mLo, mScale;
  double mExtent[3];
};

/// Adds a centroid to a box of centroids.
void grow(CentroidBounds& b, const PartitionItem& item) {
  store(b.lo, lane_min(load(b.lo), load(item.centroid)));
  store(b.hi, lane_max(load(b.hi), load(item.centroid)));
}

CentroidBounds empty_bounds() {
  CentroidBounds b;
  for (int k = 0; k < 4; ++k) {
    b.lo[k] = kFar;
    b.hi[k] = -kFar;
  }
  return b;
}

/// The median cut along `axis` (ties by id), both arrays reordered alike.
std::uint32_t partition_at_median(std::span<std::uint32_t> order, std::span<PartitionItem> items, int axis) {
  struct Entry {
    float key;
    std::uint32_t id;
    PartitionItem item;
  };
  std::vector<Entry> entries(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) entries[i] = {items[i].centroid[axis], order[i], items[i]};
  const auto mid = static_cast<std::ptrdiff_t>(order.size() / 2);
  std::nth_element(entries.begin(), entries.begin() + mid, entries.end(),
                   [](const Entry& a, const Entry& b) { return a.key < b.key || (a.key == b.key && a.id < b.id); });
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = entries[i].id;
    items[i] = entries[i].item;
  }
  return static_cast<std::uint32_t>(mid);
}

/// Moves the places where `first` holds to the front of both arrays (Hoare's two-finger
/// partition: the same result for the same input) and returns how many, with the boxes of the
/// two parts' centroids grown as the items are placed.
template <class First>
std::uint32_t partition_both(std::span<std::uint32_t> order, std::span<PartitionItem> items, First&& first, CentroidBounds& front,
                             CentroidBounds& back) {
  std::size_t lo = 0, hi = order.size();
  for (;;) {
    while (lo < hi && first(items[lo])) grow(front, items[lo++]);
    while (lo < hi && !first(items[hi - 1])) grow(back, items[--hi]);
    if (lo >= hi) break;
    std::swap(order[lo], order[hi - 1]);
    std::swap(items[lo], items[hi - 1]);
    grow(front, items[lo++]);
    grow(back, items[--hi]);
  }
  return static_cast<std::uint32_t>(lo);
}

}  // namespace

std::vector<PartitionItem> partition_items(const Mesh& mesh) {
  // Coordinates relative to the vertices' box, over its largest extent, before they are rounded to
  // floats: scaling a mesh by a power of two scales the differences and the extent alike, so the
  // items, and the tree, are the same bit for bit (tests/narrow/scale_test.cpp: the same prunes).
  // The box of the vertices the triangles use: a stray vertex far away would coarsen every item.
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  if (!mesh.triangles.empty()) lo = hi = mesh.vertices[mesh.triangles[0][0]];
  for (const auto& tri : mesh.triangles) {
    for (const std::uint32_t v : tri) {
      lo = lo.cwiseMin(mesh.vertices[v]);
      hi = hi.cwiseMax(mesh.vertices[v]);
    }
  }
  const double largest = (hi - lo).maxCoeff();
  const double extent = largest > 0.0 ? largest : 1.0;
  std::vector<PartitionItem> items(mesh.triangles.size());
  parallel::parallel_for(0, items.size(), kItemGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t != end; ++t) {
      const auto& tri = mesh.triangles[t];
      const Eigen::Vector3d p = (mesh.vertices[tri[0]] - lo) / extent;
      const Eigen::Vector3d q = (mesh.vertices[tri[1]] - lo) / extent;
      const Eigen::Vector3d r = (mesh.vertices[tri[2]] - lo) / extent;
      const Eigen::Vector3d c = (p + q + r) / 3.0;
      PartitionItem& item = items[t];
      for (int k = 0; k < 3; ++k) {
        item.centroid[k] = static_cast<float>(c[k]);
        item.lo[k] = static_cast<float>(std::min({p[k], q[k], r[k]}));
        item.hi[k] = static_cast<float>(std::max({p[k], q[k], r[k]}));
      }
      item.centroid[3] = item.lo[3] = item.hi[3] = 0.0f;
    }
  });
  return items;
}

CentroidBounds centroid_bounds(std::span<const PartitionItem> items) {
  CentroidBounds b = empty_bounds();
  for (const PartitionItem& item : items) grow(b, item);
  return b;
}

std::uint32_t partition_binned(std::span<std::uint32_t> order, std::span<PartitionItem> items, const CentroidBounds& bounds,
                               CentroidBounds& first, CentroidBounds& second) {
  const auto count = static_cast<std::uint32_t>(order.size());
  if (count == 2) {  // only one cut (the children's order aside)
    first = centroid_bounds(items.first(1));
    second = centroid_bounds(items.subspan(1));
    return 1;
  }
  const Binning binning(bounds);
  std::array<std::array<Bin, kPartitionBins>, 3> bins;
  for (const PartitionItem& item : items) {
    std::int32_t b[4];
    binning.bins(item, b);
    for (int k = 0; k < 3; ++k) {
      bins[k][b[k]].add(item.lo, item.hi);
      ++bins[k][b[k]].count;
    }
  }
  // Each axis's planes: the cost of the bins below a plane and of those above it, from a pass
  // each way; the cheapest plane that leaves both sides their share.
  const std::uint32_t least = std::max<std::uint32_t>(1, count / kPartitionBalance);
  double best = std::numeric_limits<double>::infinity();
  int best_axis = -1, best_plane = 0;  // the first part: bins 0 .. best_plane
  for (int k = 0; k < 3; ++k) {
    if (!(binning.extent(k) > 0.0)) continue;
    std::array<double, kPartitionBins> above_cost{};
    std::array<std::uint32_t, kPartitionBins> above_count{};
    Bin above;
    for (int b = kPartitionBins - 1; b > 0; --b) {
      above.add(bins[k][b]);
      above_cost[b] = above.half_area() * above.count;
      above_count[b] = above.count;
    }
    Bin below;
    for (int b = 0; b + 1 < kPartitionBins; ++b) {
      below.add(bins[k][b]);
      if (below.count < least || above_count[b + 1] < least) continue;
      const double cost = below.half_area() * below.count + above_cost[b + 1];
      if (cost < best) {
        best = cost;
        best_axis = k;
        best_plane = b;
      }
    }
  }
  if (best_axis >= 0) {
    const int k = best_axis;
    first = second = empty_bounds();
    return partition_both(
        order, items,
        [&](const PartitionItem& item) {
          std::int32_t b[4];
          binning.bins(item, b);
          return b[k] <= best_plane;
        },
        first, second);
  }
  int longest = 0;
  for (int k = 1; k < 3; ++k) longest = binning.extent(k) > binning.extent(longest) ? k : longest;
  const std::uint32_t cut = partition_at_median(order, items, longest);
  first = centroid_bounds(items.first(cut));
  second = centroid_bounds(items.subspan(cut));
  return cut;
}

}  // namespace caliber::bvh
