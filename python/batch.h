#pragma once
// Batch queries in Python: the poses of a side from numpy arrays (N x 4 x 4 matrices, N x 7
// translation + quaternion, float32 or float64) or from Pose objects, and a batch's answers as
// numpy arrays, one row per entry and one per reported triangle pair.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "caliber/batch.h"
#include "caliber/error.h"
#include "caliber/pose.h"

namespace caliber_python {

namespace py = pybind11;

/// A side's poses, as given: a Pose, a sequence of Poses, or an array of matrices (4 x 4 or
/// N x 4 x 4) or of translation + quaternion rows (7 or N x 7, the quaternion in `order`).
/// float32 matrices are rotations to float32's rounding only: they get 1e-6 as the tolerance.
/// Errors name `side` and the row.
struct SidePoses {
  std::vector<caliber::Pose> poses;

  SidePoses(const py::object& given, caliber::QuaternionOrder order, const std::string& side) {
    if (py::isinstance<caliber::Pose>(given)) {
      poses.push_back(given.cast<caliber::Pose>());
      return;
    }
    if (!py::isinstance<py::array>(given) && py::isinstance<py::sequence>(given) && !py::isinstance<py::str>(given)) {
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
    const bool single = raw.dtype().is(py::dtype::of<float>());
    const py::array_t<double, py::array::c_style | py::array::forcecast> values(raw);
    const std::span<const double> flat(values.data(), static_cast<std::size_t>(values.size()));
    const auto nd = values.ndim();
    const auto last = nd > 0 ? values.shape(nd - 1) : 0;
    py::gil_scoped_release release;
    if ((nd == 2 || nd == 3) && last == 4 && values.shape(nd - 2) == 4) {
      poses = caliber::poses_from_matrices(flat, single ? 1e-6 : 1e-9, side);
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
  py::array_t<bool> limit_reached;                  ///< N: the entry found more than max_pairs
  py::array_t<double> distance;                     ///< N: the entry's smallest reported distance (inf: none)
  py::array_t<std::uint32_t> pairs;                 ///< k x 2 triangle ids
  py::array_t<std::int64_t> entries;                ///< k: the entry each row belongs to
  py::array_t<double> points_a, points_b, normals;  ///< k x 3, world coordinates (zero for interference)
  py::array_t<double> distances, depths;            ///< k
  std::uint64_t node_tests = 0, leaf_tests = 0;

  explicit PyBatch(const caliber::BatchResult& b) {
    const auto n = static_cast<py::ssize_t>(b.size());
    const auto k = static_cast<py::ssize_t>(b.contacts.size());
    offsets = py::array_t<std::int64_t>(n + 1);
    hit = py::array_t<bool>(n);
    limit_reached = py::array_t<bool>(n);
    distance = py::array_t<double>(n);
    pairs = py::array_t<std::uint32_t>({k, py::ssize_t{2}});
    entries = py::array_t<std::int64_t>(k);
    points_a = py::array_t<double>({k, py::ssize_t{3}});
    points_b = py::array_t<double>({k, py::ssize_t{3}});
    normals = py::array_t<double>({k, py::ssize_t{3}});
    distances = py::array_t<double>(k);
    depths = py::array_t<double>(k);
    std::int64_t* const off = offsets.mutable_data();
    bool* const h = hit.mutable_data();
    bool* const lr = limit_reached.mutable_data();
    double* const dist = distance.mutable_data();
    std::uint32_t* const tri = pairs.mutable_data();
    std::int64_t* const ent = entries.mutable_data();
    double *const pa = points_a.mutable_data(), *const pb = points_b.mutable_data(), *const nn = normals.mutable_data();
    double *const dd = distances.mutable_data(), *const dp = depths.mutable_data();
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i <= n; ++i) off[i] = static_cast<std::int64_t>(b.offsets[static_cast<std::size_t>(i)]);
    for (py::ssize_t i = 0; i < n; ++i) {
      const auto e = static_cast<std::size_t>(i);
      h[i] = b.hit(e);
      lr[i] = b.limit_reached[e] != 0;
      dist[i] = std::numeric_limits<double>::infinity();
      for (std::size_t r = b.offsets[e]; r != b.offsets[e + 1]; ++r) {
        const caliber::Contact& c = b.contacts[r];
        dist[i] = std::min(dist[i], c.distance);
        ent[r] = i;
        tri[2 * r] = c.tri_a;
        tri[2 * r + 1] = c.tri_b;
        for (std::size_t d = 0; d < 3; ++d) {
          pa[3 * r + d] = c.point_a[static_cast<Eigen::Index>(d)];
          pb[3 * r + d] = c.point_b[static_cast<Eigen::Index>(d)];
          nn[3 * r + d] = c.normal[static_cast<Eigen::Index>(d)];
        }
        dd[r] = c.distance;
        dp[r] = c.depth;
      }
    }
    node_tests = b.stats.node_tests;
    leaf_tests = b.stats.leaf_tests;
  }
};

/// "wxyz" or "xyzw".
inline caliber::QuaternionOrder parse_order(const std::string& order) {
  if (order == "wxyz") return caliber::QuaternionOrder::wxyz;
  if (order == "xyzw") return caliber::QuaternionOrder::xyzw;
  throw caliber::Error(caliber::ErrorCode::bad_value, "order", "must be 'wxyz' or 'xyzw', not '" + order + "'");
}

/// Registers caliber.Batch, the answers of Engine.query_many and caliber.query_many.
inline void bind_batch(py::module_& m) {
  py::class_<PyBatch>(m, "Batch",
                      "The answers of a batch query: per entry (pose), whether it hit, its smallest distance and whether "
                      "max_pairs cut it; per reported triangle pair, one row like Result's, with the entry it belongs to.")
      .def_readonly("offsets", &PyBatch::offsets, "N + 1: entry i's rows are offsets[i]:offsets[i + 1]")
      .def_readonly("hit", &PyBatch::hit, "N bools: the entry reported a pair")
      .def_readonly("limit_reached", &PyBatch::limit_reached, "N bools: the entry found more than max_pairs")
      .def_readonly("distance", &PyBatch::distance,
                    "N: the entry's smallest reported distance (its closest pair's, for kind 'distance'); inf when none")
      .def_readonly("pairs", &PyBatch::pairs, "k x 2 triangle ids")
      .def_readonly("entries", &PyBatch::entries, "k: the entry of each row")
      .def_readonly("points_a", &PyBatch::points_a)
      .def_readonly("points_b", &PyBatch::points_b)
      .def_readonly("normals", &PyBatch::normals)
      .def_readonly("distances", &PyBatch::distances)
      .def_readonly("depths", &PyBatch::depths)
      .def_readonly("node_tests", &PyBatch::node_tests)
      .def_readonly("leaf_tests", &PyBatch::leaf_tests)
      .def("__len__", [](const PyBatch& b) { return static_cast<std::size_t>(b.hit.shape(0)); })
      .def("__reduce__", [](const PyBatch&) -> py::object {
        throw caliber::Error(caliber::ErrorCode::bad_argument, "Batch", "cannot be pickled: pickle its arrays");
      });
}

}  // namespace caliber_python
