#pragma once
// Swept queries in Python along many motions (Engine.sweep_many): the answers as numpy arrays,
// one row per motion.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "caliber/sweep.h"
#include "readonly.h"

namespace caliber_python {

namespace py = pybind11;

/// The answers of Engine.sweep_many, a row per motion.
struct PySweeps {
  py::array_t<bool> contact;               ///< N: the models come within the tolerance at `time`
  py::array_t<bool> undecided;             ///< N: max_queries ran out (free up to `time`)
  py::array_t<double> time;                ///< N: t* at a contact, 1 when free, how far it got when undecided
  py::array_t<std::int64_t> pairs;         ///< N x 2: the closest triangle pair at t* (-1 when no contact)
  py::array_t<double> distance;            ///< N: its distance (inf when no contact)
  py::array_t<double> points_a, points_b;  ///< N x 3: its closest points at t*, world (nan when no contact)
  py::array_t<std::uint64_t> queries;      ///< N: the distance queries each sweep made
  std::uint64_t node_tests = 0, leaf_tests = 0;
  double sweep_ms = 0.0;  ///< wall time of the C++ call, without reading the poses or making these arrays

  explicit PySweeps(const std::vector<caliber::SweepResult>& results) {
    const auto n = static_cast<py::ssize_t>(results.size());
    contact = py::array_t<bool>(n);
    undecided = py::array_t<bool>(n);
    time = py::array_t<double>(n);
    pairs = py::array_t<std::int64_t>({n, py::ssize_t{2}});
    distance = py::array_t<double>(n);
    points_a = py::array_t<double>({n, py::ssize_t{3}});
    points_b = py::array_t<double>({n, py::ssize_t{3}});
    queries = py::array_t<std::uint64_t>(n);
    bool *const c = contact.mutable_data(), *const u = undecided.mutable_data();
    double *const t = time.mutable_data(), *const d = distance.mutable_data();
    double *const pa = points_a.mutable_data(), *const pb = points_b.mutable_data();
    std::int64_t* const tri = pairs.mutable_data();
    std::uint64_t* const q = queries.mutable_data();
    py::gil_scoped_release release;
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t i = 0; i < results.size(); ++i) {
      const caliber::SweepResult& r = results[i];
      const bool hit = r.status == caliber::SweepStatus::contact;
      c[i] = hit;
      u[i] = r.status == caliber::SweepStatus::undecided;
      t[i] = r.time;
      q[i] = r.queries;
      tri[2 * i] = hit ? static_cast<std::int64_t>(r.closest.tri_a) : -1;
      tri[2 * i + 1] = hit ? static_cast<std::int64_t>(r.closest.tri_b) : -1;
      d[i] = hit ? r.closest.distance : std::numeric_limits<double>::infinity();
      for (Eigen::Index k = 0; k < 3; ++k) {
        pa[3 * i + static_cast<std::size_t>(k)] = hit ? r.closest.point_a[k] : nan;
        pb[3 * i + static_cast<std::size_t>(k)] = hit ? r.closest.point_b[k] : nan;
      }
      node_tests += r.stats.node_tests;
      leaf_tests += r.stats.leaf_tests;
    }
  }
};

/// Registers caliber.Sweeps (its arrays read-only views), and returns the class; `refuse_pickle`
/// throws the module's not-picklable error.
template <class Refuse>
py::class_<PySweeps> bind_sweeps(py::module_& m, Refuse&& refuse_pickle) {
  return py::class_<PySweeps>(m, "Sweeps",
                              "The answers of sweep_many, a row per motion: contact, undecided, time (t* at a contact, 1 when "
                              "free), and at a contact the closest triangle pair, its distance and points.")
      .def_property_readonly("contact", view_of<PySweeps, &PySweeps::contact>,
                             "N bools: the models come within the tolerance at time")
      .def_property_readonly("undecided", view_of<PySweeps, &PySweeps::undecided>,
                             "N bools: max_queries ran out; free up to time, unknown after")
      .def_property_readonly("time", view_of<PySweeps, &PySweeps::time>,
                             "N: the first time of contact t*; 1 when free; how far it got when undecided")
      .def_property_readonly("pairs", view_of<PySweeps, &PySweeps::pairs>,
                             "N x 2 triangle ids of the closest pair at t* (-1 when no contact)")
      .def_property_readonly("distance", view_of<PySweeps, &PySweeps::distance>, "N: that pair's distance (inf when no contact)")
      .def_property_readonly("points_a", view_of<PySweeps, &PySweeps::points_a>,
                             "N x 3: its point on a at t*, world coordinates (nan when no contact)")
      .def_property_readonly("points_b", view_of<PySweeps, &PySweeps::points_b>,
                             "N x 3: its point on b at t* (nan when no contact)")
      .def_property_readonly("queries", view_of<PySweeps, &PySweeps::queries>, "N: the distance queries each sweep made")
      .def_readonly("node_tests", &PySweeps::node_tests)
      .def_readonly("leaf_tests", &PySweeps::leaf_tests)
      .def_readonly("sweep_ms", &PySweeps::sweep_ms,
                    "wall time of the C++ call in milliseconds, without reading the poses or making these arrays")
      .def("__len__", [](const PySweeps& s) { return static_cast<std::size_t>(s.time.shape(0)); })
      .def("__reduce__", [refuse_pickle](const PySweeps&) -> py::object { throw refuse_pickle(); });
}

}  // namespace caliber_python
