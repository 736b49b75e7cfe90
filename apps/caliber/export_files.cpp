// caliber run --export: PLY files of chosen steps (ASCII, coordinates with 17 significant digits so
// that they read back exactly).

#include "export_files.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "caliber/error.h"
#include "json_output.h"
#include "output_file.h"
#include "step_geometry.h"

namespace caliber::cli {
namespace {

/// The colour of object i (the viewer's hues): distinct for neighbouring ids.
void object_colour(std::size_t i, int rgb[3]) {
  static constexpr int kPalette[8][3] = {{230, 159, 0}, {86, 180, 233}, {0, 158, 115},   {240, 228, 66},
                                         {0, 114, 178}, {213, 94, 0},   {204, 121, 167}, {120, 120, 120}};
  for (int k = 0; k < 3; ++k) rgb[k] = kPalette[i % 8][k];
}

void put(std::ostream& out, const Eigen::Vector3d& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g", p.x(), p.y(), p.z());
  out << buf;
}

void write_objects(const World& world, const std::vector<Pose>& poses, int k, const std::string& path) {
  OutputFile file(path, "--export");
  std::ostream& out = file.stream();
  std::size_t vertices = 0, faces = 0;
  for (std::size_t i = 0; i < world.object_count(); ++i) {
    vertices += world.model(i).mesh().vertices.size();
    faces += world.model(i).mesh().triangles.size();
  }
  out << "ply\nformat ascii 1.0\ncomment caliber: scene " << line_text(world.scene().name) << ", step " << k
      << ", every object's mesh posed in the world frame; face property 'object' is the object id\n";
  for (std::size_t i = 0; i < world.object_count(); ++i)
    out << "comment object " << i << " " << line_text(world.scene().objects[i].name) << "\n";
  out << "element vertex " << vertices << "\nproperty double x\nproperty double y\nproperty double z\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      << "element face " << faces << "\nproperty list uchar uint vertex_indices\nproperty uint object\nend_header\n";
  for (std::size_t i = 0; i < world.object_count(); ++i) {
    int rgb[3];
    object_colour(i, rgb);
    for (const Eigen::Vector3d& v : world.model(i).mesh().vertices) {
      put(out, poses[i].apply(v));
      out << ' ' << rgb[0] << ' ' << rgb[1] << ' ' << rgb[2] << '\n';
    }
  }
  std::size_t base = 0;
  for (std::size_t i = 0; i < world.object_count(); ++i) {
    for (const auto& t : world.model(i).mesh().triangles)
      out << "3 " << base + t[0] << ' ' << base + t[1] << ' ' << base + t[2] << ' ' << i << '\n';
    base += world.model(i).mesh().vertices.size();
  }
  file.commit();
}

/// The diagonal of the box around every object at the step: normals are drawn 3 % of it long.
double scene_diagonal(const World& world, const std::vector<Pose>& poses) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
  for (std::size_t i = 0; i < world.object_count(); ++i) {
    const auto [a, b] = world.bounds(i, poses[i], 0.0);
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  }
  return world.object_count() > 0 ? (hi - lo).norm() : 1.0;
}

void write_contacts(const World& world, const StepResult& step, const std::vector<Pose>& poses, const std::string& path) {
  const std::vector<ShownContact> contacts = shown_contacts(world, step, poses);
  const double length = 0.03 * scene_diagonal(world, poses);
  OutputFile file(path, "--export");
  std::ostream& out = file.stream();
  out << "ply\nformat ascii 1.0\ncomment caliber: scene " << line_text(world.scene().name) << ", step " << step.step << ", "
      << to_string(world.request().kind) << " query: vertex 2k is contact k's point, vertex 2k+1 the end of its normal ("
      << length << " long); edge k joins them\n"
      << "element vertex " << 2 * contacts.size() << "\nproperty double x\nproperty double y\nproperty double z\n"
      << "element edge " << contacts.size() << "\nproperty int vertex1\nproperty int vertex2\n"
      << "property uint object_a\nproperty uint object_b\nend_header\n";
  for (const ShownContact& c : contacts) {
    put(out, c.point);
    out << '\n';
    put(out, c.point + length * c.normal);
    out << '\n';
  }
  for (std::size_t k = 0; k < contacts.size(); ++k)
    out << 2 * k << ' ' << 2 * k + 1 << ' ' << contacts[k].object_a << ' ' << contacts[k].object_b << '\n';
  file.commit();
}

void write_bvh(const World& world, const std::vector<Pose>& poses, int k, int depth, const std::string& path) {
  struct Box {
    ShownBox box;
    std::size_t object;
    int depth;
  };
  std::vector<Box> boxes;
  for (std::size_t i = 0; i < world.object_count(); ++i) {
    for (const auto& [node, d] : nodes_to_depth(world.model(i), depth))
      boxes.push_back({node_box(world.model(i), node, poses[i]), i, d});
  }
  OutputFile file(path, "--export");
  std::ostream& out = file.stream();
  out << "ply\nformat ascii 1.0\ncomment caliber: scene " << line_text(world.scene().name) << ", step " << k
      << ", the box of every BVH node down to depth " << depth << " (root: 0), posed; 8 vertices and 12 edges per box\n"
      << "element vertex " << 8 * boxes.size() << "\nproperty double x\nproperty double y\nproperty double z\n"
      << "element edge " << 12 * boxes.size() << "\nproperty int vertex1\nproperty int vertex2\n"
      << "property uint object\nproperty uint depth\nend_header\n";
  for (const Box& b : boxes) {
    for (const Eigen::Vector3d& c : box_corners(b.box)) {
      put(out, c);
      out << '\n';
    }
  }
  for (std::size_t n = 0; n < boxes.size(); ++n) {
    for (const auto& e : kBoxEdges)
      out << 8 * n + e[0] << ' ' << 8 * n + e[1] << ' ' << boxes[n].object << ' ' << boxes[n].depth << '\n';
  }
  file.commit();
}

}  // namespace

Exporter::~Exporter() {
  if (mCommitted) return;
  std::error_code ec;
  for (const std::string& file : mWritten) std::filesystem::remove(file, ec);
  for (const std::filesystem::path& folder : mMadeFolders) std::filesystem::remove(folder, ec);  // only if empty
}

Exporter::Exporter(ExportOptions options, int scene_steps) : mOptions(std::move(options)) {
  for (const int k : mOptions.steps) {
    if (k < 0 || k >= scene_steps) {
      throw Error(ErrorCode::bad_value, "--export-steps",
                  "step " + std::to_string(k) + " is outside the run's steps 0.." + std::to_string(scene_steps - 1));
    }
  }
  if (mOptions.bvh_depth < -1) throw Error(ErrorCode::bad_value, "--bvh-depth", "must be -1 (no BVH) or a depth >= 0");
  std::error_code ec;
  const std::filesystem::path dir(mOptions.dir);
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec)) {
    throw Error(ErrorCode::bad_value, mOptions.dir, "--export needs a folder, and this is a file");
  }
  // The folders this makes, deepest first (removed, if empty, after a failed run).
  for (std::filesystem::path p = dir; !p.empty() && !std::filesystem::exists(p, ec); p = p.parent_path()) {
    mMadeFolders.push_back(p);
    if (p == p.parent_path()) break;
  }
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(ErrorCode::bad_value, mOptions.dir, "--export: cannot create the folder (" + ec.message() + ")");
}

bool Exporter::wants(int k) const { return std::find(mOptions.steps.begin(), mOptions.steps.end(), k) != mOptions.steps.end(); }

namespace {
std::string stem(const ExportOptions& options, int k) {
  return (std::filesystem::path(options.dir) / ("step" + std::to_string(k))).string();
}
}  // namespace

std::vector<std::string> export_paths(const ExportOptions& options) {
  std::vector<std::string> paths;
  if (options.dir.empty()) return paths;
  for (const int k : options.steps) {
    paths.insert(paths.end(), {stem(options, k) + "_objects.ply", stem(options, k) + "_contacts.ply"});
    if (options.bvh_depth >= 0) paths.push_back(stem(options, k) + "_bvh.ply");
  }
  return paths;
}

void Exporter::write(const World& world, const StepResult& step) const {
  const std::vector<Pose> poses = world.poses_at(step.step);
  const std::string stem = cli::stem(mOptions, step.step);
  // Each file counted as written as soon as it is (a failure on the next removes it too).
  write_objects(world, poses, step.step, stem + "_objects.ply");
  mWritten.push_back(stem + "_objects.ply");
  write_contacts(world, step, poses, stem + "_contacts.ply");
  mWritten.push_back(stem + "_contacts.ply");
  if (mOptions.bvh_depth >= 0) {
    write_bvh(world, poses, step.step, mOptions.bvh_depth, stem + "_bvh.ply");
    mWritten.push_back(stem + "_bvh.ply");
  }
}

}  // namespace caliber::cli
