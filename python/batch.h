#pragma once
// Batch queries in Python: the poses of a side from numpy arrays (N x 4 x 4 matrices, N x 7
// translation + quaternion, float32 or float64) or from Pose objects, and a batch's answers as
// numpy arrays, one row per entry and one per reported triangle pair.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "caliber/batch.h"
#include "readonly.h"
#include "caliber/error.h"
#include "caliber/pose.h"

namespace caliber_python {

namespace py = pybind11;

/// A side's poses, as given: a Pose, a sequence of Poses, or an array of matrices (4 x 4 or
/// N x 4 x 4) or of translation + quaternion rows (7 or N x 7, the quaternion in `order`).
/// Matrices are checked to rotation_tolerance. Errors name `side` and the row.
/// The tolerance on a matrix's rotation: float32 arrays are rotations only to float32's rounding
/// (1e-6), others to 1e-9. By kind and size, not dtype identity (an unpickled array has its own).
inline double rotation_tolerance(const py::array& a) {
  return a.dtype().kind() == 'f' && a.dtype().itemsize() == 4 ? 1e-6 : 1e-9;
}

struct SidePoses {
  std::vector<caliber::Pose> poses;

  SidePoses(const py::object& given, caliber::QuaternionOrder order, const std::string& side) {
    if (py::isinstance<caliber::Pose>(given)) {
      poses.push_back(given.cast<caliber::Pose>());
      return;
    }
    // A list or tuple of Poses; an object with the buffer protocol (a memoryview, bytes) is read as
    // an array, like a numpy array.
    if (!py::isinstance<py::array>(given) && PyObject_CheckBuffer(given.ptr()) == 0 && py::isinstance<py::sequence>(given) &&
        !py::isinstance<py::str>(given)) {
      const auto seq = given.cast<py::sequence>();
      if (seq.size() == 0 || py::isinstance<caliber::Pose>(seq[0])) {
        for (std::size_t i = 0; i < seq.size(); ++i) {
          if (!py::isinstance<caliber::Pose>(seq[i])) {
            throw caliber::Error(caliber::ErrorCode::bad_argument, side + "[" + std::to_string(i) + "]",
                                 "must be a caliber.Pose like the items before it");
          }
          poses.push_back(seq[i].cast<caliber::Pose>());
        }
        return;
      }
    }
    const py::array raw = py::array::ensure(given);
    if (!raw || (raw.dtype().kind() != 'f' && raw.dtype().kind() != 'i' && raw.dtype().kind() != 'u')) {
      throw caliber::Error(caliber::ErrorCode::bad_argument, side,
                           "must be a caliber.Pose, a list of them, or an array of N x 4 x 4 matrices or N x 7 rows");
    }
    const double tolerance = rotation_tolerance(raw);
    const py::array_t<double, py::array::c_style | py::array::forcecast> values(raw);
    const std::span<const double> flat(values.data(), static_cast<std::size_t>(values.size()));
    const auto nd = values.ndim();
    const auto last = nd > 0 ? values.shape(nd - 1) : 0;
    py::gil_scoped_release release;
    if ((nd == 2 || nd == 3) && last == 4 && values.shape(nd - 2) == 4) {
      poses = caliber::poses_from_matrices(flat, tolerance, side);
    } else if ((nd == 1 || nd == 2) && last == 7) {
      poses = caliber::poses_from_vectors(flat, order, side);
    } else {
      throw caliber::Error(caliber::ErrorCode::bad_argument, side,
                           "an array of poses must be 4 x 4, N x 4 x 4, 7 or N x 7 (translation and quaternion)");
    }
  }
};

/// A batch's answers as numpy arrays.
struct PyBatch {
  py::array_t<std::int64_t> offsets;                ///< N + 1: entry i's rows are [offsets[i], offsets[i + 1])
  py::array_t<bool> hit;                            ///< N: the entry reported a pair
  py::array_t<bool> limit_reached;                  ///< N: the entry found max_pairs and stopped
  py::array_t<double> distance;                     ///< N: the entry's smallest reported distance (inf: none)
  py::array_t<std::uint32_t> pairs;                 ///< k x 2 triangle ids
  py::array_t<std::int64_t> entries;                ///< k: the entry each row belongs to
  py::array_t<double> points_a, points_b, normals;  ///< k x 3, world coordinates (zero for interference)
  py::array_t<double> distances, depths;            ///< k
  std::uint64_t node_tests = 0, leaf_tests = 0;
  double batch_ms = 0.0;  ///< wall time of the C++ batch (Engine::query_many), without the arrays' conversion

  PyBatch() = default;

  explicit PyBatch(const caliber::BatchResult& b) {
    // Interference reports ids only: its points, normals, distances and depths are zeros, made by
    // numpy.zeros (pages the system hands out zeroed) instead of copied row by row.
    const bool ids_only = b.kind == caliber::QueryKind::interference;
    allocate(static_cast<py::ssize_t>(b.size()), static_cast<py::ssize_t>(b.contacts.size()), ids_only);
    std::int64_t* const off = offsets.mutable_data();
    bool* const lr = limit_reached.mutable_data();
    std::uint32_t* const tri = pairs.mutable_data();
    double *const pa = points_a.mutable_data(), *const pb = points_b.mutable_data(), *const nn = normals.mutable_data();
    double *const dd = distances.mutable_data(), *const dp = depths.mutable_data();
    {
      py::gil_scoped_release release;
      for (std::size_t i = 0; i < b.offsets.size(); ++i) off[i] = static_cast<std::int64_t>(b.offsets[i]);
      for (std::size_t i = 0; i < b.size(); ++i) lr[i] = b.limit_reached[i] != 0;
      for (std::size_t r = 0; r < b.contacts.size(); ++r) {
        const caliber::Contact& c = b.contacts[r];
        tri[2 * r] = c.tri_a;
        tri[2 * r + 1] = c.tri_b;
        if (ids_only) continue;
        for (std::size_t d = 0; d < 3; ++d) {
          pa[3 * r + d] = c.point_a[static_cast<Eigen::Index>(d)];
          pb[3 * r + d] = c.point_b[static_cast<Eigen::Index>(d)];
          nn[3 * r + d] = c.normal[static_cast<Eigen::Index>(d)];
        }
        dd[r] = c.distance;
        dp[r] = c.depth;
      }
    }
    derive();
    node_tests = b.stats.node_tests;
    leaf_tests = b.stats.leaf_tests;
  }

  /// What pickle keeps: the arrays the others derive from, and the counters.
  [[nodiscard]] py::tuple state() const {
    // Copies: the Batch's own arrays never leave it (concatenate trusts their shapes).
    const auto copy = [](const py::array& a) { return a.attr("copy")(); };
    return py::make_tuple(copy(offsets), copy(limit_reached), copy(pairs), copy(points_a), copy(points_b), copy(normals),
                          copy(distances), copy(depths), node_tests, leaf_tests);
  }

  /// A Batch from its pickled state, every array checked (dtype converted, shape and offsets
  /// refused with caliber.Error when they do not fit together).
  static PyBatch from_state(const py::object& state) {
    const auto refuse = [](const std::string& why) {
      return caliber::Error(caliber::ErrorCode::bad_argument, "pickle", "not a caliber.Batch state: " + why);
    };
    if (!py::isinstance<py::tuple>(state) || py::len(state) != 10) throw refuse("expected a tuple of 10 items");
    const auto t = state.cast<py::tuple>();
    try {
      const auto off = array_of<std::int64_t>(t[0]);
      if (off.ndim() != 1 || off.shape(0) < 1) throw refuse("offsets must be N + 1 integers");
      const py::ssize_t n = off.shape(0) - 1;
      const std::int64_t* o = off.data();
      for (py::ssize_t i = 0; i < n; ++i) {
        if (o[i + 1] < o[i]) throw refuse("offsets must not decrease");
      }
      if (o[0] != 0) throw refuse("offsets must start at 0");
      const py::ssize_t k = static_cast<py::ssize_t>(o[n]);
      const auto dist = array_of<double>(t[6]);
      if (!dist || dist.ndim() != 1 || dist.shape(0) != k) throw refuse("distances must have offsets[-1] rows");
      PyBatch b;
      b.allocate(n, k);
      copy_checked(off, b.offsets, {n + 1}, "offsets", refuse);
      copy_checked(array_of<bool>(t[1]), b.limit_reached, {n}, "limit_reached", refuse);
      copy_checked(array_of<std::uint32_t>(t[2]), b.pairs, {k, 2}, "pairs", refuse);
      copy_checked(array_of<double>(t[3]), b.points_a, {k, 3}, "points_a", refuse);
      copy_checked(array_of<double>(t[4]), b.points_b, {k, 3}, "points_b", refuse);
      copy_checked(array_of<double>(t[5]), b.normals, {k, 3}, "normals", refuse);
      copy_checked(dist, b.distances, {k}, "distances", refuse);
      copy_checked(array_of<double>(t[7]), b.depths, {k}, "depths", refuse);
      b.node_tests = t[8].cast<std::uint64_t>();
      b.leaf_tests = t[9].cast<std::uint64_t>();
      b.derive();
      return b;
    } catch (const py::cast_error&) {
      throw refuse("the counters must be integers >= 0");
    } catch (const py::error_already_set& e) {
      throw refuse(std::string("an array could not be read: ") + e.what());
    }
  }

  /// The batches one after the other: one batch of all their entries, in order.
  static PyBatch concatenate(const std::vector<const PyBatch*>& parts) {
    py::ssize_t n = 0, k = 0;
    for (const PyBatch* p : parts) {
      n += p->hit.shape(0);
      k += p->distances.shape(0);
    }
    PyBatch b;
    b.allocate(n, k);
    py::ssize_t e = 0, r = 0;
    b.offsets.mutable_data()[0] = 0;
    for (const PyBatch* p : parts) {
      const py::ssize_t pn = p->hit.shape(0), pk = p->distances.shape(0);
      for (py::ssize_t i = 0; i < pn; ++i) b.offsets.mutable_data()[e + i + 1] = r + p->offsets.data()[i + 1];
      std::copy_n(p->limit_reached.data(), pn, b.limit_reached.mutable_data() + e);
      std::copy_n(p->pairs.data(), 2 * pk, b.pairs.mutable_data() + 2 * r);
      std::copy_n(p->points_a.data(), 3 * pk, b.points_a.mutable_data() + 3 * r);
      std::copy_n(p->points_b.data(), 3 * pk, b.points_b.mutable_data() + 3 * r);
      std::copy_n(p->normals.data(), 3 * pk, b.normals.mutable_data() + 3 * r);
      std::copy_n(p->distances.data(), pk, b.distances.mutable_data() + r);
      std::copy_n(p->depths.data(), pk, b.depths.mutable_data() + r);
      b.node_tests += p->node_tests;
      b.leaf_tests += p->leaf_tests;
      e += pn;
      r += pk;
    }
    b.derive();
    return b;
  }

 private:
  /// The arrays for n entries and k rows; with `zero_rows`, the rows' points, normals, distances
  /// and depths are zeros (numpy.zeros), else left to be written.
  void allocate(py::ssize_t n, py::ssize_t k, bool zero_rows = false) {
    offsets = py::array_t<std::int64_t>(n + 1);
    hit = py::array_t<bool>(n);
    limit_reached = py::array_t<bool>(n);
    distance = py::array_t<double>(n);
    pairs = py::array_t<std::uint32_t>({k, py::ssize_t{2}});
    entries = py::array_t<std::int64_t>(k);
    if (zero_rows) {
      const py::object zeros = py::module_::import("numpy").attr("zeros");
      points_a = zeros(py::make_tuple(k, 3));
      points_b = zeros(py::make_tuple(k, 3));
      normals = zeros(py::make_tuple(k, 3));
      distances = zeros(k);
      depths = zeros(k);
      return;
    }
    points_a = py::array_t<double>({k, py::ssize_t{3}});
    points_b = py::array_t<double>({k, py::ssize_t{3}});
    normals = py::array_t<double>({k, py::ssize_t{3}});
    distances = py::array_t<double>(k);
    depths = py::array_t<double>(k);
  }

  /// hit, distance and entries, from offsets and distances.
  void derive() {
    const std::int64_t* const off = offsets.data();
    const double* const dd = distances.data();
    bool* const h = hit.mutable_data();
    double* const dist = distance.mutable_data();
    std::int64_t* const ent = entries.mutable_data();
    for (py::ssize_t i = 0; i + 1 < offsets.shape(0); ++i) {
      h[i] = off[i + 1] > off[i];
      dist[i] = std::numeric_limits<double>::infinity();
      for (std::int64_t r = off[i]; r != off[i + 1]; ++r) {
        dist[i] = std::min(dist[i], dd[r]);
        ent[r] = i;
      }
    }
  }

  template <class T>
  static py::array_t<T, py::array::c_style | py::array::forcecast> array_of(py::handle h) {
    return py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(h);
  }

  template <class T, class Refuse>
  static void copy_checked(const py::array_t<T, py::array::c_style | py::array::forcecast>& from, py::array_t<T>& to,
                           std::initializer_list<py::ssize_t> shape, const char* name, const Refuse& refuse) {
    bool fits = from && from.ndim() == static_cast<py::ssize_t>(shape.size());
    for (std::size_t d = 0; fits && d < shape.size(); ++d) fits = from.shape(static_cast<py::ssize_t>(d)) == shape.begin()[d];
    if (!fits) throw refuse(std::string(name) + " does not have the shape the offsets give");
    std::copy_n(from.data(), to.size(), to.mutable_data());
  }
};

/// "wxyz" or "xyzw".
inline caliber::QuaternionOrder parse_order(const std::string& order) {
  if (order == "wxyz") return caliber::QuaternionOrder::wxyz;
  if (order == "xyzw") return caliber::QuaternionOrder::xyzw;
  throw caliber::Error(caliber::ErrorCode::bad_value, "order", "must be 'wxyz' or 'xyzw', not '" + order + "'");
}

/// Registers caliber.Batch, the answers of Engine.query_many and caliber.query_many, and returns
/// the class. Its arrays are read-only.
inline py::class_<PyBatch> bind_batch(py::module_& m) {
  auto cls =
      py::class_<PyBatch>(
          m, "Batch",
          "The answers of a batch query: per entry (pose), whether it hit, its smallest distance and whether "
          "it stopped at max_pairs; per reported triangle pair, one row like Result's, with the entry it belongs to.")
          .def_property_readonly("offsets", view_of<PyBatch, &PyBatch::offsets>,
                                 "N + 1: entry i's rows are offsets[i]:offsets[i + 1]")
          .def_property_readonly("hit", view_of<PyBatch, &PyBatch::hit>, "N bools: the entry reported a pair")
          .def_property_readonly("limit_reached", view_of<PyBatch, &PyBatch::limit_reached>,
                                 "N bools: the entry found max_pairs pairs and stopped")
          .def_property_readonly(
              "distance", view_of<PyBatch, &PyBatch::distance>,
              "N: the entry's smallest reported distance (its closest pair's, for kind 'distance'); inf when none")
          .def_property_readonly("pairs", view_of<PyBatch, &PyBatch::pairs>, "k x 2 triangle ids")
          .def_property_readonly("entries", view_of<PyBatch, &PyBatch::entries>, "k: the entry of each row")
          .def_property_readonly("points_a", view_of<PyBatch, &PyBatch::points_a>)
          .def_property_readonly("points_b", view_of<PyBatch, &PyBatch::points_b>)
          .def_property_readonly("normals", view_of<PyBatch, &PyBatch::normals>)
          .def_property_readonly("distances", view_of<PyBatch, &PyBatch::distances>)
          .def_property_readonly("depths", view_of<PyBatch, &PyBatch::depths>)
          .def_readonly("node_tests", &PyBatch::node_tests)
          .def_readonly("leaf_tests", &PyBatch::leaf_tests)
          .def_readonly("batch_ms", &PyBatch::batch_ms,
                        "wall time of the C++ batch in milliseconds, without reading the poses or making these arrays (0 for a "
                        "Batch unpickled or joined)")
          .def("__len__", [](const PyBatch& b) { return static_cast<std::size_t>(b.hit.shape(0)); })
          .def_static(
              "concatenate",
              [](const std::vector<const PyBatch*>& parts) {
                for (const PyBatch* p : parts) {
                  if (p == nullptr) throw caliber::Error(caliber::ErrorCode::bad_argument, "Batch.concatenate", "got None");
                }
                return PyBatch::concatenate(parts);
              },
              py::arg("batches"),
              "One Batch of the given batches' entries, in order (what a pose batch cut in chunks gathers); counters summed.")
          .def("__reduce__", [](const PyBatch& b) {
            return py::make_tuple(py::module_::import("caliber").attr("_batch_from_state"), py::make_tuple(b.state()));
          });
  m.def("_checked_batch", &PyBatch::from_state);
  return cls;
}

}  // namespace caliber_python
