// Sphere-tree BVH build: top-down median split, exact covering radii, normal cones, group masks.

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/Geometry>

#include "caliber/error.h"
#include "caliber/model.h"

namespace caliber {
namespace {

using Vec3 = Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;
/// Added to every cone half-angle: covers rounding in the angles and in the rotated normals.
constexpr double kConeSlack = 1e-6;

double angle_between(const Vec3& u, const Vec3& v) {
  return std::acos(std::clamp(u.dot(v), -1.0, 1.0));
}

/// A float that is >= x (x >= 0), so that a stored half-angle never shrinks.
float round_up(double x) {
  auto f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, 4.0f);
  return f;
}

Vec3 to_float_axis(const Vec3& axis) {
  Vec3 rounded(static_cast<float>(axis.x()), static_cast<float>(axis.y()), static_cast<float>(axis.z()));
  return rounded;
}

class Builder {
 public:
  Builder(const Mesh& mesh, const std::vector<Vec3>& normals) : mMesh(mesh), mNormals(normals) {
    const std::size_t n = mesh.triangles.size();
    mOrder.resize(n);
    std::iota(mOrder.begin(), mOrder.end(), 0u);
    mCentroids.resize(n);
    for (std::size_t t = 0; t < n; ++t) {
      const auto& tri = mesh.triangles[t];
      mCentroids[t] = (mesh.vertices[tri[0]] + mesh.vertices[tri[1]] + mesh.vertices[tri[2]]) / 3.0;
    }
    mNodes.reserve(2 * n - 1);
    mBoxes.reserve(2 * n - 1);
    mNormalSums.reserve(2 * n - 1);
  }

  void build(std::vector<BvhNode>& nodes, std::vector<BvhBox>& boxes, int& height) {
    height = build_range(0, static_cast<std::uint32_t>(mOrder.size()));
    nodes = std::move(mNodes);
    boxes = std::move(mBoxes);
  }

 private:
  /// Builds the subtree over mOrder[begin, end) at index mNodes.size(); returns its height.
  int build_range(std::uint32_t begin, std::uint32_t end) {
    const auto self = static_cast<std::uint32_t>(mNodes.size());
    mNodes.emplace_back();
    mBoxes.emplace_back();
    mNormalSums.emplace_back(Vec3::Zero());
    if (end - begin == 1) {
      make_leaf(self, mOrder[begin]);
      return 1;
    }
    const std::uint32_t mid = split(begin, end);
    const std::uint32_t left = self + 1;
    const int hl = build_range(begin, mid);
    const auto right = static_cast<std::uint32_t>(mNodes.size());
    const int hr = build_range(mid, end);
    make_internal(self, left, right, begin, end);
    return 1 + std::max(hl, hr);
  }

  /// Median split along the longest axis of the centroid bounds; ties broken by triangle id.
  std::uint32_t split(std::uint32_t begin, std::uint32_t end) {
    Vec3 lo = mCentroids[mOrder[begin]], hi = lo;
    for (std::uint32_t i = begin + 1; i < end; ++i) {
      lo = lo.cwiseMin(mCentroids[mOrder[i]]);
      hi = hi.cwiseMax(mCentroids[mOrder[i]]);
    }
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(mOrder.begin() + begin, mOrder.begin() + mid, mOrder.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) {
                       const double ca = mCentroids[a][axis], cb = mCentroids[b][axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    return mid;
  }

  /// Largest distance from c to a vertex of a triangle in mOrder[begin, end).
  double covering_radius(const Vec3& c, std::uint32_t begin, std::uint32_t end) const {
    double r2 = 0.0;
    for (std::uint32_t i = begin; i < end; ++i) {
      for (const std::uint32_t v : mMesh.triangles[mOrder[i]]) r2 = std::max(r2, (mMesh.vertices[v] - c).squaredNorm());
    }
    // Rounded up a little: the radius must cover every vertex despite rounding in the norm.
    return std::sqrt(r2) * (1.0 + 1e-14);
  }

  /// The box of the vertices below, grown by a relative hair so rounding never leaves one outside.
  void set_box(std::uint32_t self, const Vec3& lo, const Vec3& hi) {
    const Vec3 c = 0.5 * (lo + hi);
    const Vec3 h = 0.5 * (hi - lo);
    const double pad = 1e-14 * (c.cwiseAbs().maxCoeff() + h.maxCoeff());
    for (int k = 0; k < 3; ++k) {
      mBoxes[self].center[k] = c[k];
      mBoxes[self].half[k] = h[k] + pad;
    }
  }

  void set_sphere(BvhNode& node, const Vec3& c, double r) {
    node.center[0] = c.x();
    node.center[1] = c.y();
    node.center[2] = c.z();
    node.radius = r;
  }

  void make_leaf(std::uint32_t self, std::uint32_t tri) {
    const auto& t = mMesh.triangles[tri];
    const Vec3& a = mMesh.vertices[t[0]];
    const Vec3& b = mMesh.vertices[t[1]];
    const Vec3& c = mMesh.vertices[t[2]];
    // Candidate centers: the smallest enclosing sphere (circumcenter or midpoint of the longest
    // edge) and the box center; keep whichever covers with the smaller radius.
    set_box(self, a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c));
    Vec3 best = 0.5 * (a.cwiseMin(b).cwiseMin(c) + a.cwiseMax(b).cwiseMax(c));
    double best_r = std::max({(a - best).norm(), (b - best).norm(), (c - best).norm()});
    const Vec3 ab = b - a, ac = c - a;
    const Vec3 n = ab.cross(ac);
    const double n2 = n.squaredNorm();
    if (n2 > 0.0) {
      const Vec3 cc = a + (ac.squaredNorm() * n.cross(ab) + ab.squaredNorm() * ac.cross(n)) / (2.0 * n2);
      const Vec3 candidates[4] = {cc, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)};
      for (const Vec3& cand : candidates) {
        if (!cand.allFinite()) continue;
        const double r = std::max({(a - cand).norm(), (b - cand).norm(), (c - cand).norm()});
        if (r < best_r) {
          best = cand;
          best_r = r;
        }
      }
    }
    BvhNode& node = mNodes[self];
    set_sphere(node, best, best_r * (1.0 + 1e-14));
    node.index = tri;
    node.count = 1;
    node.groups = std::uint64_t{1} << (mMesh.groups.empty() ? 0 : mMesh.groups[tri]);
    const Vec3& normal = mNormals[tri];
    mNormalSums[self] = normal;
    if (normal.squaredNorm() > 0.0) {
      const Vec3 axis = to_float_axis(normal);
      const Vec3 unit = axis.normalized();
      for (int k = 0; k < 3; ++k) node.cone_axis[k] = static_cast<float>(axis[k]);
      node.cone_angle = round_up(angle_between(unit, normal) + kConeSlack);
    } else {
      for (float& k : node.cone_axis) k = 0.0f;
      node.cone_angle = -1.0f;
    }
  }

  void make_internal(std::uint32_t self, std::uint32_t left, std::uint32_t right, std::uint32_t begin,
                     std::uint32_t end) {
    const BvhNode& l = mNodes[left];
    const BvhNode& r = mNodes[right];
    BvhNode node{};
    node.index = right;
    node.count = l.count + r.count;
    node.groups = l.groups | r.groups;

    // Sphere: the merged child spheres' center or the box center, whichever covers tighter.
    const Vec3 cl(l.center[0], l.center[1], l.center[2]), cr(r.center[0], r.center[1], r.center[2]);
    Vec3 merged = cl;
    const double d = (cr - cl).norm();
    if (d > 0.0 && d + r.radius > l.radius) {
      if (d + l.radius <= r.radius) {
        merged = cr;
      } else {
        const double radius = 0.5 * (d + l.radius + r.radius);
        merged = cl + ((radius - l.radius) / d) * (cr - cl);
      }
    }
    Vec3 lo = mMesh.vertices[mMesh.triangles[mOrder[begin]][0]], hi = lo;
    for (std::uint32_t i = begin; i < end; ++i) {
      for (const std::uint32_t v : mMesh.triangles[mOrder[i]]) {
        lo = lo.cwiseMin(mMesh.vertices[v]);
        hi = hi.cwiseMax(mMesh.vertices[v]);
      }
    }
    set_box(self, lo, hi);
    const Vec3 box = 0.5 * (lo + hi);
    const double r_merged = covering_radius(merged, begin, end);
    const double r_box = covering_radius(box, begin, end);
    if (r_box < r_merged) {
      set_sphere(node, box, r_box);
    } else {
      set_sphere(node, merged, r_merged);
    }

    // Normal cone: axis along the sum of the unit normals below; half-angle from the children's
    // cones by the triangle inequality (angle to a child's axis + that child's half-angle).
    mNormalSums[self] = mNormalSums[left] + mNormalSums[right];
    const BvhNode* kids[2] = {&l, &r};
    const bool has_l = l.cone_angle >= 0.0f, has_r = r.cone_angle >= 0.0f;
    if (!has_l && !has_r) {
      for (float& k : node.cone_axis) k = 0.0f;
      node.cone_angle = -1.0f;
    } else {
      const Vec3& sum = mNormalSums[self];
      const double sum_norm = sum.norm();
      Vec3 axis = sum_norm > 1e-9 * node.count ? Vec3(sum / sum_norm) : Vec3(1.0, 0.0, 0.0);
      axis = to_float_axis(axis);
      const Vec3 unit = axis.normalized();
      double angle = 0.0;
      for (const BvhNode* kid : kids) {
        if (kid->cone_angle < 0.0f) continue;
        const Vec3 kid_axis = Vec3(kid->cone_axis[0], kid->cone_axis[1], kid->cone_axis[2]).normalized();
        angle = std::max(angle, angle_between(unit, kid_axis) + kid->cone_angle);
      }
      angle = std::min(angle + kConeSlack, 2.0 * kPi);
      for (int k = 0; k < 3; ++k) node.cone_axis[k] = static_cast<float>(axis[k]);
      node.cone_angle = round_up(angle);
    }
    mNodes[self] = node;
  }

  const Mesh& mMesh;
  const std::vector<Vec3>& mNormals;
  std::vector<std::uint32_t> mOrder;
  std::vector<Vec3> mCentroids;
  std::vector<BvhNode> mNodes;
  std::vector<BvhBox> mBoxes;
  std::vector<Vec3> mNormalSums;
};

std::vector<Vec3> face_normals(const Mesh& mesh) {
  std::vector<Vec3> normals(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 n = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]]).cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
    const double len = n.norm();
    normals[t] = (len > 0.0 && std::isfinite(len)) ? Vec3(n / len) : Vec3::Zero();
  }
  return normals;
}

/// Triangles that share a vertex position (vertices welded by exact equality, so files that repeat
/// vertices per face, like STL, still get their topology).
void vertex_adjacency(const Mesh& mesh, std::vector<std::uint32_t>& offsets, std::vector<std::uint32_t>& adjacency) {
  const std::size_t nv = mesh.vertices.size();
  std::vector<std::uint32_t> order(nv);
  std::iota(order.begin(), order.end(), 0u);
  const auto less = [&](std::uint32_t a, std::uint32_t b) {
    const Vec3& p = mesh.vertices[a];
    const Vec3& q = mesh.vertices[b];
    if (p.x() != q.x()) return p.x() < q.x();
    if (p.y() != q.y()) return p.y() < q.y();
    if (p.z() != q.z()) return p.z() < q.z();
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<std::uint32_t> weld(nv);
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < nv; ++i) {
    if (i > 0 && mesh.vertices[order[i]] != mesh.vertices[order[i - 1]]) ++next;
    weld[order[i]] = next;
  }
  const std::uint32_t nw = nv == 0 ? 0 : next + 1;
  // Triangles around each welded vertex (CSR).
  std::vector<std::uint32_t> start(nw + 1, 0);
  for (const auto& tri : mesh.triangles) {
    for (const std::uint32_t v : tri) ++start[weld[v] + 1];
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint32_t> incident(start.back());
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const std::uint32_t v : mesh.triangles[t]) incident[fill[weld[v]]++] = t;
  }
  offsets.assign(mesh.triangles.size() + 1, 0);
  adjacency.clear();
  std::vector<std::uint32_t> around;
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    around.clear();
    for (const std::uint32_t v : mesh.triangles[t]) {
      const std::uint32_t w = weld[v];
      for (std::uint32_t k = start[w]; k < start[w + 1]; ++k) {
        if (incident[k] != t) around.push_back(incident[k]);
      }
    }
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end()), around.end());
    adjacency.insert(adjacency.end(), around.begin(), around.end());
    offsets[t + 1] = static_cast<std::uint32_t>(adjacency.size());
  }
}

}  // namespace

std::shared_ptr<const Model> build_model(Mesh mesh, const BuildOptions& options) {
  validate_mesh(mesh);
  auto model = std::make_shared<Model>();
  model->normals = face_normals(mesh);
  Builder builder(mesh, model->normals);
  builder.build(model->nodes, model->boxes, model->height);
  double extent = 0.0;
  for (const auto& tri : mesh.triangles) {
    for (const std::uint32_t v : tri) extent = std::max(extent, mesh.vertices[v].norm());
  }
  model->extent = extent;
  if (options.adjacency) vertex_adjacency(mesh, model->adjacency_offsets, model->adjacency);
  model->mesh = std::move(mesh);
  return model;
}

}  // namespace caliber
