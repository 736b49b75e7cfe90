// caliber::Model's read-only accessors: a view of the layout build_model made (bvh/model_data.h).

#include "bvh/model_data.h"

#include <string>

#include "caliber/error.h"

namespace caliber {

const Mesh& Model::mesh() const { return data(*this).mesh; }
const std::vector<Eigen::Vector3d>& Model::normals() const { return data(*this).normals; }
std::size_t Model::triangle_count() const { return data(*this).mesh.triangles.size(); }
std::size_t Model::node_count() const { return data(*this).nodes.size(); }
int Model::height() const { return data(*this).height; }
double Model::extent() const { return data(*this).extent; }
bool Model::has_adjacency() const { return data(*this).has_adjacency(); }
bool Model::has_oriented_boxes() const { return !data(*this).oriented_boxes.empty(); }

std::size_t Model::memory_bytes() const {
  const ModelData& m = data(*this);
  const auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
  return bytes(m.mesh.vertices) + bytes(m.mesh.triangles) + bytes(m.mesh.groups) + bytes(m.normals) + bytes(m.nodes) +
         bytes(m.wide) + bytes(m.filters) + bytes(m.laterals) + bytes(m.group_masks) + bytes(m.oriented_boxes) +
         bytes(m.leaf_position) + bytes(m.corner_vertex) + bytes(m.vertex_offsets) + bytes(m.vertex_triangles);
}

NodeBox node_box(const Model& model, std::uint32_t node) {
  const ModelData& m = data(model);
  if (node >= m.nodes.size()) {
    throw Error(ErrorCode::bad_index, "node_box",
                "node " + std::to_string(node) + " but the model has " + std::to_string(m.nodes.size()));
  }
  const BvhNode& n = m.nodes[node];
  NodeBox box;
  box.center = m.origin + Eigen::Vector3d(n.box_center[0], n.box_center[1], n.box_center[2]);
  box.half = Eigen::Vector3d(n.box_half[0], n.box_half[1], n.box_half[2]);
  if (!n.is_leaf()) {
    box.children[0] = n.index;
    box.children[1] = n.index + 1;
    box.child_count = 2;
  }
  return box;
}

}  // namespace caliber
