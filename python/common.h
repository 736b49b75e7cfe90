#pragma once
// What the binding files share: the bound value types (PyModel, PyResult), the readers of
// arguments (paths, real numbers, flags, quaternion orders, the query request), pickling helpers,
// and the casters that refuse half-built objects, declared here so that every file binds the
// same ones.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "caliber/caliber.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "batch.h"
#include "half_built.h"
#include "sweeps.h"

namespace caliber_python {

namespace py = pybind11;

/// A built model, shared (the C++ side holds it as shared_ptr<const Model>).
struct PyModel {
  std::shared_ptr<const caliber::Model> model;
};

/// A query's or a step's answer: the contacts as numpy arrays (one row per reported triangle pair),
/// made on the first read of any of them (a query that answers "no" builds none; a planner that
/// reads only len() or limit_reached builds none either). The contacts are let go once copied.
struct PyResult {
  std::vector<caliber::Contact> contacts;  ///< until the arrays are made
  std::size_t rows = 0;
  std::uint64_t node_tests = 0, leaf_tests = 0;
  bool limit_reached = false;  ///< max_pairs were found: it stopped there (maybe a part)
  caliber::QueryKind kind = caliber::QueryKind::interference;

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
  Arrays make_arrays();
};

/// A Result of `contacts` found by a query or step of `kind`.
PyResult to_result(std::vector<caliber::Contact> contacts, const caliber::QueryStats& stats, bool limit_reached,
                   caliber::QueryKind kind);

/// A path as the file system has it: str (undecodable bytes as surrogate escapes, as os.listdir
/// gives them), bytes or any os.PathLike, through os.fsencode; so a file whose name is not UTF-8
/// can be named, and its name reaches messages as written (escaped there by caliber::Error).
std::string file_path(const py::object& path);

/// The reader of reals<N>: a list or tuple of N numbers, or an array of N real numbers.
void read_reals(const py::object& given, const char* name, double* out, std::size_t n);

/// N real numbers (`name`: a translation, a quaternion): a list or tuple of N numbers (Python
/// floats and ints, numpy reals, anything with __float__), or an array of N real numbers (a row,
/// a column). Complex numbers, bools and strings are refused, not converted: an imaginary part is
/// not dropped, True is not 1.
template <std::size_t N>
std::array<double, N> reals(const py::object& given, const char* name) {
  std::array<double, N> out{};
  read_reals(given, name, out.data(), N);
  return out;
}

/// One flag per object (`fixed`): each True or False (a numpy bool too), or an integer 0 or 1
/// (Python's or numpy's); an empty list for none. Anything else is refused, not converted by its
/// truth value.
std::vector<bool> flags_of(const py::object& given, const char* name);

/// The quaternion (w, x, y, z) of `q` given in `order` ("wxyz" or "xyzw", read by parse_order).
std::array<double, 4> quaternion_wxyz(const std::array<double, 4>& q, const std::string& order);

/// The request of a query, a batch or a step from its keyword arguments. `tolerance` None: 0, or
/// for a distance query, any distance (caliber::kUnbounded).
caliber::QueryRequest make_request(const std::string& kind, std::optional<double> tolerance, double angle, std::size_t max_pairs,
                                   bool lowest_ids);

/// The keyword arguments make_request reads, as every binding that takes a request declares them,
/// after its own positional ones (lowest_ids is keyword-only: request_kw_args).
inline auto request_args() {
  return std::make_tuple(py::arg("kind") = "interference", py::arg("tolerance") = py::none(), py::arg("angle") = 30.0,
                         py::arg("max_pairs") = 0);
}

/// The shared models of a list of Models.
std::vector<std::shared_ptr<const caliber::Model>> shared_models(const std::vector<PyModel>& models);

using IdPairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;
/// Object pairs from Python's (a, b) tuples, and back.
std::vector<caliber::ObjectPair> object_pairs(const IdPairs& pairs);
IdPairs id_pairs(const std::vector<caliber::ObjectPair>& pairs);

/// [((a, b), Sweep)] for a scene's swept pairs.
py::list swept_pairs(const std::vector<caliber::PairSweep>& swept);

/// The request of a swept query.
caliber::SweepRequest sweep_request(double tolerance, std::uint64_t max_queries);

/// How pickle rebuilds an object: `function` of module caliber called with `args`. Every picklable
/// class defines __reduce__ this way, so that every protocol (0 and 1 included, where pybind11's
/// default would abort the interpreter) gives a pickle that unpickles through a checked function.
py::tuple rebuilt_by(const char* function, py::tuple args);

/// The error of pickling an unpicklable `name`, saying what to do `instead`.
caliber::Error not_picklable(const char* name, const std::string& instead);

/// Python's repr of a float (the shortest text that reads back as the same double).
std::string float_text(double value);

/// "<caliber.Name: what>", what every repr without a constructor call prints.
std::string bracket_repr(const char* name, const std::string& what);

/// The __repr__ of the bound class T (`name` in "caliber.Name"): "<caliber.Name: what>", `what` of
/// the object (alone where not `bracketed`), or "never built" for an object made by __new__ alone,
/// which the class's caster refuses.
template <class T, class What>
auto repr_of(const char* name, What what, bool bracketed = true) {
  return [name, what, bracketed](py::handle self) -> std::string {
    if (!py::isinstance<T>(self)) {
      throw py::type_error(std::string("__repr__ of caliber.") + name + " takes a caliber." + name + ", not " +
                           py::str(self.get_type().attr("__name__")).cast<std::string>());
    }
    if (is_half_built(self, py::detail::get_type_info(typeid(T)))) return bracket_repr(name, "never built");
    return bracketed ? bracket_repr(name, what(self.cast<const T&>())) : what(self.cast<const T&>());
  };
}

/// "1 thing" or "n things" (`plural`: "things" when not given).
std::string count_of(std::size_t n, const char* thing, const char* plural = nullptr);

// The bindings, by what they bind (one file each).
void bind_mesh(py::module_& m);
void bind_model(py::module_& m);
void bind_pose(py::module_& m);
void bind_query(py::module_& m);
void bind_sweep(py::module_& m);
void bind_engine(py::module_& m);
void bind_world(py::module_& m);

}  // namespace caliber_python

CALIBER_REFUSE_HALF_BUILT(caliber::Mesh, "Mesh")
CALIBER_REFUSE_HALF_BUILT(caliber_python::PyModel, "Model")
CALIBER_REFUSE_HALF_BUILT(caliber::Pose, "Pose")
CALIBER_REFUSE_HALF_BUILT(caliber_python::PyResult, "Result")
CALIBER_REFUSE_HALF_BUILT(caliber::Engine, "Engine")
CALIBER_REFUSE_HALF_BUILT(caliber::World, "World")
CALIBER_REFUSE_HALF_BUILT(caliber_python::PyBatch, "Batch")
CALIBER_REFUSE_HALF_BUILT(caliber_python::PySweeps, "Sweeps")
CALIBER_REFUSE_HALF_BUILT(caliber::SweepResult, "Sweep")
