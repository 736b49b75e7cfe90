// What the viewer and the exports draw of a step.

#include "step_geometry.h"

#include <Eigen/Geometry>

namespace caliber::cli {

std::vector<ShownContact> shown_contacts(const World& world, const StepResult& step, const std::vector<Pose>& poses) {
  std::vector<ShownContact> out;
  out.reserve(step.contacts.size());
  const bool points = world.request().kind != QueryKind::interference;
  for (const Contact& c : step.contacts) {
    ShownContact s{c.object_a, c.object_b, c.point_a, c.normal};
    if (!points) {
      const Model& model = world.model(c.object_a);
      const Pose& pose = poses[c.object_a];
      const auto& t = model.mesh().triangles[c.tri_a];
      const auto& v = model.mesh().vertices;
      s.point = pose.apply((v[t[0]] + v[t[1]] + v[t[2]]) / 3.0);
      s.normal = pose.rotation * model.normals()[c.tri_a];
    }
    out.push_back(s);
  }
  return out;
}

ShownBox node_box(const Model& model, std::uint32_t node, const Pose& pose) {
  const NodeBox box = caliber::node_box(model, node);
  return ShownBox{pose.apply(box.center), box.half, pose.rotation_matrix()};
}

std::vector<std::pair<std::uint32_t, int>> nodes_to_depth(const Model& model, int depth) {
  std::vector<std::pair<std::uint32_t, int>> out;
  if (model.node_count() == 0 || depth < 0) return out;
  std::vector<std::uint32_t> level{0};
  for (int d = 0; d <= depth && !level.empty(); ++d) {
    std::vector<std::uint32_t> next;
    for (const std::uint32_t i : level) {
      out.emplace_back(i, d);
      const NodeBox box = caliber::node_box(model, i);
      next.insert(next.end(), box.children, box.children + box.child_count);
    }
    level = std::move(next);
  }
  return out;
}

std::vector<Eigen::Vector3d> box_corners(const ShownBox& box) {
  std::vector<Eigen::Vector3d> corners;
  for (int i = 0; i < 8; ++i) {
    Eigen::Vector3d local(i & 1 ? box.half.x() : -box.half.x(), i & 2 ? box.half.y() : -box.half.y(),
                          i & 4 ? box.half.z() : -box.half.z());
    corners.push_back(box.center + box.axes * local);
  }
  return corners;
}

}  // namespace caliber::cli
