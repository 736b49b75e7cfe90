// caliber.sweep and caliber.Sweep, caliber.Sweeps: the swept query of one pair along one motion,
// and the answers of many (Engine.sweep_many) as numpy arrays.

#include "common.h"

namespace caliber_python {
namespace {

const char* status_text(caliber::SweepStatus status) {
  return status == caliber::SweepStatus::contact ? "contact" : status == caliber::SweepStatus::free ? "free" : "undecided";
}

std::string sweep_repr(const caliber::SweepResult& s) {
  std::string what = status_text(s.status);
  if (s.status == caliber::SweepStatus::contact) {
    what += " at t=" + float_text(s.time) + ", pair (" + std::to_string(s.closest.tri_a) + ", " +
            std::to_string(s.closest.tri_b) + ")";
  } else if (s.status == caliber::SweepStatus::undecided) {
    what += ", free up to t=" + float_text(s.time);
  }
  return (what + ", " + count_of(s.queries, "query", "queries"));
}

std::string sweeps_repr(const PySweeps& s) {
  const auto n = static_cast<std::size_t>(s.time.shape(0));
  std::size_t contacts = 0, undecided = 0;
  for (std::size_t i = 0; i < n; ++i) {
    contacts += s.contact.data()[i] ? 1 : 0;
    undecided += s.undecided.data()[i] ? 1 : 0;
  }
  return (count_of(n, "motion") + ", " + count_of(contacts, "contact") + ", " + std::to_string(undecided) + " undecided");
}

py::object when_contact(const caliber::SweepResult& s, py::object value) {
  return s.status == caliber::SweepStatus::contact ? std::move(value) : py::none();
}

void bind_sweep_result(py::module_& m) {
  py::class_<caliber::SweepResult>(m, "Sweep", py::module_local(),
                                   "The answer of sweep: status 'contact', 'free' or 'undecided'; time (contact: the first "
                                   "time of contact t*; free: 1; undecided: free up to it); at a contact the closest "
                                   "triangle pair there, its distance and points.")
      .def_property_readonly("status", [](const caliber::SweepResult& s) { return status_text(s.status); })
      .def_readonly("time", &caliber::SweepResult::time)
      .def_readonly("queries", &caliber::SweepResult::queries)
      .def_property_readonly(
          "pair", [](const caliber::SweepResult& s) { return when_contact(s, py::make_tuple(s.closest.tri_a, s.closest.tri_b)); })
      .def_property_readonly("distance",
                             [](const caliber::SweepResult& s) { return when_contact(s, py::float_(s.closest.distance)); })
      .def_property_readonly("points",
                             [](const caliber::SweepResult& s) {
                               const Eigen::Vector3d &a = s.closest.point_a, &b = s.closest.point_b;
                               return when_contact(
                                   s, py::make_tuple(py::make_tuple(a.x(), a.y(), a.z()), py::make_tuple(b.x(), b.y(), b.z())));
                             })
      .def("__repr__", repr_of<caliber::SweepResult>("Sweep", &sweep_repr))
      .def("__reduce__", [](const caliber::SweepResult&) -> py::object { throw not_picklable("Sweep", "pickle its fields"); });
}

}  // namespace

void bind_sweep(py::module_& m) {
  bind_sweep_result(m);
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
  bind_sweeps(m, [] {
    return not_picklable("Sweeps", "pickle its arrays");
  }).def("__repr__", repr_of<PySweeps>("Sweeps", &sweeps_repr));
}

}  // namespace caliber_python
