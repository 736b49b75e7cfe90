// caliber::Model's read-only accessors: a view of the layout build_model made (bvh/model_data.h).

#include "bvh/model_data.h"

namespace caliber {

const Mesh& Model::mesh() const { return data(*this).mesh; }
const std::vector<Eigen::Vector3d>& Model::normals() const { return data(*this).normals; }
std::size_t Model::triangle_count() const { return data(*this).mesh.triangles.size(); }
std::size_t Model::node_count() const { return data(*this).nodes.size(); }
int Model::height() const { return data(*this).height; }
double Model::extent() const { return data(*this).extent; }
bool Model::has_adjacency() const { return data(*this).has_adjacency(); }
bool Model::has_oriented_boxes() const { return !data(*this).oriented_boxes.empty(); }

}  // namespace caliber
