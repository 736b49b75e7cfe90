// Sphere-tree BVH build: top-down binned surface-area partition (bvh/partition.h), exact covering radii, normal cones and slabs, group masks.

#include <numbers>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <span>

#include <Eigen/Geometry>

#include "caliber/error.h"
#include "bvh/model_data.h"
#include "bvh/validate.h"
#include "util/assert.h"
#include "bvh/adjacency.h"
#include "bvh/lateral.h"
#include "bvh/leaf_shape.h"
#include "bvh/partition.h"
#include "bvh/volume_origin.h"
#include "bvh/wide_tree.h"
#include "util/float_round.h"
#include "parallel/executor.h"

namespace caliber {
namespace {

using Vec3 = Eigen::Vector3d;
using bvh::partition_binned;
using bvh::partition_items;
using bvh::partition_turn;
using bvh::triangle_turn;
using bvh::turned_axes;
using bvh::unturned_axes;
using util::round_down;
using util::round_up;

/// Nodes with at most this many triangles get the exact covering radius (a pass over their vertices);
/// larger ones bound it from their children's spheres.
constexpr std::uint32_t kExactRadiusCount = 256;
/// Added to every cone half-angle: covers rounding in the angles and in the rotated normals.
constexpr double kConeSlack = 1e-6;

double angle_between(const Vec3& u, const Vec3& v) { return std::acos(std::clamp(u.dot(v), -1.0, 1.0)); }

Vec3 to_float_axis(const Vec3& axis) {
  Vec3 rounded(static_cast<float>(axis.x()), static_cast<float>(axis.y()), static_cast<float>(axis.z()));
  return rounded;
}

/// A node while it is built, in double precision; converted to BvhNode / BvhNodeFilter at the end.
struct WorkNode {
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();                      ///< box of the vertices below
  Vec3 normal_sum = Vec3::Zero();                                 ///< sum of the unit normals below (cone axis direction)
  Vec3 axis = Vec3::Zero();                                       ///< cone axis, already rounded to float
  double cone = -1.0;                                             ///< cone half-angle about `axis`, < 0 when no normal below
  double slab_lo = 0.0, slab_hi = 0.0;                            ///< range of axis . v over the vertices below (0, 0: no axis)
  double lateral_lo[2] = {0.0, 0.0}, lateral_hi[2] = {0.0, 0.0};  ///< ranges along the turned lateral axes
  double turn[2] = {1.0, 0.0};                                    ///< the lateral axes' turn, the stored integers
  std::uint64_t groups = 0;
  std::uint32_t index = 0;
  std::uint32_t count = 0;
  std::uint32_t first = 0;  ///< first position of its triangles in leaf order
};

/// Room for a WorkNode, which the build constructs there (std::construct_at) when it makes the
/// node: the 2 n - 1 nodes' memory is written once, in the (parallel) build, instead of also being
/// value-initialized first in one thread.
union WorkSlot {
  WorkSlot() {}   // NOLINT(modernize-use-equals-default): leaves `node` unconstructed on purpose
  ~WorkSlot() {}  // NOLINT(modernize-use-equals-default)
  WorkNode node;
};

/// Subtrees over more triangles than this build their two halves in parallel (on the executor the
/// caller runs in); smaller ones, and every leaf-level pass, in a loop of their own.
constexpr std::uint32_t kParallelBuildCount = 2048;
/// Items per chunk for the build's per-triangle and per-node loops.
constexpr std::size_t kBuildGrain = 4096;

class Builder {
 public:
  Builder(const Mesh& mesh, const std::vector<Vec3>& normals) : mMesh(mesh), mNormals(normals) {
    const std::size_t n = mesh.triangles.size();
    mOrder.resize(n);
    std::iota(mOrder.begin(), mOrder.end(), 0u);
    mItems = partition_items(mesh);
    mWork = std::make_unique_for_overwrite<WorkSlot[]>(2 * n - 1);
    mWorkCount = 2 * n - 1;
  }

  /// The tree into model, with each node's oriented box where `oriented_boxes` asks for them.
  void build(ModelData& model, bool oriented_boxes) {
    model.height = build_range(0, 1, 0, static_cast<std::uint32_t>(mOrder.size()), bvh::centroid_bounds(mItems));
    model.nodes.resize(mWorkCount);
    model.filters.resize(mWorkCount);
    model.laterals.resize(mWorkCount);
    if (!mMesh.groups.empty()) model.group_masks.resize(mWorkCount);
    if (oriented_boxes) model.oriented_boxes.resize(mWorkCount);
    model.leaf_position.resize(mOrder.size());
    parallel::parallel_for(0, mWorkCount, kBuildGrain, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t i = lo; i != hi; ++i) {
        convert(mWork[i].node, model.nodes[i], model.filters[i], model.laterals[i]);
        if (oriented_boxes) node_oriented_box(model.nodes[i], model.filters[i], model.laterals[i], model.oriented_boxes[i]);
        if (!model.group_masks.empty()) model.group_masks[i] = mWork[i].node.groups;
      }
    });
    for (std::uint32_t p = 0; p < mOrder.size(); ++p) model.leaf_position[mOrder[p]] = p;
  }

 private:
  /// Builds the subtree over mOrder[begin, end) into mWork[slot], its other nodes into mWork from
  /// `next` on; returns its height. The layout is the one of a depth-first build that appends the
  /// two children of a node, then builds the left subtree, then the right one: a subtree over m
  /// triangles holds 2 m - 1 nodes, so the right subtree's nodes start 2 (left count) - 2 after the
  /// left's, and both halves can be built at once, into the same places, whatever the threads.
  /// `bounds`: the box of the range's centroids.
  int build_range(std::uint32_t slot, std::uint32_t next, std::uint32_t begin, std::uint32_t end,
                  const bvh::CentroidBounds& bounds) {
    if (end - begin == 1) {
      make_leaf(slot, mOrder[begin], begin);
      return 1;
    }
    bvh::CentroidBounds left, right;
    const std::uint32_t mid =
        begin + partition_binned(std::span<std::uint32_t>(mOrder.data() + begin, end - begin),
                                 std::span<bvh::PartitionItem>(mItems.data() + begin, end - begin), bounds, left, right);
    const std::uint32_t first = next;
    const std::uint32_t left_next = first + 2, right_next = left_next + 2 * (mid - begin) - 2;
    int hl = 0, hr = 0;
    if (end - begin > kParallelBuildCount) {
      parallel::JobGroup halves;
      halves.run([&] { hl = build_range(first, left_next, begin, mid, left); });
      hr = build_range(first + 1, right_next, mid, end, right);
      halves.wait();
    } else {
      hl = build_range(first, left_next, begin, mid, left);
      hr = build_range(first + 1, right_next, mid, end, right);
    }
    make_internal(slot, first, begin, end);
    return 1 + std::max(hl, hr);
  }

  /// One pass over the vertices of the triangles in mOrder[begin, end): the largest distances from
  /// c1 and from c2, rounded up a little so that they cover every vertex despite rounding in the
  /// norms, and the ranges of axis . v (the slab) and of the lateral axes' products (node.lateral_*).
  void exact_bounds(const Vec3& c1, const Vec3& c2, const Vec3& u0, const Vec3& v0, WorkNode& node, std::uint32_t begin,
                    std::uint32_t end, double& r1, double& r2) const {
    double d1 = 0.0, d2 = 0.0;
    Vec3 u, v;
    turned_axes(u0, v0, node.turn, u, v);
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::numeric_limits<double>::infinity();
      hi[k] = -lo[k];
    }
    for (std::uint32_t i = begin; i < end; ++i) {
      for (const std::uint32_t w : mMesh.triangles[mOrder[i]]) {
        const Vec3& p = mMesh.vertices[w];
        d1 = std::max(d1, (p - c1).squaredNorm());
        d2 = std::max(d2, (p - c2).squaredNorm());
        const double s[3] = {node.axis.dot(p), u.dot(p), v.dot(p)};
        for (int k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], s[k]);
          hi[k] = std::max(hi[k], s[k]);
        }
      }
    }
    node.slab_lo = lo[0];
    node.slab_hi = hi[0];
    for (int k = 0; k < 2; ++k) {
      node.lateral_lo[k] = lo[k + 1];
      node.lateral_hi[k] = hi[k + 1];
    }
    r1 = std::sqrt(d1) * (1.0 + 1e-14);
    r2 = std::sqrt(d2) * (1.0 + 1e-14);
  }

  /// The range along `axis` of the children's boxes (a bound on the vertices' range, not the range).
  static void children_range(const Vec3& axis, const WorkNode& l, const WorkNode& r, double& lo, double& hi) {
    lo = std::numeric_limits<double>::infinity();
    hi = -lo;
    for (const WorkNode* kid : {&l, &r}) {
      const Vec3 center = 0.5 * (kid->lo + kid->hi), half = 0.5 * (kid->hi - kid->lo);
      const double mid = axis.dot(center), reach = axis.cwiseAbs().dot(half);
      lo = std::min(lo, mid - reach);
      hi = std::max(hi, mid + reach);
    }
  }

  void make_leaf(std::uint32_t slot, std::uint32_t tri, std::uint32_t position) {
    const auto& t = mMesh.triangles[tri];
    const Vec3& a = mMesh.vertices[t[0]];
    const Vec3& b = mMesh.vertices[t[1]];
    const Vec3& c = mMesh.vertices[t[2]];
    WorkNode node;
    node.first = position;
    node.lo = a.cwiseMin(b).cwiseMin(c);
    node.hi = a.cwiseMax(b).cwiseMax(c);
    // Trial centers: the box center, the circumcenter and the edge midpoints (the smallest
    // enclosing sphere is one of the last four); keep whichever covers with the smallest radius.
    const Vec3 ab = b - a, ac = c - a, n = ab.cross(ac);
    const double n2 = n.squaredNorm();
    Vec3 trials[5] = {0.5 * (node.lo + node.hi), 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a), a};
    int count = 4;
    if (n2 > 0.0) trials[count++] = a + (ac.squaredNorm() * n.cross(ab) + ab.squaredNorm() * ac.cross(n)) / (2.0 * n2);
    node.radius = std::numeric_limits<double>::infinity();
    for (int i = 0; i < count; ++i) {
      if (!trials[i].allFinite()) continue;
      // The largest of the three norms: one square root of the largest square (sqrt is monotone
      // and correctly rounded, as norm() takes it).
      const double r =
          std::sqrt(std::max({(a - trials[i]).squaredNorm(), (b - trials[i]).squaredNorm(), (c - trials[i]).squaredNorm()}));
      if (r < node.radius) {
        node.radius = r;
        node.center = trials[i];
      }
    }
    node.radius *= 1.0 + 1e-14;
    node.index = tri;
    node.count = 1;
    node.groups = std::uint64_t{1} << (mMesh.groups.empty() ? 0 : mMesh.groups[tri]);
    const Vec3& normal = mNormals[tri];
    node.normal_sum = normal;
    if (normal.squaredNorm() > 0.0) {
      node.axis = to_float_axis(normal);
      Vec3 u0, v0;
      unturned_axes(node.axis, u0, v0);
      triangle_turn(u0, v0, a, b, c, node.turn);
      node.cone = angle_between(node.axis.normalized(), normal) + kConeSlack;
      const double along[3] = {node.axis.dot(a), node.axis.dot(b), node.axis.dot(c)};
      node.slab_lo = std::min({along[0], along[1], along[2]});
      node.slab_hi = std::max({along[0], along[1], along[2]});
      Vec3 lateral[2];
      turned_axes(u0, v0, node.turn, lateral[0], lateral[1]);
      for (int k = 0; k < 2; ++k) {
        const double at[3] = {lateral[k].dot(a), lateral[k].dot(b), lateral[k].dot(c)};
        node.lateral_lo[k] = std::min({at[0], at[1], at[2]});
        node.lateral_hi[k] = std::max({at[0], at[1], at[2]});
      }
    }
    std::construct_at(&mWork[slot].node, node);
  }

  void make_internal(std::uint32_t slot, std::uint32_t first, std::uint32_t begin, std::uint32_t end) {
    const WorkNode& l = mWork[first].node;
    const WorkNode& r = mWork[first + 1].node;
    WorkNode node;
    node.index = first;
    node.count = l.count + r.count;
    node.groups = l.groups | r.groups;
    node.lo = l.lo.cwiseMin(r.lo);
    node.hi = l.hi.cwiseMax(r.hi);

    // Normal cone: axis along the sum of the unit normals below; half-angle from the children's
    // cones by the triangle inequality (angle to a child's axis + that child's half-angle).
    node.normal_sum = l.normal_sum + r.normal_sum;
    if (l.cone >= 0.0 || r.cone >= 0.0) {
      const double sum_norm = node.normal_sum.norm();
      node.axis = to_float_axis(sum_norm > 1e-9 * node.count ? Vec3(node.normal_sum / sum_norm) : Vec3(1.0, 0.0, 0.0));
      const Vec3 unit = node.axis.normalized();
      double angle = 0.0;
      for (const WorkNode* kid : {&l, &r}) {
        if (kid->cone >= 0.0) angle = std::max(angle, angle_between(unit, kid->axis.normalized()) + kid->cone);
      }
      node.cone = std::min(angle + kConeSlack, 2.0 * std::numbers::pi);
    }
    // The lateral axes before and after their turn (0 when there is no cone axis).
    Vec3 u0 = Vec3::Zero(), v0 = Vec3::Zero();
    if (node.cone >= 0.0) {
      unturned_axes(node.axis, u0, v0);
      partition_turn(u0, v0, 0.5 * (r.lo + r.hi) - 0.5 * (l.lo + l.hi), node.turn);
    }

    // Sphere: the merged child spheres' center or the box center, whichever covers tighter.
    Vec3 merged = l.center;
    const double d = (r.center - l.center).norm();
    if (d > 0.0 && d + r.radius > l.radius) {
      if (d + l.radius <= r.radius) {
        merged = r.center;
      } else {
        merged = l.center + ((0.5 * (d + l.radius + r.radius) - l.radius) / d) * (r.center - l.center);
      }
    }
    const Vec3 box = 0.5 * (node.lo + node.hi);
    double r_merged, r_box;
    if (node.count <= kExactRadiusCount) {
      // The slab's range comes from the same pass (unused, and the axis 0, when there is no cone).
      exact_bounds(merged, box, u0, v0, node, begin, end, r_merged, r_box);
    } else {
      // Near the root, the children's spheres bound the radius: O(1) instead of a pass over every
      // vertex below, which keeps the build O(n log n) with a small constant. These few large
      // nodes are also pruned by their boxes.
      const auto bound = [&](const Vec3& c) {
        return std::max((c - l.center).norm() + l.radius, (c - r.center).norm() + r.radius) * (1.0 + 1e-14);
      };
      r_merged = bound(merged);
      r_box = bound(box);
      // The slab and lateral ranges likewise: the children's boxes projected on the axes (a bound,
      // not the range).
      Vec3 u, v;
      turned_axes(u0, v0, node.turn, u, v);
      children_range(node.axis, l, r, node.slab_lo, node.slab_hi);
      children_range(u, l, r, node.lateral_lo[0], node.lateral_hi[0]);
      children_range(v, l, r, node.lateral_lo[1], node.lateral_hi[1]);
    }
    node.center = r_box < r_merged ? box : merged;
    node.radius = std::min(r_box, r_merged);
    node.first = begin;
    std::construct_at(&mWork[slot].node, node);
  }

  /// Rounds the volumes outward to floats: the stored radius and half-extents also cover the
  /// distance the center moved when it was rounded.
  static void convert(const WorkNode& w, BvhNode& node, BvhNodeFilter& filter, BvhNodeLateral& lateral) {
    const Vec3 box_center = 0.5 * (w.lo + w.hi);
    const Vec3 box_half = 0.5 * (w.hi - w.lo);
    const double pad = 1e-14 * (box_center.cwiseAbs().maxCoeff() + box_half.maxCoeff());
    for (int k = 0; k < 3; ++k) {
      node.center[k] = static_cast<float>(w.center[k]);
      node.box_center[k] = static_cast<float>(box_center[k]);
      const double moved = std::abs(static_cast<double>(node.box_center[k]) - box_center[k]);
      node.box_half[k] = round_up(box_half[k] + moved + pad);
    }
    const Vec3 stored(node.center[0], node.center[1], node.center[2]);
    node.radius = round_up((w.radius + (stored - w.center).norm()) * (1.0 + 1e-14));
    node.index = w.index;
    node.count = w.count;
    for (int k = 0; k < 3; ++k) filter.cone_axis[k] = w.cone >= 0.0 ? static_cast<float>(w.axis[k]) : 0.0f;
    filter.cone_angle = w.cone >= 0.0 ? round_up(w.cone) : -1.0f;
    filter.cone_cos = static_cast<float>(std::cos(static_cast<double>(filter.cone_angle)));
    filter.cone_sin = static_cast<float>(std::sin(static_cast<double>(filter.cone_angle)));
    // The dot products above carry a few ulps of |axis|_1 * |v|_inf; the pad is far above that.
    const double slab_pad = 1e-13 * (box_center.cwiseAbs().maxCoeff() + box_half.maxCoeff());
    filter.slab_lo = w.cone >= 0.0 ? round_down(w.slab_lo - slab_pad) : 0.0f;
    filter.slab_hi = w.cone >= 0.0 ? round_up(w.slab_hi + slab_pad) : 0.0f;
    for (int k = 0; k < 2; ++k) lateral.turn[k] = static_cast<std::int16_t>(w.turn[k]);  // already integers within 32767
    if (w.cone >= 0.0) {
      bvh::lateral_steps(node, filter, w.lateral_lo, w.lateral_hi, slab_pad, lateral);
    } else {
      lateral.lo[0] = lateral.lo[1] = lateral.hi[0] = lateral.hi[1] = 0;
    }
  }

  const Mesh& mMesh;
  const std::vector<Vec3>& mNormals;
  std::vector<std::uint32_t> mOrder;
  std::vector<bvh::PartitionItem> mItems;  ///< what the partition reads of triangle mOrder[i], in mItems[i]
  std::unique_ptr<WorkSlot[]> mWork;       ///< node i in mWork[i].node, once made
  std::size_t mWorkCount = 0;
};

}  // namespace

namespace {

/// The build, its parallel parts on the executor the caller runs in.
std::shared_ptr<ModelData> build_on_this_thread(Mesh mesh, const BuildOptions& options) {
  auto model = std::make_shared<ModelData>();
  model->normals = bvh::face_normals(mesh, kBuildGrain);
  model->origin = bvh::volume_origin(mesh);
  {  // the volumes of the vertices moved by -origin (the mesh itself is kept as given)
    const Mesh moved = model->origin == Vec3::Zero() ? Mesh{} : bvh::moved_by(mesh, -model->origin);
    Builder builder(model->origin == Vec3::Zero() ? mesh : moved, model->normals);
    builder.build(*model, options.oriented_boxes);
    bvh::fill_leaf_shapes(model->origin == Vec3::Zero() ? mesh : moved, *model, kBuildGrain);
  }
  bvh::build_wide_tree(*model);
  model->extent = bvh::largest_norm(mesh, Vec3::Zero());
  model->local_extent = bvh::largest_norm(mesh, model->origin);
  if (options.adjacency) bvh::vertex_adjacency(mesh, *model);
  model->mesh = std::move(mesh);
  return model;
}

}  // namespace

std::shared_ptr<const Model> build_model(Mesh mesh, const BuildOptions& options) {
  if (options.threads < 0 || options.threads > 1024) {
    throw Error(ErrorCode::bad_value, "threads", "must be between 0 and 1024 (0: the arena caliber is called from)");
  }
  validate_mesh(mesh);
  std::shared_ptr<ModelData> out;
  // Inside an executor already (a step, a World being built on the host's arena), its threads
  // are this build's too; otherwise the build runs where BuildOptions::threads says.
  if (parallel::in_executor() && options.threads == 0) {
    out = build_on_this_thread(std::move(mesh), options);
  } else {
    parallel::Executor executor(options.threads, options.host);
    executor.execute([&] { out = build_on_this_thread(std::move(mesh), options); });
  }
  CALIBER_ASSERT(bvh::bvh_problem(*out).empty(), "a built BVH keeps its invariants (bvh/validate.h)");
  return out;
}

}  // namespace caliber
