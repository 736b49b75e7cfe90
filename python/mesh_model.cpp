// caliber.Mesh and caliber.Model: meshes from files or numpy arrays, models built once and
// pickled as their mesh (the BVH built again when unpickled).

#include <limits>
#include <span>

#include "common.h"

namespace caliber_python {
namespace {

using Vertices = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Faces = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

caliber::Mesh mesh_from_arrays(const Vertices& vertices, const Faces& faces) {
  if (vertices.ndim() != 2 || vertices.shape(1) != 3)
    throw caliber::Error(caliber::ErrorCode::bad_argument, "vertices", "must be an n x 3 array");
  if (faces.ndim() != 2 || faces.shape(1) != 3)
    throw caliber::Error(caliber::ErrorCode::bad_argument, "faces", "must be an m x 3 array");
  // Both arrays are C-contiguous (the casters' c_style): the library's checks do the rest.
  const std::span<const double> xyz(vertices.data(), static_cast<std::size_t>(vertices.size()));
  const std::span<const std::int64_t> indices(faces.data(), static_cast<std::size_t>(faces.size()));
  return caliber::mesh_from_buffers(xyz, indices, "arrays");
}

/// Refuses a uint64 face index past the int64 range the library reads indices in, naming its value
/// as given (cast, 2^64 - 1 would read as -1). Smaller indices are checked by the library.
void check_wide_indices(const py::array& vertices, const py::array& faces) {
  if (faces.dtype().kind() != 'u' || faces.itemsize() != 8 || faces.ndim() != 2 || faces.shape(1) != 3) return;
  if (vertices.ndim() != 2 || vertices.shape(1) != 3) return;  // refused by mesh_from_arrays first
  const auto wide = faces.cast<py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>>();
  const std::uint64_t* data = wide.data();
  for (py::ssize_t i = 0; i < wide.size(); ++i) {
    if (data[i] > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
      throw caliber::Error(caliber::ErrorCode::bad_index, "arrays",
                           "face " + std::to_string(i / 3) + " refers to vertex " + std::to_string(data[i]) +
                               " but there are only " + std::to_string(vertices.shape(0)));
    }
  }
}

/// A mesh from the arrays a user hands in: faces must hold integers and vertices real numbers
/// (float or integer); a float, bool or complex face array, or a bool or complex vertex array, is
/// refused rather than cast (0.9 would become vertex 0).
caliber::Mesh mesh_from_user_arrays(const py::object& vertex_data, const py::object& face_data) {
  const py::array vertices = py::array::ensure(vertex_data), faces = py::array::ensure(face_data);
  if (!vertices) throw caliber::Error(caliber::ErrorCode::bad_argument, "vertices", "must be an n x 3 array");
  if (!faces) throw caliber::Error(caliber::ErrorCode::bad_argument, "faces", "must be an m x 3 array");
  const char vk = vertices.dtype().kind(), fk = faces.dtype().kind();
  if (vk != 'f' && vk != 'i' && vk != 'u') {
    throw caliber::Error(caliber::ErrorCode::bad_argument, "vertices",
                         std::string("must hold real numbers, not dtype ") + py::str(vertices.dtype()).cast<std::string>());
  }
  if (fk != 'i' && fk != 'u') {
    throw caliber::Error(
        caliber::ErrorCode::bad_argument, "faces",
        std::string("must hold integer vertex indices, not dtype ") + py::str(faces.dtype()).cast<std::string>());
  }
  check_wide_indices(vertices, faces);
  return mesh_from_arrays(vertices.cast<Vertices>(), faces.cast<Faces>());
}

py::array_t<double> vertices_of(const caliber::Mesh& mesh) {
  py::array_t<double> out({static_cast<py::ssize_t>(mesh.vertices.size()), py::ssize_t{3}});
  auto o = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) o(static_cast<py::ssize_t>(i), k) = mesh.vertices[i][k];
  }
  return out;
}

py::array_t<std::int64_t> faces_of(const caliber::Mesh& mesh) {
  py::array_t<std::int64_t> out({static_cast<py::ssize_t>(mesh.triangles.size()), py::ssize_t{3}});
  auto o = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) o(static_cast<py::ssize_t>(i), k) = mesh.triangles[i][static_cast<std::size_t>(k)];
  }
  return out;
}

py::object model_state(const PyModel& p) {
  return py::make_tuple(vertices_of(p.model->mesh()), faces_of(p.model->mesh()), p.model->has_adjacency(),
                        p.model->has_oriented_boxes());
}

/// A Model from its pickled state (vertices, faces, adjacency[, oriented_boxes]): the arrays are
/// checked as Mesh(vertices, faces) checks them and the BVH is built again, so no tampered state
/// yields a model that was not built from a valid mesh.
PyModel model_from_state(const py::object& state) {
  const auto refuse = [](const std::string& why) {
    return caliber::Error(caliber::ErrorCode::bad_argument, "pickle", "not a caliber.Model state: " + why);
  };
  if (!py::isinstance<py::tuple>(state))
    throw refuse("expected a tuple, got " + std::string(py::str(state.get_type().attr("__name__"))));
  const auto t = state.cast<py::tuple>();
  if (t.size() != 3 && t.size() != 4) throw refuse("expected 3 or 4 items, got " + std::to_string(t.size()));
  for (std::size_t i = 2; i < t.size(); ++i) {
    if (!py::isinstance<py::bool_>(t[i])) throw refuse("item " + std::to_string(i) + " must be True or False");
  }
  caliber::BuildOptions options;
  options.adjacency = t[2].cast<bool>();
  options.oriented_boxes = t.size() == 4 && t[3].cast<bool>();
  caliber::Mesh mesh;
  try {
    mesh = mesh_from_user_arrays(t[0], t[1]);
  } catch (const caliber::Error& e) {
    throw refuse(e.what());
  }
  py::gil_scoped_release release;
  return PyModel{caliber::build_model(std::move(mesh), options)};
}

/// A model of `mesh`, built without the GIL.
PyModel built(caliber::Mesh mesh, bool adjacency, bool oriented_boxes) {
  caliber::BuildOptions options;
  options.adjacency = adjacency;
  options.oriented_boxes = oriented_boxes;
  py::gil_scoped_release release;
  return PyModel{caliber::build_model(std::move(mesh), options)};
}

std::string mesh_repr(const caliber::Mesh& mesh) {
  return count_of(mesh.vertices.size(), "vertex", "vertices") + ", " + count_of(mesh.triangles.size(), "triangle");
}

std::string model_repr(const PyModel& p) {
  std::string what = count_of(p.model->mesh().triangles.size(), "triangle") + ", BVH height " + std::to_string(p.model->height());
  if (p.model->has_adjacency()) what += ", adjacency";
  if (p.model->has_oriented_boxes()) what += ", oriented boxes";
  return what;
}

}  // namespace

void bind_mesh(py::module_& m) {
  py::class_<caliber::Mesh>(m, "Mesh", "Vertices (n x 3 float64) and triangles (m x 3 int); triangle ids are row numbers.")
      .def(py::init(&mesh_from_user_arrays), py::arg("vertices"), py::arg("faces"))
      .def_static(
          "load", [](const py::object& path) { return caliber::load_mesh(file_path(path)); }, py::arg("path"),
          "Reads .off, .ply, .obj or .stl (the extension chooses the reader).")
      .def_property_readonly("vertices", &vertices_of)
      .def_property_readonly("faces", &faces_of)
      .def("__len__", [](const caliber::Mesh& mesh) { return mesh.triangles.size(); })
      .def("__repr__", repr_of<caliber::Mesh>("Mesh", &mesh_repr))
      .def("__reduce__",
           [](const caliber::Mesh& mesh) { return rebuilt_by("Mesh", py::make_tuple(vertices_of(mesh), faces_of(mesh))); });
}

void bind_model(py::module_& m) {
  py::class_<PyModel>(m, "Model", py::module_local(),
                      "A mesh with its BVH, built once; immutable, shareable between threads, picklable.")
      .def(py::init([](const caliber::Mesh& mesh, bool adjacency, bool oriented_boxes) {
             return built(mesh, adjacency, oriented_boxes);
           }),
           py::arg("mesh"), py::arg("adjacency") = true, py::arg("oriented_boxes") = false,
           "adjacency: for contact queries; oriented_boxes: kept per node (120 bytes each), for faster distance queries")
      .def_static(
          "load",
          [](const py::object& path, bool adjacency, bool oriented_boxes) {
            return built(caliber::load_mesh(file_path(path)), adjacency, oriented_boxes);
          },
          py::arg("path"), py::arg("adjacency") = true, py::arg("oriented_boxes") = false)
      .def_property_readonly("mesh", [](const PyModel& p) { return p.model->mesh(); })
      .def_property_readonly("triangles", [](const PyModel& p) { return p.model->mesh().triangles.size(); })
      .def_property_readonly("height", [](const PyModel& p) { return p.model->height(); })
      .def_property_readonly(
          "oriented_boxes", [](const PyModel& p) { return p.model->has_oriented_boxes(); },
          "whether each node's oriented box is kept (for faster distance queries)")
      .def("__repr__", repr_of<PyModel>("Model", &model_repr))
      .def(py::pickle(&model_state, &model_from_state))
      .def("__reduce__", [](const PyModel& p) { return rebuilt_by("_model_from_state", py::make_tuple(model_state(p))); });
  m.def("_checked_model", &model_from_state);
}

}  // namespace caliber_python
