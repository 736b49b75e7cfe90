// Python bindings (pybind11): meshes from files or numpy arrays, models that pickle, poses, the
// three query kinds with numpy results, and the parallel engine over in-memory frames or scenes.
// Every query and step releases the GIL, so Python threads can query at once.

#include <pybind11/eval.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <dlfcn.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "caliber/caliber.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "batch.h"
#include "bounded_errors.h"
#include "fast_call.h"
#include "interrupts.h"
#include "sweeps.h"
#include "half_built.h"

namespace py = pybind11;

namespace {

using Vertices = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Faces = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

/// A path as the file system has it: str (undecodable bytes as surrogate escapes, as os.listdir
/// gives them), bytes or any os.PathLike, through os.fsencode; so a file whose name is not UTF-8
/// can be named, and its name reaches messages as written (escaped there by caliber::Error).
std::string file_path(const py::object& path) {
  py::object encoded;
  try {
    encoded = py::module_::import("os").attr("fsencode")(path);
  } catch (const py::error_already_set&) {
    throw caliber::Error(
        caliber::ErrorCode::bad_argument, "path",
        "must be a str, bytes or os.PathLike, not " + py::str(path.get_type().attr("__name__")).cast<std::string>());
  }
  std::string bytes = encoded.cast<std::string>();
  // The file is opened by a C string, which would end at the NUL: another file.
  if (bytes.find('\0') != std::string::npos) throw caliber::Error(caliber::ErrorCode::bad_argument, "path", "holds a NUL byte");
  return bytes;
}

/// N real numbers (`name`: a translation, a quaternion): a list or tuple of N numbers (Python
/// floats and ints, numpy reals, anything with __float__), or an array of N real numbers (a row,
/// a column). Complex numbers, bools and strings are refused, not converted: an imaginary part is
/// not dropped, True is not 1.
template <std::size_t N>
std::array<double, N> reals(const py::object& given, const char* name) {
  const auto refuse = [&](const std::string& what) {
    return caliber::Error(caliber::ErrorCode::bad_argument, name, "must be " + std::to_string(N) + " real numbers, not " + what);
  };
  std::array<double, N> out{};
  if (PyList_Check(given.ptr()) != 0 || PyTuple_Check(given.ptr()) != 0) {
    if (py::len(given) != N) throw refuse(std::to_string(py::len(given)) + " items");
    static const py::object numpy_bool = py::module_::import("numpy").attr("bool_");
    static const py::object numpy_complex = py::module_::import("numpy").attr("complexfloating");
    for (std::size_t i = 0; i < N; ++i) {
      PyObject* item = PySequence_Fast_GET_ITEM(given.ptr(), static_cast<Py_ssize_t>(i));
      const py::handle h(item);
      const std::string type = py::str(h.get_type().attr("__name__"));
      if (PyBool_Check(item) != 0 || py::isinstance(h, numpy_bool) || PyComplex_Check(item) != 0 ||
          py::isinstance(h, numpy_complex) || PyUnicode_Check(item) != 0 || PyBytes_Check(item) != 0) {
        throw refuse("a " + type);
      }
      out[i] = PyFloat_AsDouble(item);  // floats, ints, numpy reals, Decimal, Fraction: their __float__
      if (out[i] == -1.0 && PyErr_Occurred() != nullptr) {
        PyErr_Clear();
        throw refuse("a " + type);
      }
    }
    return out;
  }
  const py::array a = py::array::ensure(given);
  const char kind = a ? a.dtype().kind() : 'O';
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw refuse(a ? "dtype " + std::string(py::str(a.dtype())) : std::string(py::str(given.get_type().attr("__name__"))));
  }
  if (a.size() != static_cast<py::ssize_t>(N) || a.ndim() > 2) {
    throw refuse("an array of " + std::to_string(a.size()) + " in " + std::to_string(a.ndim()) + " dimensions");
  }
  const py::array_t<double, py::array::c_style | py::array::forcecast> values(a);
  std::copy_n(values.data(), N, out.begin());
  return out;
}

/// One flag per object (`fixed`): each True or False (a numpy bool too), or an integer 0 or 1
/// (Python's or numpy's); an empty list for none. Anything else is refused, not converted by its
/// truth value.
std::vector<bool> flags_of(const py::object& given, const char* name) {
  if (given.is_none()) return {};
  if (py::isinstance<py::str>(given) || !py::isinstance<py::sequence>(given)) {
    throw caliber::Error(caliber::ErrorCode::bad_argument, name, "must be a list of True or False, one per object");
  }
  const auto seq = py::reinterpret_borrow<py::sequence>(given);
  std::vector<bool> out;
  out.reserve(seq.size());
  static const py::object numpy_bool = py::module_::import("numpy").attr("bool_");
  static const py::object numpy_integer = py::module_::import("numpy").attr("integer");
  for (std::size_t i = 0; i < seq.size(); ++i) {
    const py::object item = seq[i];
    if (PyBool_Check(item.ptr()) != 0 || py::isinstance(item, numpy_bool)) {
      out.push_back(PyObject_IsTrue(item.ptr()) == 1);
    } else if ((PyLong_Check(item.ptr()) != 0 || py::isinstance(item, numpy_integer)) &&
               (item.equal(py::int_(0)) || item.equal(py::int_(1)))) {
      out.push_back(item.equal(py::int_(1)));
    } else {
      throw caliber::Error(caliber::ErrorCode::bad_argument, std::string(name) + "[" + std::to_string(i) + "]",
                           "must be True or False, not " + py::str(item.get_type().attr("__name__")).cast<std::string>());
    }
  }
  return out;
}

/// A built model, shared (the C++ side holds it as shared_ptr<const Model>).
struct PyModel {
  std::shared_ptr<const caliber::Model> model;
};

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

/// `tolerance` None: 0, or for a distance query, any distance (caliber::kUnbounded).
caliber::QueryRequest make_request(const std::string& kind, std::optional<double> tolerance, double angle,
                                   std::size_t max_pairs = 0, bool lowest_ids = false) {
  caliber::QueryRequest request;
  request.max_pairs = max_pairs;
  request.lowest_ids = lowest_ids;
  request.kind = caliber::parse_query_kind(kind);
  request.tolerance = tolerance ? *tolerance : request.kind == caliber::QueryKind::distance ? caliber::kUnbounded : 0.0;
  request.angle_deg = angle;
  caliber::validate_request(request);
  return request;
}

/// A query's or a step's answer: the contacts as numpy arrays (one row per reported triangle pair),
/// made on the first read of any of them (a query that answers "no" builds none; a planner that
/// reads only len() or limit_reached builds none either). The contacts are let go once copied.
struct PyResult {
  std::vector<caliber::Contact> contacts;  ///< until the arrays are made
  std::size_t rows = 0;
  std::uint64_t node_tests = 0, leaf_tests = 0;
  bool limit_reached = false;  ///< more than max_pairs were found: a partial answer

  struct Arrays {
    py::array_t<std::uint32_t> objects;               ///< k x 2 object ids (steps only)
    py::array_t<std::uint32_t> pairs;                 ///< k x 2 triangle ids
    py::array_t<double> points_a, points_b, normals;  ///< k x 3 (zero for interference)
    py::array_t<double> distances;                    ///< k
    py::array_t<double> depths;                       ///< k: Contact::depth (intersecting pairs' penetration estimate)
  };
  std::optional<Arrays> arrays;

  const Arrays& get() {
    if (!arrays) arrays = make_arrays();
    return *arrays;
  }

 private:
  Arrays make_arrays() {
    const auto k = static_cast<py::ssize_t>(rows);
    Arrays r{py::array_t<std::uint32_t>({k, py::ssize_t{2}}),
             py::array_t<std::uint32_t>({k, py::ssize_t{2}}),
             py::array_t<double>({k, py::ssize_t{3}}),
             py::array_t<double>({k, py::ssize_t{3}}),
             py::array_t<double>({k, py::ssize_t{3}}),
             py::array_t<double>(k),
             py::array_t<double>(k)};
    auto obj = r.objects.mutable_unchecked<2>();
    auto tri = r.pairs.mutable_unchecked<2>();
    auto pa = r.points_a.mutable_unchecked<2>();
    auto pb = r.points_b.mutable_unchecked<2>();
    auto nn = r.normals.mutable_unchecked<2>();
    auto dd = r.distances.mutable_unchecked<1>();
    auto dp = r.depths.mutable_unchecked<1>();
    for (py::ssize_t i = 0; i < k; ++i) {
      const caliber::Contact& c = contacts[static_cast<std::size_t>(i)];
      obj(i, 0) = c.object_a;
      obj(i, 1) = c.object_b;
      tri(i, 0) = c.tri_a;
      tri(i, 1) = c.tri_b;
      for (int d = 0; d < 3; ++d) {
        pa(i, d) = c.point_a[d];
        pb(i, d) = c.point_b[d];
        nn(i, d) = c.normal[d];
      }
      dd(i) = c.distance;
      dp(i) = c.depth;
    }
    contacts = {};
    return r;
  }
};

PyResult to_result(std::vector<caliber::Contact> contacts, const caliber::QueryStats& stats) {
  PyResult r;
  r.rows = contacts.size();
  r.contacts = std::move(contacts);
  r.node_tests = stats.node_tests;
  r.leaf_tests = stats.leaf_tests;
  return r;
}

PyResult query_result(caliber::QueryResult&& q) {
  PyResult r = to_result(std::move(q.contacts), q.stats);
  r.limit_reached = q.limit_reached;
  return r;
}

caliber::Pose pose_from_matrix(const py::array& m) {
  const char kind = m.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw caliber::Error(caliber::ErrorCode::bad_argument, "matrix",
                         "must hold real numbers, not dtype " + std::string(py::str(m.dtype())));
  }
  const double tolerance = caliber_python::rotation_tolerance(m);
  const py::array_t<double, py::array::c_style | py::array::forcecast> d(m);
  if (d.ndim() != 2 || d.shape(0) != 4 || d.shape(1) != 4)
    throw caliber::Error(caliber::ErrorCode::bad_argument, "matrix", "must be 4 x 4");
  const auto a = d.unchecked<2>();
  Eigen::Matrix4d matrix;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) matrix(i, j) = a(i, j);
  }
  return caliber::Pose::from_matrix(matrix, tolerance, "matrix");
}

/// The quaternion (w, x, y, z) of `q` given in `order` ("wxyz", caliber's and Eigen's; "xyzw",
/// scipy's and ROS's).
std::array<double, 4> quaternion_wxyz(const std::array<double, 4>& q, const std::string& order) {
  if (order == "wxyz") return q;
  if (order == "xyzw") return {q[3], q[0], q[1], q[2]};
  throw caliber::Error(caliber::ErrorCode::bad_value, "order", "must be 'wxyz' or 'xyzw', not '" + order + "'");
}

caliber::Frame make_frame(const std::vector<PyModel>& models, const std::vector<caliber::Pose>& poses,
                          const std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs,
                          const caliber::QueryRequest& request) {
  caliber::Frame frame;
  for (const PyModel& m : models) frame.models.push_back(m.model);
  frame.poses = poses;
  for (const auto& [a, b] : pairs) frame.pairs.push_back(caliber::ObjectPair{a, b});
  frame.request = request;
  return frame;
}

py::object model_state(const PyModel& p) {
  return py::make_tuple(vertices_of(p.model->mesh()), faces_of(p.model->mesh()), p.model->has_adjacency(),
                        p.model->has_oriented_boxes());
}

/// How pickle rebuilds an object: `function` of module caliber called with `args`. Every picklable
/// class defines __reduce__ this way, so that every protocol (0 and 1 included, where pybind11's
/// default would abort the interpreter) gives a pickle that unpickles through a checked function.
py::tuple rebuilt_by(const char* function, py::tuple args) {
  return py::make_tuple(py::module_::import("caliber").attr(function), std::move(args));
}

caliber::Error not_picklable(const char* name, const std::string& instead) {
  return caliber::Error(caliber::ErrorCode::bad_argument, name, std::string("cannot be pickled: ") + instead);
}

/// A Pose from its pickled state: the same checks as Pose(translation, quaternion), and the
/// quaternion kept exactly as pickled (it was unit to rounding when pickled).
caliber::Pose pose_from_state(const std::array<double, 3>& t, const std::array<double, 4>& q) {
  caliber::Pose pose = caliber::Pose::from_values(t[0], t[1], t[2], q[0], q[1], q[2], q[3], "pickle");
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(std::abs(norm - 1.0) <= 1e-12))
    throw caliber::Error(caliber::ErrorCode::bad_argument, "pickle", "not a caliber.Pose state: the quaternion is not unit");
  pose.rotation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  return pose;
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

/// Engine.query_many and caliber.query_many: the poses read (errors naming the side and row), then
/// the batch with the GIL released once.
caliber_python::PyBatch query_many(caliber::Engine& engine, const PyModel& a, const py::object& poses_a, const PyModel& b,
                                   const py::object& poses_b, const caliber::QueryRequest& request, const std::string& order) {
  const caliber::QuaternionOrder o = caliber_python::parse_order(order);
  const caliber_python::SidePoses pa(poses_a, o, "poses_a"), pb(poses_b, o, "poses_b");
  caliber::BatchResult result;
  double ms = 0.0;
  {
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    result = engine.query_many(*a.model, pa.poses, *b.model, pb.poses, request);
    ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  caliber_python::PyBatch batch(result);
  batch.batch_ms = ms;
  return batch;
}

caliber::SweepRequest sweep_request(double tolerance, std::uint64_t max_queries) {
  caliber::SweepRequest request;
  request.tolerance = tolerance;
  request.max_queries = max_queries;
  return request;
}

/// A side's motions from its start and end poses (each as SidePoses reads them), the same count.
std::vector<caliber::SweptPose> motions_of(const caliber_python::SidePoses& start, const caliber_python::SidePoses& end,
                                           const char* side) {
  if (start.poses.size() != end.poses.size()) {
    throw caliber::Error(caliber::ErrorCode::bad_argument, std::string("end_") + side,
                         std::to_string(end.poses.size()) + " poses but start_" + side + " has " +
                             std::to_string(start.poses.size()) + " (a side's start and end give one pose per motion)");
  }
  std::vector<caliber::SweptPose> out(start.poses.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {start.poses[i], end.poses[i]};
  return out;
}

caliber_python::PySweeps sweep_many(caliber::Engine& engine, const PyModel& a, const py::object& start_a, const py::object& end_a,
                                    const PyModel& b, const py::object& start_b, const py::object& end_b, double tolerance,
                                    std::uint64_t max_queries, const std::string& order) {
  const caliber::QuaternionOrder o = caliber_python::parse_order(order);
  const std::vector<caliber::SweptPose> ma = motions_of({start_a, o, "start_a"}, {end_a, o, "end_a"}, "a");
  const std::vector<caliber::SweptPose> mb = motions_of({start_b, o, "start_b"}, {end_b, o, "end_b"}, "b");
  if (ma.size() != mb.size() && ma.size() != 1 && mb.size() != 1) {
    throw caliber::Error(caliber::ErrorCode::bad_argument, "start_b",
                         std::to_string(mb.size()) + " motions but start_a gives " + std::to_string(ma.size()) +
                             " (give both sides the same number, or one motion to a side that moves the same in every row)");
  }
  const caliber::SweepRequest request = sweep_request(tolerance, max_queries);
  std::vector<caliber::SweepResult> results;
  double ms = 0.0;
  {
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    results = engine.sweep_many(*a.model, ma, *b.model, mb, request);
    ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  caliber_python::PySweeps sweeps(results);
  sweeps.sweep_ms = ms;
  return sweeps;
}

/// caliber.query.
PyResult run_query(const PyModel& a, const caliber::Pose& pose_a, const PyModel& b, const caliber::Pose& pose_b,
                   const std::string& kind, std::optional<double> tolerance, double angle, std::size_t max_pairs,
                   bool lowest_ids) {
  const caliber::QueryRequest request = make_request(kind, tolerance, angle, max_pairs, lowest_ids);
  caliber::QueryResult q;
  {
    py::gil_scoped_release release;
    q = caliber::query(*a.model, pose_a, *b.model, pose_b, request);
  }
  return query_result(std::move(q));
}

/// The pybind11 function caliber.query (run_query), which query_fastcall calls for what it does
/// not take (fast_call.h).
PyObject* g_query = nullptr;

/// caliber.query called by vectorcall: run_query on arguments of the common types, read here.
PyObject* query_fastcall(PyObject*, PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames) {
  namespace fast = caliber_python::fast;
  static constexpr std::array<const char*, 9> kNames{"a",         "pose_a", "b",         "pose_b",    "kind",
                                                     "tolerance", "angle",  "max_pairs", "lowest_ids"};
  std::array<PyObject*, 9> v{};
  try {
    if (fast::gather(args, nargs, kwnames, kNames, 8, v) && v[0] != nullptr && v[1] != nullptr && v[2] != nullptr &&
        v[3] != nullptr) {
      const PyModel* a = fast::as_bound<PyModel>(v[0]);
      const PyModel* b = fast::as_bound<PyModel>(v[2]);
      const caliber::Pose* pose_a = fast::as_bound<caliber::Pose>(v[1]);
      const caliber::Pose* pose_b = fast::as_bound<caliber::Pose>(v[3]);
      std::string_view kind = "interference";
      std::optional<double> tolerance;
      double angle = 30.0;
      std::size_t max_pairs = 0;
      bool lowest_ids = false;
      if (a != nullptr && b != nullptr && pose_a != nullptr && pose_b != nullptr && a->model && b->model &&
          (v[4] == nullptr || fast::as_string(v[4], kind)) && (v[5] == nullptr || fast::as_optional_double(v[5], tolerance)) &&
          (v[6] == nullptr || fast::as_double(v[6], angle)) && (v[7] == nullptr || fast::as_size(v[7], max_pairs)) &&
          (v[8] == nullptr || fast::as_bool(v[8], lowest_ids))) {
        return py::cast(run_query(*a, *pose_a, *b, *pose_b, std::string(kind), tolerance, angle, max_pairs, lowest_ids))
            .release()
            .ptr();
      }
    }
  } catch (...) {  // raised again, with its message, by the pybind11 function below
  }
  PyObject* result = PyObject_Vectorcall(g_query, args, static_cast<std::size_t>(nargs), kwnames);
  if (result == nullptr) caliber_python::bound_type_error(args, nargs, kwnames);
  return result;
}

PyMethodDef g_query_def{
    "query", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(&query_fastcall)), METH_FASTCALL | METH_KEYWORDS,
    "query(a, pose_a, b, pose_b, kind='interference', tolerance=None, angle=30.0, max_pairs=0, *, lowest_ids=False)\n--\n\n"
    "One pair: kind is 'interference', 'proximity', 'contact' or 'distance' (the closest pair: one row, or none "
    "beyond the tolerance; no tolerance: any distance). max_pairs > 0 stops past that many pairs and sets "
    "limit_reached (1: any pair). Distance on intersecting meshes: the first intersecting pair of the traversal, "
    "or with lowest_ids=True the lowest ids at distance 0 (slower). Returns a caliber.Result."};

}  // namespace

CALIBER_REFUSE_HALF_BUILT(caliber::Mesh, "Mesh")
CALIBER_REFUSE_HALF_BUILT(PyModel, "Model")
CALIBER_REFUSE_HALF_BUILT(caliber::Pose, "Pose")
CALIBER_REFUSE_HALF_BUILT(PyResult, "Result")
CALIBER_REFUSE_HALF_BUILT(caliber::Engine, "Engine")
CALIBER_REFUSE_HALF_BUILT(caliber::World, "World")
CALIBER_REFUSE_HALF_BUILT(caliber_python::PyBatch, "Batch")
CALIBER_REFUSE_HALF_BUILT(caliber_python::PySweeps, "Sweeps")
CALIBER_REFUSE_HALF_BUILT(caliber::SweepResult, "Sweep")

PYBIND11_MODULE(caliber, m) {
  m.doc() = "caliber: exact collision detection between rigid triangle meshes, parallelized by task calibration";
  m.attr("__version__") = caliber::kVersion;
  static py::exception<caliber::Error> error(m, "Error", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const caliber::Error& e) {
      error(e.what());
    }
  });

  py::class_<caliber::Mesh>(m, "Mesh", "Vertices (n x 3 float64) and triangles (m x 3 int); triangle ids are row numbers.")
      .def(py::init(&mesh_from_user_arrays), py::arg("vertices"), py::arg("faces"))
      .def_static(
          "load", [](const py::object& path) { return caliber::load_mesh(file_path(path)); }, py::arg("path"),
          "Reads .off, .ply, .obj or .stl (the extension chooses the reader).")
      .def_property_readonly("vertices", &vertices_of)
      .def_property_readonly("faces", &faces_of)
      .def("__len__", [](const caliber::Mesh& mesh) { return mesh.triangles.size(); })
      .def("__reduce__",
           [](const caliber::Mesh& mesh) { return rebuilt_by("Mesh", py::make_tuple(vertices_of(mesh), faces_of(mesh))); });

  py::class_<PyModel>(m, "Model", py::module_local(),
                      "A mesh with its BVH, built once; immutable, shareable between threads, picklable.")
      .def(py::init([](const caliber::Mesh& mesh, bool adjacency, bool oriented_boxes) {
             caliber::BuildOptions options;
             options.adjacency = adjacency;
             options.oriented_boxes = oriented_boxes;
             py::gil_scoped_release release;
             return PyModel{caliber::build_model(mesh, options)};
           }),
           py::arg("mesh"), py::arg("adjacency") = true, py::arg("oriented_boxes") = false,
           "adjacency: for contact queries; oriented_boxes: kept per node (120 bytes each), for faster distance queries")
      .def_static(
          "load",
          [](const py::object& path, bool adjacency, bool oriented_boxes) {
            caliber::Mesh mesh = caliber::load_mesh(file_path(path));
            caliber::BuildOptions options;
            options.adjacency = adjacency;
            options.oriented_boxes = oriented_boxes;
            py::gil_scoped_release release;
            return PyModel{caliber::build_model(std::move(mesh), options)};
          },
          py::arg("path"), py::arg("adjacency") = true, py::arg("oriented_boxes") = false)
      .def_property_readonly("mesh", [](const PyModel& p) { return p.model->mesh(); })
      .def_property_readonly("triangles", [](const PyModel& p) { return p.model->mesh().triangles.size(); })
      .def_property_readonly("height", [](const PyModel& p) { return p.model->height(); })
      .def_property_readonly(
          "oriented_boxes", [](const PyModel& p) { return p.model->has_oriented_boxes(); },
          "whether each node's oriented box is kept (for faster distance queries)")
      .def(py::pickle(&model_state, &model_from_state))
      .def("__reduce__", [](const PyModel& p) { return rebuilt_by("_model_from_state", py::make_tuple(model_state(p))); });

  py::class_<caliber::Pose>(m, "Pose", py::module_local(), "A rigid transform: x_world = R x + t.")
      .def(py::init([](const py::object& translation, const py::object& quaternion, const std::string& order) {
             const std::array<double, 3> t = reals<3>(translation, "translation");
             const std::array<double, 4> q = quaternion_wxyz(reals<4>(quaternion, "quaternion"), order);
             return caliber::Pose::from_values(t[0], t[1], t[2], q[0], q[1], q[2], q[3]);
           }),
           py::arg("translation") = py::make_tuple(0.0, 0.0, 0.0), py::arg("quaternion") = py::make_tuple(1.0, 0.0, 0.0, 0.0),
           py::kw_only(), py::arg("order") = "wxyz",
           "translation (x, y, z), quaternion normalized, in `order`: 'wxyz' (the default, Eigen's) or 'xyzw' (scipy's "
           "Rotation.as_quat() and ROS's)")
      .def_static(
          "from_quaternion",
          [](const py::object& quaternion, const std::string& order, const py::object& translation) {
            const std::array<double, 4> q = quaternion_wxyz(reals<4>(quaternion, "quaternion"), order);
            const std::array<double, 3> t = reals<3>(translation, "translation");
            return caliber::Pose::from_values(t[0], t[1], t[2], q[0], q[1], q[2], q[3], "quaternion");
          },
          py::arg("quaternion"), py::arg("order"), py::arg("translation") = py::make_tuple(0.0, 0.0, 0.0),
          "from a quaternion in an explicit order, 'wxyz' or 'xyzw' (scipy's and ROS's), and a translation")
      .def_static("from_matrix", &pose_from_matrix, py::arg("matrix"),
                  "from a 4 x 4 rigid transform; its rotation must be orthonormal within 1e-9 (float64) or 1e-6 (float32)")
      .def_property_readonly("translation",
                             [](const caliber::Pose& p) {
                               return std::array<double, 3>{p.translation.x(), p.translation.y(), p.translation.z()};
                             })
      .def_property_readonly(
          "quaternion",
          [](const caliber::Pose& p) {
            return std::array<double, 4>{p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z()};
          },
          "the unit quaternion (w, x, y, z)")
      .def(
          "as_quaternion",
          [](const caliber::Pose& p, const std::string& order) {
            const std::array<double, 4> q{p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z()};
            if (order == "wxyz") return q;
            if (order == "xyzw") return std::array<double, 4>{q[1], q[2], q[3], q[0]};
            throw caliber::Error(caliber::ErrorCode::bad_value, "order", "must be 'wxyz' or 'xyzw', not '" + order + "'");
          },
          py::arg("order"), "the unit quaternion in `order`, 'wxyz' or 'xyzw'")
      .def("matrix",
           [](const caliber::Pose& p) {
             py::array_t<double> out({py::ssize_t{4}, py::ssize_t{4}});
             auto o = out.mutable_unchecked<2>();
             const Eigen::Matrix3d r = p.rotation_matrix();
             for (int i = 0; i < 4; ++i) {
               for (int j = 0; j < 4; ++j) o(i, j) = i < 3 ? (j < 3 ? r(i, j) : p.translation[i]) : (j == 3 ? 1.0 : 0.0);
             }
             return out;
           })
      .def("__reduce__", [](const caliber::Pose& p) {
        const std::array<double, 3> t{p.translation.x(), p.translation.y(), p.translation.z()};
        const std::array<double, 4> q{p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z()};
        return rebuilt_by("_pose_from_state", py::make_tuple(t, q));
      });
  // caliber's pure-Python modules (caliber.distributed) sit in the folder caliber/ beside this
  // file: with that folder as the module's __path__, `import caliber.distributed` finds them.
  if (Dl_info info{}; dladdr(reinterpret_cast<const void*>(&model_state), &info) != 0 && info.dli_fname != nullptr) {
    py::list path;
    path.append((std::filesystem::path(info.dli_fname).parent_path() / "caliber").string());
    m.attr("__path__") = path;
  }
  m.def("_checked_model", &model_from_state);
  m.def("_checked_pose", &pose_from_state);
  // What pickles name to rebuild a Model or a Pose: Python functions of module caliber (pickle
  // cannot name a pybind11 function at protocols 0 and 1), calling the checked builders above.
  py::exec(R"(
def _model_from_state(state):
    """How a pickled Model is rebuilt: its state checked, its BVH built again."""
    return _checked_model(state)

def _pose_from_state(translation, quaternion):
    """How a pickled Pose is rebuilt: its values checked."""
    return _checked_pose(translation, quaternion)

def _batch_from_state(state):
    """How a pickled Batch is rebuilt: its arrays checked against its offsets."""
    return _checked_batch(state)
)",
           m.attr("__dict__"));

  py::class_<PyResult>(m, "Result", py::module_local(),
                       "Reported triangle pairs, sorted, with points, normals and distances (zero for interference).")
      .def_property_readonly(
          "objects", [](PyResult& r) { return r.get().objects; }, "k x 2 object ids (steps; 0 and 1 for a query)")
      .def_property_readonly(
          "pairs", [](PyResult& r) { return r.get().pairs; }, "k x 2 triangle ids")
      .def_property_readonly(
          "points_a", [](PyResult& r) { return r.get().points_a; }, "k x 3 closest points on A (world)")
      .def_property_readonly(
          "points_b", [](PyResult& r) { return r.get().points_b; }, "k x 3 closest points on B (world)")
      .def_property_readonly(
          "normals", [](PyResult& r) { return r.get().normals; }, "k x 3 contact normals (world)")
      .def_property_readonly(
          "distances", [](PyResult& r) { return r.get().distances; }, "k distances (0: intersecting)")
      .def_property_readonly(
          "depths", [](PyResult& r) { return r.get().depths; }, "k penetration estimates of intersecting pairs")
      .def_readonly("node_tests", &PyResult::node_tests)
      .def_readonly("limit_reached", &PyResult::limit_reached)
      .def_readonly("leaf_tests", &PyResult::leaf_tests)
      .def("__len__", [](const PyResult& r) { return r.rows; })
      .def("__reduce__", [](const PyResult&) -> py::object { throw not_picklable("Result", "pickle its arrays"); });

  m.def("query", &run_query, py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"), py::arg("kind") = "interference",
        py::arg("tolerance") = py::none(), py::arg("angle") = 30.0, py::arg("max_pairs") = 0, py::kw_only(),
        py::arg("lowest_ids") = false);
  g_query = caliber_python::fast::stand_in(m, g_query_def);

  py::class_<caliber::SweepResult>(m, "Sweep", py::module_local(),
                                   "The answer of sweep: status 'contact', 'free' or 'undecided'; time (contact: the first "
                                   "time of contact t*; free: 1; undecided: free up to it); at a contact the closest "
                                   "triangle pair there, its distance and points.")
      .def_property_readonly("status",
                             [](const caliber::SweepResult& s) {
                               return s.status == caliber::SweepStatus::contact ? "contact"
                                      : s.status == caliber::SweepStatus::free  ? "free"
                                                                                : "undecided";
                             })
      .def_readonly("time", &caliber::SweepResult::time)
      .def_readonly("queries", &caliber::SweepResult::queries)
      .def_property_readonly("pair",
                             [](const caliber::SweepResult& s) -> py::object {
                               if (s.status != caliber::SweepStatus::contact) return py::none();
                               return py::make_tuple(s.closest.tri_a, s.closest.tri_b);
                             })
      .def_property_readonly("distance",
                             [](const caliber::SweepResult& s) -> py::object {
                               if (s.status != caliber::SweepStatus::contact) return py::none();
                               return py::float_(s.closest.distance);
                             })
      .def_property_readonly("points",
                             [](const caliber::SweepResult& s) -> py::object {
                               if (s.status != caliber::SweepStatus::contact) return py::none();
                               const Eigen::Vector3d &a = s.closest.point_a, &b = s.closest.point_b;
                               return py::make_tuple(py::make_tuple(a.x(), a.y(), a.z()), py::make_tuple(b.x(), b.y(), b.z()));
                             })
      .def("__reduce__", [](const caliber::SweepResult&) -> py::object { throw not_picklable("Sweep", "pickle its fields"); });
  m.def(
      "sweep",
      [](const PyModel& a, const caliber::Pose& start_a, const caliber::Pose& end_a, const PyModel& b,
         const caliber::Pose& start_b, const caliber::Pose& end_b, double tolerance, std::uint64_t max_queries) {
        const caliber::SweepRequest request = sweep_request(tolerance, max_queries);
        py::gil_scoped_release release;
        return caliber::sweep(*a.model, {start_a, end_a}, *b.model, {start_b, end_b}, request);
      },
      py::arg("a"), py::arg("start_a"), py::arg("end_a"), py::arg("b"), py::arg("start_b"), py::arg("end_b"), py::kw_only(),
      py::arg("tolerance") = 0.0, py::arg("max_queries") = 100000,
      "The first time t in [0, 1] at which a, moving from start_a to end_a, and b, from start_b to end_b (translation "
      "linear, rotation by slerp), come within tolerance (0: 1e-6 of the larger model's radius): never later than the "
      "first true contact, never a missed contact (docs/queries.md). Returns a Sweep.");
  caliber_python::bind_sweeps(m, [] { return not_picklable("Sweeps", "pickle its arrays"); });
  m.def(
      "sweep_many",
      [](const PyModel& a, const py::object& start_a, const py::object& end_a, const PyModel& b, const py::object& start_b,
         const py::object& end_b, double tolerance, std::uint64_t max_queries, const std::string& order, int threads) {
        caliber::EngineOptions options;
        options.threads = threads;
        caliber::Engine engine(caliber_python::interruptible(options));
        return sweep_many(engine, a, start_a, end_a, b, start_b, end_b, tolerance, max_queries, order);
      },
      py::arg("a"), py::arg("start_a"), py::arg("end_a"), py::arg("b"), py::arg("start_b"), py::arg("end_b"), py::kw_only(),
      py::arg("tolerance") = 0.0, py::arg("max_queries") = 100000, py::arg("order") = "wxyz", py::arg("threads") = 0,
      "Engine(threads=threads).sweep_many(...): the swept query along many motions, in parallel, without the GIL. "
      "Returns Sweeps.");

  caliber_python::bind_batch(m);
  m.def(
      "query_many",
      [](const PyModel& a, const py::object& poses_a, const PyModel& b, const py::object& poses_b, const std::string& kind,
         std::optional<double> tolerance, double angle, std::size_t max_pairs, const std::string& order, int threads,
         bool lowest_ids) {
        const caliber::QueryRequest request = make_request(kind, tolerance, angle, max_pairs, lowest_ids);
        caliber::EngineOptions options;
        options.threads = threads;
        caliber::Engine engine(caliber_python::interruptible(options));
        return query_many(engine, a, poses_a, b, poses_b, request, order);
      },
      py::arg("a"), py::arg("poses_a"), py::arg("b"), py::arg("poses_b"), py::arg("kind") = "interference",
      py::arg("tolerance") = py::none(), py::arg("angle") = 30.0, py::arg("max_pairs") = 0, py::kw_only(),
      py::arg("order") = "wxyz", py::arg("threads") = 0, py::arg("lowest_ids") = false,
      "Engine(threads=threads).query_many(...): model a against model b at many poses, in parallel, the GIL released "
      "once. Returns a Batch: per entry hit, distance, limit_reached; per reported pair a row with its entry.");

  py::class_<caliber::Engine>(m, "Engine",
                              "The parallel engine: a method on the threads the process allows; keeps temporal state.")
      .def(py::init([](const std::string& method, int threads) {
             caliber::EngineOptions options;
             options.method = caliber::parse_method(method);
             options.threads = threads;
             return std::make_unique<caliber::Engine>(caliber_python::interruptible(options));
           }),
           py::arg("method") = std::string(caliber::to_string(caliber::kDefaultMethod)), py::arg("threads") = 0,
           "method: sequential, exploitation, stealing (the default), aposteriori, apriori or hybrid. threads: 0, every "
           "hardware thread the process may use (oneTBB's arena and limit); 1, the calling thread alone; N, at most N.")
      .def_property_readonly("threads", &caliber::Engine::threads)
      .def("__reduce__",
           [](const caliber::Engine&) -> py::object {
             throw not_picklable("Engine", "it holds temporal state and threads; make a new Engine where it is needed");
           })
      .def("forget", &caliber::Engine::forget)
      .def(
          "query_many",
          [](caliber::Engine& engine, const PyModel& a, const py::object& poses_a, const PyModel& b, const py::object& poses_b,
             const std::string& kind, std::optional<double> tolerance, double angle, std::size_t max_pairs,
             const std::string& order, bool lowest_ids) {
            return query_many(engine, a, poses_a, b, poses_b, make_request(kind, tolerance, angle, max_pairs, lowest_ids), order);
          },
          py::arg("a"), py::arg("poses_a"), py::arg("b"), py::arg("poses_b"), py::arg("kind") = "interference",
          py::arg("tolerance") = py::none(), py::arg("angle") = 30.0, py::arg("max_pairs") = 0, py::kw_only(),
          py::arg("order") = "wxyz", py::arg("lowest_ids") = false,
          "Model a against model b at many poses, on this engine's threads: entry i is query(a, poses_a[i], b, poses_b[i], "
          "...) bit for bit. Each side is one Pose (kept for every entry), a list of Poses, or an array of N x 4 x 4 "
          "matrices or N x 7 rows (translation, then the quaternion in `order`: 'wxyz' or 'xyzw'), float32 or float64. "
          "Returns a Batch.")
      .def(
          "sweep_many",
          [](caliber::Engine& engine, const PyModel& a, const py::object& start_a, const py::object& end_a, const PyModel& b,
             const py::object& start_b, const py::object& end_b, double tolerance, std::uint64_t max_queries,
             const std::string& order) {
            return sweep_many(engine, a, start_a, end_a, b, start_b, end_b, tolerance, max_queries, order);
          },
          py::arg("a"), py::arg("start_a"), py::arg("end_a"), py::arg("b"), py::arg("start_b"), py::arg("end_b"), py::kw_only(),
          py::arg("tolerance") = 0.0, py::arg("max_queries") = 100000, py::arg("order") = "wxyz",
          "The swept query along many motions, on this engine's threads: row i is sweep(a, start_a[i], end_a[i], b, "
          "start_b[i], end_b[i], ...) bit for bit. Each of the four is one Pose, a list of Poses, or an array of N x 4 x 4 "
          "matrices or N x 7 rows (translation, then the quaternion in `order`); a side's start and end give the same "
          "number, and a side of one motion keeps it for every row. Heavy sweeps' queries are split across threads when "
          "few are left. Returns Sweeps.")
      .def(
          "find_pairs",
          [](caliber::Engine& engine, const std::vector<PyModel>& models, const std::vector<caliber::Pose>& poses,
             const std::string& kind, std::optional<double> tolerance, const py::object& fixed_flags,
             const std::vector<std::pair<std::uint32_t, std::uint32_t>>& ignored) {
            const std::vector<bool> fixed = flags_of(fixed_flags, "fixed");
            caliber::Frame frame = make_frame(models, poses, {}, make_request(kind, tolerance, 30.0, 0, false));
            std::vector<caliber::ObjectPair> skip;
            for (const auto& [a, b] : ignored) skip.push_back(caliber::ObjectPair{a, b});
            {
              py::gil_scoped_release release;
              engine.find_pairs(frame, fixed, skip);
            }
            std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
            out.reserve(frame.pairs.size());
            for (const caliber::ObjectPair& p : frame.pairs) out.emplace_back(p.a, p.b);
            return out;
          },
          py::arg("models"), py::arg("poses"), py::arg("kind") = "interference", py::arg("tolerance") = py::none(), py::kw_only(),
          py::arg("fixed") = py::list(), py::arg("ignored") = std::vector<std::pair<std::uint32_t, std::uint32_t>>{},
          "The broad phase on this engine's threads: the object pairs (a < b, sorted) whose world boxes overlap within "
          "the query's reach (its tolerance for kind 'distance' or 'contact'), what step() takes. The same pairs as "
          "broad_phase(); the engine keeps its tree of boxes from call to call (refitted), so calls on the same objects "
          "moving a little are cheaper. fixed: one flag per object (pairs of two fixed objects skipped); ignored: pairs "
          "never reported.")
      .def(
          "sweep",
          [](caliber::Engine& engine, const std::vector<PyModel>& models, const std::vector<caliber::Pose>& start,
             const std::vector<caliber::Pose>& end, double tolerance, std::uint64_t max_queries, const py::object& fixed_flags,
             const std::vector<std::pair<std::uint32_t, std::uint32_t>>& ignored) {
            const std::vector<bool> fixed = flags_of(fixed_flags, "fixed");
            std::vector<std::shared_ptr<const caliber::Model>> shared;
            shared.reserve(models.size());
            for (const PyModel& m : models) shared.push_back(m.model);
            std::vector<caliber::ObjectPair> skip;
            for (const auto& [a, b] : ignored) skip.push_back(caliber::ObjectPair{a, b});
            const caliber::SweepRequest request = sweep_request(tolerance, max_queries);
            std::vector<caliber::PairSweep> swept;
            {
              py::gil_scoped_release release;
              swept = engine.sweep(shared, start, end, request, fixed, skip);
            }
            py::list out;
            for (const caliber::PairSweep& p : swept) out.append(py::make_tuple(py::make_tuple(p.pair.a, p.pair.b), p.result));
            return out;
          },
          py::arg("models"), py::arg("start"), py::arg("end"), py::kw_only(), py::arg("tolerance") = 0.0,
          py::arg("max_queries") = 100000, py::arg("fixed") = py::list(),
          py::arg("ignored") = std::vector<std::pair<std::uint32_t, std::uint32_t>>{},
          "Continuous collision detection for many objects: object i moves from start[i] to end[i] (translation linear, "
          "rotation by slerp); every pair whose swept boxes overlap is swept (caliber.sweep), in parallel on this engine's "
          "threads. Returns [((a, b), Sweep)] for the pairs that are not free, sorted.")
      .def(
          "step",
          [](caliber::Engine& engine, const std::vector<PyModel>& models, const std::vector<caliber::Pose>& poses,
             const std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs, const std::string& kind,
             std::optional<double> tolerance, double angle, std::size_t max_pairs, bool lowest_ids) {
            const caliber::Frame frame =
                make_frame(models, poses, pairs, make_request(kind, tolerance, angle, max_pairs, lowest_ids));
            caliber::StepResult s;
            {
              py::gil_scoped_release release;
              s = engine.step(frame);
            }
            PyResult r = to_result(std::move(s.contacts), s.stats);
            r.limit_reached = s.limit_reached;
            return r;
          },
          py::arg("models"), py::arg("poses"), py::arg("pairs"), py::arg("kind") = "interference",
          py::arg("tolerance") = py::none(), py::arg("angle") = 30.0, py::arg("max_pairs") = 0, py::kw_only(),
          py::arg("lowest_ids") = false,
          "One frame: every listed object pair (a < b, sorted) tested. max_pairs > 0 stops each object pair past that many "
          "triangle pairs and sets limit_reached (1: does each pair touch at all?).");

  m.def(
      "broad_phase",
      [](const std::vector<PyModel>& models, const std::vector<caliber::Pose>& poses, double reach, const py::object& fixed_flags,
         const std::vector<std::pair<std::uint32_t, std::uint32_t>>& ignored) {
        const std::vector<bool> fixed = flags_of(fixed_flags, "fixed");
        std::vector<std::shared_ptr<const caliber::Model>> shared;
        for (const PyModel& m : models) shared.push_back(m.model);
        std::vector<caliber::ObjectPair> skip;
        for (const auto& [a, b] : ignored) skip.push_back(caliber::ObjectPair{a, b});
        std::vector<caliber::ObjectPair> pairs;
        {
          py::gil_scoped_release release;
          pairs = caliber::broad_phase(shared, poses, reach, fixed, skip);
        }
        std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
        out.reserve(pairs.size());
        for (const caliber::ObjectPair& p : pairs) out.emplace_back(p.a, p.b);
        return out;
      },
      py::arg("models"), py::arg("poses"), py::arg("reach") = 0.0, py::arg("fixed") = py::list(),
      py::arg("ignored") = std::vector<std::pair<std::uint32_t, std::uint32_t>>{},
      "The object pairs (a < b, sorted) whose world boxes, grown by reach / 2, overlap: what Engine.step takes. fixed: "
      "one flag per object (pairs of two fixed objects are skipped); ignored: pairs never tested.");

  py::class_<caliber::World>(m, "World", "A scene file's objects, poses and broad phase.")
      .def(py::init([](const py::object& path) {
             caliber::Scene scene = caliber::load_scene(file_path(path));
             py::gil_scoped_release release;
             return std::make_unique<caliber::World>(std::move(scene));
           }),
           py::arg("path"))
      .def_property_readonly("steps", [](const caliber::World& w) { return w.scene().steps; })
      .def_property_readonly("objects",
                             [](const caliber::World& w) {
                               std::vector<std::string> names;
                               for (const caliber::SceneObject& o : w.scene().objects) names.push_back(o.name);
                               return names;
                             })
      .def(
          "step",
          [](const caliber::World& world, caliber::Engine& engine, int k) {
            caliber::StepResult s;
            {
              py::gil_scoped_release release;
              s = caliber::step(world, engine, k);
            }
            PyResult r = to_result(std::move(s.contacts), s.stats);
            r.limit_reached = s.limit_reached;
            return r;
          },
          py::arg("engine"), py::arg("k"), "Step k: poses and broad phase, then the engine.")
      .def(
          "sweep",
          [](const caliber::World& world, caliber::Engine& engine, int k, double tolerance, std::uint64_t max_queries) {
            const caliber::SweepRequest request = sweep_request(tolerance, max_queries);
            std::vector<caliber::PairSweep> swept;
            {
              py::gil_scoped_release release;
              swept = world.sweep(k, engine, request);
            }
            py::list out;
            for (const caliber::PairSweep& p : swept) out.append(py::make_tuple(py::make_tuple(p.pair.a, p.pair.b), p.result));
            return out;
          },
          py::arg("engine"), py::arg("k"), py::kw_only(), py::arg("tolerance") = 0.0, py::arg("max_queries") = 100000,
          "The pairs that touch between step k and k + 1, following the scene's motions (cut where an object turns more "
          "than a quarter turn or has keys), with the scene's groups: [((a, b), Sweep)], times as fractions of the step.")
      .def("__reduce__", [](const caliber::World&) -> py::object {
        throw not_picklable("World", "load the scene file again where it is needed");
      });

  // No object is built twice (see half_built.h).
  caliber_python::refuse_second<caliber::Mesh>(m.attr("Mesh"), "__init__", "Mesh");
  caliber_python::refuse_second<PyModel>(m.attr("Model"), "__init__", "Model");
  caliber_python::refuse_second<PyModel>(m.attr("Model"), "__setstate__", "Model");
  caliber_python::refuse_second<caliber::Pose>(m.attr("Pose"), "__init__", "Pose");
  caliber_python::refuse_second<caliber::Engine>(m.attr("Engine"), "__init__", "Engine");
  caliber_python::refuse_second<caliber::World>(m.attr("World"), "__init__", "World");
  // Last: every public function and method, as now bound, raises TypeErrors of bounded length
  // (caliber.query bounds its own, above).
  caliber_python::bound_type_errors(m, {"query"});
}
