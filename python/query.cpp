// caliber.query and caliber.Result: one pair of models at one pose each, its answer as numpy
// arrays made on first read. caliber.query is also reached through CPython's vectorcall
// (fast_call.h), for a call a planner makes millions of times.

#include "bounded_errors.h"
#include "common.h"
#include "fast_call.h"

namespace caliber_python {

PyResult::Arrays PyResult::make_arrays() {
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
  std::vector<caliber::Contact>().swap(contacts);  // (`= {}` would clear, not free)
  return r;
}

PyResult to_result(std::vector<caliber::Contact> contacts, const caliber::QueryStats& stats, bool limit_reached,
                   caliber::QueryKind kind) {
  PyResult r;
  r.rows = contacts.size();
  r.contacts = std::move(contacts);
  r.node_tests = stats.node_tests;
  r.leaf_tests = stats.leaf_tests;
  r.limit_reached = limit_reached;
  r.kind = kind;
  return r;
}

namespace {

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
  return to_result(std::move(q.contacts), q.stats, q.limit_reached, request.kind);
}

/// The pybind11 function caliber.query (run_query), which query_fastcall calls for what it does
/// not take (fast_call.h).
PyObject* g_query = nullptr;

/// caliber.query called by vectorcall: run_query on arguments of the common types, read here.
PyObject* query_fastcall(PyObject*, PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames) {
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
  if (result == nullptr) bound_type_error(args, nargs, kwnames);
  return result;
}

PyMethodDef g_query_def{
    "query", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(&query_fastcall)), METH_FASTCALL | METH_KEYWORDS,
    "query(a, pose_a, b, pose_b, kind='interference', tolerance=None, angle=30.0, max_pairs=0, *, lowest_ids=False)\n--\n\n"
    "One pair: kind is 'interference', 'proximity', 'contact' or 'distance' (the closest pair: one row, or none "
    "beyond the tolerance; no tolerance: any distance). max_pairs > 0 stops at that many pairs and sets "
    "limit_reached (1: any pair). Distance on intersecting meshes: the first hit (the pair max_pairs=1 stops at) "
    "(the lowest ids on models with at most 16 triangle pairs), or with lowest_ids=True the lowest ids at "
    "distance 0 (slower). Returns a caliber.Result."};

std::string result_repr(const PyResult& r) {
  std::string what = std::string(caliber::to_string(r.kind)) + ", " + count_of(r.rows, "pair") + ", " +
                     count_of(r.node_tests, "node test") + ", " + count_of(r.leaf_tests, "leaf test");
  if (r.limit_reached) what += ", limit reached";
  return (what);
}

void bind_result(py::module_& m) {
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
      .def_property_readonly(
          "kind", [](const PyResult& r) { return std::string(caliber::to_string(r.kind)); }, "the query kind that found them")
      .def_readonly("node_tests", &PyResult::node_tests)
      .def_readonly("limit_reached", &PyResult::limit_reached)
      .def_readonly("leaf_tests", &PyResult::leaf_tests)
      .def("__len__", [](const PyResult& r) { return r.rows; })
      .def("__repr__", repr_of<PyResult>("Result", &result_repr))
      .def("__reduce__", [](const PyResult&) -> py::object { throw not_picklable("Result", "pickle its arrays"); });
}

}  // namespace

void bind_query(py::module_& m) {
  bind_result(m);
  std::apply(
      [&](auto&&... request) {
        m.def("query", &run_query, py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"), request..., py::kw_only(),
              py::arg("lowest_ids") = false);
      },
      request_args());
  g_query = fast::stand_in(m, g_query_def);
}

}  // namespace caliber_python
