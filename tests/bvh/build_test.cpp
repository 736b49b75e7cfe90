#include <algorithm>
#include <cstring>
#include <cmath>
#include <memory>
#include <numbers>
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include "bvh/leaf_shape.h"
#include "bvh/model_data.h"
#include "caliber/error.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "bvh/partition.h"
#include "parallel/executor.h"

namespace caliber {
namespace {

/// The largest height the build's balance rule allows over n triangles: each cut leaves each side
/// at least max(1, n / kPartitionBalance) of them (bvh/partition.h).
int height_bound(std::uint32_t n) {
  int height = 1;
  while (n > 1) {
    n -= std::max<std::uint32_t>(1, n / bvh::kPartitionBalance);
    ++height;
  }
  return height;
}

/// Leaf `index`'s corners as leaf_corners decodes them: each the triangle's own corner (relative to
/// the origin) within the error it states, plus along each axis what the box's rounding added to
/// its range (the extreme corners decode to the box's bounds).
void check_leaf_shape(const Model& m, const BvhNode& node, std::uint32_t index) {
  double corner[3][3], error;
  bvh::leaf_corners(node, corner, error);
  const auto& t = m.mesh().triangles[node.triangle()];
  for (int i = 0; i < 3; ++i) {
    double lo = 0.0, hi = 0.0;
    for (int j = 0; j < 3; ++j) {
      const double x = m.mesh().vertices[t[j]][i] - data(m).origin[i];
      lo = j == 0 ? x : std::min(lo, x);
      hi = j == 0 ? x : std::max(hi, x);
    }
    const double rounding = 2.0 * static_cast<double>(node.box_half[i]) - (hi - lo);
    EXPECT_LE(error, 0x1p-16 * 2.0 * (static_cast<double>(node.box_half[0]) + node.box_half[1] + node.box_half[2]));
    for (int j = 0; j < 3; ++j) {
      const double x = m.mesh().vertices[t[j]][i] - data(m).origin[i];
      EXPECT_LE(std::abs(corner[j][i] - x), error + rounding + 1e-12 * (std::abs(x) + 1.0))
          << "leaf " << index << " corner " << j << " axis " << i << ": " << corner[j][i] << " for " << x;
    }
  }
}

/// Checks every invariant of the BVH; returns the triangles below `index`.
std::vector<std::uint32_t> check_subtree(const Model& m, std::uint32_t index) {
  const BvhNode& node = data(m).nodes[index];
  const BvhNodeFilter& filter = data(m).filters[index];
  const BvhNodeLateral& lateral_range = data(m).laterals[index];
  std::vector<std::uint32_t> below;
  if (node.is_leaf()) {
    below.push_back(node.index);
    check_leaf_shape(m, node, index);
  } else {
    EXPECT_GT(node.index, index) << "children after their parent";
    auto left = check_subtree(m, node.index);
    auto right = check_subtree(m, node.index + 1);
    EXPECT_EQ(data(m).nodes[node.index].count + data(m).nodes[node.index + 1].count, node.count);
    EXPECT_EQ(data(m).group_mask(node.index) | data(m).group_mask(node.index + 1), data(m).group_mask(index));
    below = std::move(left);
    below.insert(below.end(), right.begin(), right.end());
  }
  EXPECT_EQ(below.size(), node.count);
  const Eigen::Vector3d c(node.center[0], node.center[1], node.center[2]);
  const Eigen::Vector3d bc(node.box_center[0], node.box_center[1], node.box_center[2]);
  const Eigen::Vector3d bh(node.box_half[0], node.box_half[1], node.box_half[2]);
  const Eigen::Vector3d stored_axis(filter.cone_axis[0], filter.cone_axis[1], filter.cone_axis[2]);
  const Eigen::Vector3d axis = stored_axis.normalized();
  double lateral[2][3], lateral_lo[2], lateral_hi[2];
  lateral_axes(filter.cone_axis, lateral_range.turn, lateral[0], lateral[1]);
  caliber::lateral_range(node, lateral_range, lateral[0], lateral[1], lateral_lo, lateral_hi);
  bool any_normal = false;
  for (const std::uint32_t t : below) {
    for (const std::uint32_t v : m.mesh().triangles[t]) {
      const Eigen::Vector3d p = m.mesh().vertices[v] - data(m).origin;  // volumes are relative to it
      EXPECT_LE((p - c).norm(), node.radius) << "node " << index << " sphere must cover its vertices";
      EXPECT_TRUE(((p - bc).cwiseAbs().array() <= bh.array()).all()) << "node " << index << " box must cover its vertices";
      const double along = stored_axis.dot(p);
      EXPECT_TRUE(filter.slab_lo <= along && along <= filter.slab_hi)
          << "node " << index << " slab must cover its vertices: " << filter.slab_lo << " <= " << along
          << " <= " << filter.slab_hi << " (triangle " << t << ")";
      for (int k = 0; k < 2; ++k) {
        const double at = lateral[k][0] * p.x() + lateral[k][1] * p.y() + lateral[k][2] * p.z();
        EXPECT_TRUE(lateral_lo[k] <= at && at <= lateral_hi[k])
            << "node " << index << " lateral range " << k << " must cover its vertices: " << lateral_lo[k] << " <= " << at
            << " <= " << lateral_hi[k] << " (triangle " << t << ")";
      }
    }
    if (m.normals()[t].squaredNorm() > 0.0) {
      any_normal = true;
      const double angle = std::acos(std::clamp(axis.dot(m.normals()[t]), -1.0, 1.0));
      EXPECT_LE(angle, filter.cone_angle) << "node " << index << " cone must hold the normal of triangle " << t;
    }
  }
  if (!data(m).oriented_boxes.empty()) {
    // The kept oriented box is the one the query would compute, and it covers the vertices.
    BvhNodeOrientedBox computed;
    node_oriented_box(node, filter, lateral_range, computed);
    const BvhNodeOrientedBox& kept = data(m).oriented_boxes[index];
    EXPECT_EQ(std::memcmp(&kept, &computed, sizeof kept), 0) << "node " << index << " oriented box as computed";
    const Eigen::Vector3d center(kept.center[0], kept.center[1], kept.center[2]);
    for (const std::uint32_t t : below) {
      for (const std::uint32_t v : m.mesh().triangles[t]) {
        const Eigen::Vector3d p = m.mesh().vertices[v] - data(m).origin;
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d axis_k(kept.axis[k][0], kept.axis[k][1], kept.axis[k][2]);
          EXPECT_LE(std::abs(axis_k.dot(p - center)), kept.half[k] + 1e-12 * (1.0 + p.norm() + center.norm()))
              << "node " << index << " oriented box must cover its vertices along axis " << k << " (triangle " << t << ")";
        }
      }
    }
  }
  EXPECT_EQ(any_normal, filter.cone_angle >= 0.0f) << "node " << index;
  if (!any_normal) {
    EXPECT_TRUE(filter.slab_lo == 0.0f && filter.slab_hi == 0.0f) << "node " << index << ": no axis, no slab";
    for (int k = 0; k < 2; ++k)
      EXPECT_TRUE(lateral_range.lo[k] == 0 && lateral_range.hi[k] == 0) << "node " << index << ": no axis, no lateral range";
  } else {
    // The frame is orthonormal: the lateral axes unit, orthogonal to each other and to the axis.
    const Eigen::Vector3d u(lateral[0][0], lateral[0][1], lateral[0][2]), w(lateral[1][0], lateral[1][1], lateral[1][2]);
    EXPECT_NEAR(u.norm(), 1.0, 1e-12);
    EXPECT_NEAR(w.norm(), 1.0, 1e-12);
    EXPECT_NEAR(u.dot(w), 0.0, 1e-12);
    EXPECT_NEAR(u.dot(axis), 0.0, 1e-12);
    EXPECT_NEAR(w.dot(axis), 0.0, 1e-12);
  }
  return below;
}

void check_model(const Model& m) {
  ASSERT_EQ(data(m).nodes.size(), 2 * m.mesh().triangles.size() - 1);
  auto all = check_subtree(m, 0);
  std::sort(all.begin(), all.end());
  for (std::uint32_t t = 0; t < all.size(); ++t) ASSERT_EQ(all[t], t) << "each triangle in exactly one leaf";
}

TEST(BuildModel, InvariantsOnProceduralMeshes) {
  check_model(*build_model(make_sphere(1.0, 12, 16)));
  check_model(*build_model(make_torus(2.0, 0.5, 16, 10)));
  check_model(*build_model(make_box(1.0, 2.0, 0.5, 3)));
  check_model(*build_model(make_plate(1.0, 0.02, 5)));
}

TEST(BuildModel, OrientedBoxesOnlyWhenAskedAndCoveringTheirTriangles) {
  EXPECT_TRUE(data(*build_model(make_sphere(1.0, 12, 16))).oriented_boxes.empty()) << "off by default";
  BuildOptions options;
  options.oriented_boxes = true;
  for (const Mesh& mesh : {make_sphere(1.0, 12, 16), make_torus(2.0, 0.5, 16, 10), make_plate(1.0, 0.02, 5)}) {
    const auto model = build_model(mesh, options);
    ASSERT_EQ(data(*model).oriented_boxes.size(), data(*model).nodes.size());
    check_model(*model);
  }
  // Far from the origin, and a node with no normal below (its box is the node's own).
  Mesh far = make_sphere(0.001, 6, 8);
  for (auto& v : far.vertices) v += Eigen::Vector3d(1e6, -2e6, 3e5);
  check_model(*build_model(far, options));
  Mesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 1}, {1, 2, 0}, {0, 3, 1}};
  flat.triangles = {{0, 1, 2}, {3, 4, 5}};
  check_model(*build_model(flat, options));
}

TEST(BuildModel, GroupMasksAndTheirBytesOnlyForMeshesWithGroups) {
  Mesh plain = make_torus(1.0, 0.3, 24, 16);
  Mesh grouped = plain;
  grouped.groups.assign(grouped.triangles.size(), 0);
  for (std::size_t t = 0; t < grouped.groups.size(); t += 3) grouped.groups[t] = 2;
  BuildOptions options;
  options.adjacency = false;
  const auto a = build_model(plain, options), b = build_model(grouped, options);
  EXPECT_TRUE(data(*a).group_masks.empty());
  EXPECT_EQ(data(*a).group_mask(0), 1u) << "every triangle in group 0";
  EXPECT_EQ(data(*b).group_mask(0), 0b101u);
  // The masks (8 bytes a node) and the groups (1 byte a triangle) are all that differ.
  EXPECT_EQ(b->memory_bytes() - a->memory_bytes(), 8 * b->node_count() + b->triangle_count());
  EXPECT_GE(a->memory_bytes(), (sizeof(BvhNode) + sizeof(BvhNodeFilter)) * a->node_count())
      << "at least the nodes and their filters";
}

TEST(BuildModel, InvariantsOnRandomSoupWithGroupsAndDegenerates) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-10, 10);
  Mesh mesh;
  mesh.source = "soup";
  for (int t = 0; t < 500; ++t) {
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    mesh.vertices.push_back(p);
    mesh.vertices.push_back(t % 7 == 0 ? p : Eigen::Vector3d(p + Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.1));
    mesh.vertices.push_back(p + Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.1);
    mesh.triangles.push_back({base, base + 1, base + 2});
    mesh.groups.push_back(static_cast<std::uint8_t>(t % 5));
  }
  const auto model = build_model(mesh);
  check_model(*model);
  EXPECT_EQ(data(*model).group_mask(0), 0b11111u);
  EXPECT_EQ(data(*model).group_masks.size(), model->node_count());
  EXPECT_LE(model->height(), height_bound(500));
}

TEST(BuildModel, FarFromTheOriginVolumesStillCover) {
  // Float storage must not lose a vertex: coordinates around 1e6 with millimetre triangles.
  Mesh mesh = make_sphere(0.001, 6, 8);
  for (auto& v : mesh.vertices) v += Eigen::Vector3d(1e6, -2e6, 3e5);
  check_model(*build_model(mesh));
}

TEST(BuildModel, LateralAxesFollowAnElongatedPatch) {
  // A flat strip 1 long and 0.01 wide along a direction 30 degrees from x, in the plane z = 0 (so
  // the unturned lateral axes would be x and y, across which the strip is 0.5 and 0.87 wide). The
  // turned axes follow it: one of the root's lateral ranges is about the strip's width.
  const int n = 60;
  const Eigen::Vector3d along(std::cos(std::numbers::pi / 6), std::sin(std::numbers::pi / 6), 0.0);
  const Eigen::Vector3d across(-along.y(), along.x(), 0.0);
  Mesh mesh;
  for (int i = 0; i <= n; ++i) {
    mesh.vertices.push_back(along * (double(i) / n));
    mesh.vertices.push_back(along * (double(i) / n) + 0.01 * across);
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    mesh.triangles.push_back({2 * i, 2 * i + 2, 2 * i + 1});
    mesh.triangles.push_back({2 * i + 1, 2 * i + 2, 2 * i + 3});
  }
  const auto model = build_model(mesh);
  check_model(*model);
  const ModelData& m = data(*model);
  double axes[2][3], lo[2], hi[2];
  lateral_axes(m.filters[0].cone_axis, m.laterals[0].turn, axes[0], axes[1]);
  lateral_range(m.nodes[0], m.laterals[0], axes[0], axes[1], lo, hi);
  const double width[2] = {hi[0] - lo[0], hi[1] - lo[1]};
  EXPECT_LT(std::min(width[0], width[1]), 0.011) << width[0] << " " << width[1];
  EXPECT_GT(std::max(width[0], width[1]), 0.99) << width[0] << " " << width[1];
}

TEST(BuildModel, SingleTriangleAndOnlyDegenerate) {
  Mesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  mesh.triangles = {{0, 1, 2}};
  const auto model = build_model(mesh);
  ASSERT_EQ(data(*model).nodes.size(), 1u);
  EXPECT_TRUE(data(*model).nodes[0].is_leaf());
  EXPECT_LT(data(*model).filters[0].cone_angle, 0.0f) << "a degenerate triangle has no normal";
  EXPECT_EQ(model->normals()[0], Eigen::Vector3d::Zero());
  check_model(*model);
}

/// The triangles sharing a vertex position with t, sorted and distinct.
std::vector<std::uint32_t> neighbours(const Model& model, std::uint32_t t) {
  std::vector<std::uint32_t> out;
  EXPECT_FALSE(data(model).any_neighbour(t, [&](std::uint32_t u) {
    out.push_back(u);
    return false;
  }));
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

TEST(BuildModel, AdjacencyWeldsRepeatedVertices) {
  // Two triangles sharing an edge, with the shared vertices repeated (as STL stores them),
  // and a third far away.
  Mesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {5, 5, 5}, {6, 5, 5}, {5, 6, 5}};
  mesh.triangles = {{0, 1, 2}, {3, 5, 4}, {6, 7, 8}};
  const auto model = build_model(mesh);
  const auto neighbors = [&](std::uint32_t t) { return neighbours(*model, t); };
  EXPECT_EQ(neighbors(0), std::vector<std::uint32_t>{1});
  EXPECT_EQ(neighbors(1), std::vector<std::uint32_t>{0});
  // The walk stops at the first neighbour the function accepts (triangle 1 comes twice: two shared
  // positions).
  int calls = 0;
  EXPECT_TRUE(data(*model).any_neighbour(0, [&](std::uint32_t u) { return ++calls, u == 1; }));
  EXPECT_EQ(calls, 1);
  EXPECT_TRUE(neighbors(2).empty());
  EXPECT_EQ(data(*model).corner_vertex.size(), 9u) << "repeated positions: the welded corners are kept";
  EXPECT_TRUE(data(*model).are_neighbours(0, 1));
  EXPECT_FALSE(data(*model).are_neighbours(0, 2));
}

// A mesh whose vertices are all at distinct positions keeps no welded corners (its own are the
// welded ones) and has the same neighbours as the same mesh with its vertices repeated per face.
TEST(BuildModel, AdjacencyOfADistinctMeshNeedsNoWeldedCorners) {
  // The torus with its seam's repeated vertices merged.
  const Mesh torus = make_torus(1.0, 0.35, 10, 7);
  Mesh welded;
  std::vector<std::uint32_t> index(torus.vertices.size());
  for (std::size_t v = 0; v < torus.vertices.size(); ++v) {
    const auto same = std::find(welded.vertices.begin(), welded.vertices.end(), torus.vertices[v]);
    index[v] = static_cast<std::uint32_t>(same - welded.vertices.begin());
    if (same == welded.vertices.end()) welded.vertices.push_back(torus.vertices[v]);
  }
  for (const auto& tri : torus.triangles) welded.triangles.push_back({index[tri[0]], index[tri[1]], index[tri[2]]});
  ASSERT_LT(welded.vertices.size(), torus.vertices.size()) << "the seam repeats vertices";
  Mesh soup;
  for (const auto& tri : welded.triangles) {
    const auto first = static_cast<std::uint32_t>(soup.vertices.size());
    for (const std::uint32_t v : tri) soup.vertices.push_back(welded.vertices[v]);
    soup.triangles.push_back({first, first + 1, first + 2});
  }
  const auto a = build_model(welded), b = build_model(soup);
  EXPECT_TRUE(data(*a).corner_vertex.empty());
  EXPECT_EQ(data(*b).corner_vertex.size(), 3 * soup.triangles.size());
  EXPECT_LT(a->memory_bytes(), b->memory_bytes());
  for (std::uint32_t t = 0; t < welded.triangles.size(); ++t) {
    EXPECT_EQ(neighbours(*a, t), neighbours(*b, t)) << "triangle " << t;
    EXPECT_GE(neighbours(*a, t).size(), 9u) << "a torus triangle touches twelve others";
    for (std::uint32_t u = 0; u < welded.triangles.size(); u += 7) {
      EXPECT_EQ(data(*a).are_neighbours(t, u), data(*b).are_neighbours(t, u)) << t << " " << u;
    }
  }
}

/// The bytes of a vector, to compare two builds exactly.
template <class T>
std::vector<unsigned char> bytes(const std::vector<T>& v) {
  const auto* p = reinterpret_cast<const unsigned char*>(v.data());
  return std::vector<unsigned char>(p, p + v.size() * sizeof(T));
}

TEST(BuildModel, ParallelBuildIsTheSameBytesAtAnyThreadCount) {
  // Over 2048 triangles (kParallelBuildCount), so the two halves of the top subtrees are built at once.
  const Mesh mesh = make_sphere(1.0, 120, 160);
  ASSERT_GT(mesh.triangles.size(), 30000u);
  std::shared_ptr<const Model> one;
  parallel::Executor single(1);
  single.execute([&] { one = build_model(mesh); });
  for (const int threads : {2, 3, 8}) {
    std::shared_ptr<const Model> many;
    parallel::Executor executor(threads);
    executor.execute([&] { many = build_model(mesh); });
    EXPECT_EQ(bytes(data(*many).nodes), bytes(data(*one).nodes)) << threads << " threads";
    EXPECT_EQ(bytes(data(*many).filters), bytes(data(*one).filters)) << threads << " threads";
    EXPECT_EQ(bytes(data(*many).laterals), bytes(data(*one).laterals)) << threads << " threads";
    EXPECT_EQ(data(*many).leaf_position, data(*one).leaf_position);
    EXPECT_EQ(bytes(many->normals()), bytes(one->normals()));
    EXPECT_EQ(data(*many).corner_vertex, data(*one).corner_vertex);
    EXPECT_EQ(data(*many).vertex_offsets, data(*one).vertex_offsets);
    EXPECT_EQ(data(*many).vertex_triangles, data(*one).vertex_triangles);
    EXPECT_EQ(many->height(), one->height());
    EXPECT_EQ(many->extent(), one->extent());
  }
  // The layout of a depth-first build that appends a node's two children, then builds the left
  // subtree, then the right (the one every earlier version had): the left child's children come
  // right after the pair, the right child's after the left subtree's 2 m - 2 further nodes.
  const Model& m = *one;
  for (std::size_t i = 0; i < data(m).nodes.size(); ++i) {
    if (data(m).nodes[i].is_leaf()) continue;
    const std::uint32_t first = data(m).nodes[i].index;
    if (!data(m).nodes[first].is_leaf()) EXPECT_EQ(data(m).nodes[first].index, first + 2) << "node " << i;
    if (!data(m).nodes[first + 1].is_leaf())
      EXPECT_EQ(data(m).nodes[first + 1].index, first + 2 * data(m).nodes[first].count) << "node " << i;
  }
}

TEST(BuildModel, RejectsBadMesh) {
  Mesh mesh;
  mesh.source = "empty";
  EXPECT_THROW((void)build_model(mesh), Error);
}

TEST(BuildModel, BoxAdjacencyIsVertexAdjacency) {
  const auto model = build_model(make_box(1, 1, 1, 1));
  // A cube of 12 triangles: faces are separate grids, so adjacency comes from welding positions.
  for (std::uint32_t t = 0; t < 12; ++t) {
    EXPECT_GE(neighbours(*model, t).size(), 5u) << "triangle " << t;
  }
}

TEST(BuildModel, AdjacencyIsLinearInTheCornersOfAHugeFan) {
  // One polygon of 200,000 corners fanned from its first: the fan's hub touches every triangle.
  // The old per-triangle neighbour lists held the square of that degree (4e10 entries); the
  // per-vertex lists hold three entries a triangle.
  Mesh mesh;
  const int n = 200000;
  mesh.vertices.emplace_back(0, 0, 0);
  for (int i = 0; i < n; ++i) {
    const double a = 6.283185307179586 * i / n;
    mesh.vertices.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  for (std::uint32_t i = 1; i + 1 <= static_cast<std::uint32_t>(n); ++i) mesh.triangles.push_back({0, i, i + 1});
  const auto model = build_model(mesh);
  EXPECT_EQ(data(*model).vertex_triangles.size(), 3 * mesh.triangles.size());
  EXPECT_TRUE(data(*model).corner_vertex.empty()) << "no repeated positions";
  EXPECT_EQ(neighbours(*model, 5).size(), mesh.triangles.size() - 1) << "the hub: every other triangle";
}

// node_box, the viewer's view of the BVH: every node's box holds the vertices of the triangles
// below it (walked through the children it gives), leaves have no children, and every node is
// reached once.
TEST(NodeBox, ChildrenCoverTheTreeAndBoxesHoldTheirTriangles) {
  const auto model = build_model(make_torus(1.0, 0.3, 12, 8));
  const Mesh& mesh = model->mesh();
  std::vector<int> seen(model->node_count(), 0);
  std::function<std::vector<std::uint32_t>(std::uint32_t)> below = [&](std::uint32_t node) {
    ++seen[node];
    const NodeBox box = node_box(*model, node);
    std::vector<std::uint32_t> triangles;
    for (int c = 0; c < box.child_count; ++c) {
      const auto more = below(box.children[c]);
      triangles.insert(triangles.end(), more.begin(), more.end());
    }
    if (box.child_count == 0) triangles.push_back(static_cast<std::uint32_t>(data(*model).nodes[node].index));
    for (const std::uint32_t t : triangles) {
      for (const auto v : mesh.triangles[t]) {
        const Eigen::Vector3d d = (mesh.vertices[v] - box.center).cwiseAbs() - box.half;
        EXPECT_LE(d.maxCoeff(), 1e-6) << "node " << node << " triangle " << t;
      }
    }
    return triangles;
  };
  EXPECT_EQ(below(0).size(), mesh.triangles.size());
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
  EXPECT_THROW((void)node_box(*model, static_cast<std::uint32_t>(model->node_count())), Error);
}

}  // namespace
}  // namespace caliber
