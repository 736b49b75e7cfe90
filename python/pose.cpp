// caliber.Pose: a rigid transform from a translation and a quaternion (in either order) or a
// matrix; pickled as its values, checked when unpickled.

#include <cmath>

#include "common.h"

namespace caliber_python {
namespace {

caliber::Pose pose_from_matrix(const py::array& m) {
  const char kind = m.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw caliber::Error(caliber::ErrorCode::bad_argument, "matrix",
                         "must hold real numbers, not dtype " + std::string(py::str(m.dtype())));
  }
  const double tolerance = rotation_tolerance(m);
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

std::array<double, 3> translation_of(const caliber::Pose& p) { return {p.translation.x(), p.translation.y(), p.translation.z()}; }

std::array<double, 4> quaternion_of(const caliber::Pose& p) {
  return {p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z()};
}

py::array_t<double> matrix_of(const caliber::Pose& p) {
  py::array_t<double> out({py::ssize_t{4}, py::ssize_t{4}});
  auto o = out.mutable_unchecked<2>();
  const Eigen::Matrix3d r = p.rotation_matrix();
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) o(i, j) = i < 3 ? (j < 3 ? r(i, j) : p.translation[i]) : (j == 3 ? 1.0 : 0.0);
  }
  return out;
}

/// "caliber.Pose((x, y, z), (w, x, y, z))": the call that makes the same pose.
std::string pose_repr(const caliber::Pose& p) {
  const auto t = translation_of(p);
  const auto q = quaternion_of(p);
  return "caliber.Pose((" + float_text(t[0]) + ", " + float_text(t[1]) + ", " + float_text(t[2]) + "), (" + float_text(q[0]) +
         ", " + float_text(q[1]) + ", " + float_text(q[2]) + ", " + float_text(q[3]) + "))";
}

}  // namespace

void bind_pose(py::module_& m) {
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
      .def_property_readonly("translation", &translation_of)
      .def_property_readonly("quaternion", &quaternion_of, "the unit quaternion (w, x, y, z)")
      .def(
          "as_quaternion",
          [](const caliber::Pose& p, const std::string& order) {
            const std::array<double, 4> q = quaternion_of(p);
            if (parse_order(order) == caliber::QuaternionOrder::wxyz) return q;
            return std::array<double, 4>{q[1], q[2], q[3], q[0]};
          },
          py::arg("order"), "the unit quaternion in `order`, 'wxyz' or 'xyzw'")
      .def("matrix", &matrix_of)
      .def("__repr__", repr_of<caliber::Pose>("Pose", &pose_repr, false))
      .def("__reduce__", [](const caliber::Pose& p) {
        return rebuilt_by("_pose_from_state", py::make_tuple(translation_of(p), quaternion_of(p)));
      });
  m.def("_checked_pose", &pose_from_state);
}

}  // namespace caliber_python
