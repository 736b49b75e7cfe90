// The readers of arguments and the helpers every binding file shares (common.h).

#include "common.h"

#include <algorithm>
#include <cstring>

namespace caliber_python {

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

namespace {
/// read_reals of a list or tuple.
void read_sequence(const py::object& given, double* out, std::size_t n, const auto& refuse) {
  if (py::len(given) != n) throw refuse(std::to_string(py::len(given)) + " items");
  static const py::object numpy_bool = py::module_::import("numpy").attr("bool_");
  static const py::object numpy_complex = py::module_::import("numpy").attr("complexfloating");
  for (std::size_t i = 0; i < n; ++i) {
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
}
}  // namespace

void read_reals(const py::object& given, const char* name, double* out, std::size_t n) {
  const auto refuse = [&](const std::string& what) {
    return caliber::Error(caliber::ErrorCode::bad_argument, name, "must be " + std::to_string(n) + " real numbers, not " + what);
  };
  if (PyList_Check(given.ptr()) != 0 || PyTuple_Check(given.ptr()) != 0) {
    read_sequence(given, out, n, refuse);
    return;
  }
  const py::array a = py::array::ensure(given);
  const char kind = a ? a.dtype().kind() : 'O';
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw refuse(a ? "dtype " + std::string(py::str(a.dtype())) : std::string(py::str(given.get_type().attr("__name__"))));
  }
  if (a.size() != static_cast<py::ssize_t>(n) || a.ndim() > 2) {
    throw refuse("an array of " + std::to_string(a.size()) + " in " + std::to_string(a.ndim()) + " dimensions");
  }
  const py::array_t<double, py::array::c_style | py::array::forcecast> values(a);
  std::copy_n(values.data(), n, out);
}

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

std::array<double, 4> quaternion_wxyz(const std::array<double, 4>& q, const std::string& order) {
  if (parse_order(order) == caliber::QuaternionOrder::wxyz) return q;
  return {q[3], q[0], q[1], q[2]};
}

caliber::QueryRequest make_request(const std::string& kind, std::optional<double> tolerance, double angle, std::size_t max_pairs,
                                   bool lowest_ids) {
  caliber::QueryRequest request;
  request.max_pairs = max_pairs;
  request.lowest_ids = lowest_ids;
  request.kind = caliber::parse_query_kind(kind);
  request.tolerance = tolerance ? *tolerance : request.kind == caliber::QueryKind::distance ? caliber::kUnbounded : 0.0;
  request.angle_deg = angle;
  caliber::validate_request(request);
  return request;
}

std::vector<std::shared_ptr<const caliber::Model>> shared_models(const std::vector<PyModel>& models) {
  std::vector<std::shared_ptr<const caliber::Model>> shared;
  shared.reserve(models.size());
  for (const PyModel& m : models) shared.push_back(m.model);
  return shared;
}

std::vector<caliber::ObjectPair> object_pairs(const IdPairs& pairs) {
  std::vector<caliber::ObjectPair> out;
  out.reserve(pairs.size());
  for (const auto& [a, b] : pairs) out.push_back(caliber::ObjectPair{a, b});
  return out;
}

IdPairs id_pairs(const std::vector<caliber::ObjectPair>& pairs) {
  IdPairs out;
  out.reserve(pairs.size());
  for (const caliber::ObjectPair& p : pairs) out.emplace_back(p.a, p.b);
  return out;
}

py::list swept_pairs(const std::vector<caliber::PairSweep>& swept) {
  py::list out;
  for (const caliber::PairSweep& p : swept) out.append(py::make_tuple(py::make_tuple(p.pair.a, p.pair.b), p.result));
  return out;
}

caliber::SweepRequest sweep_request(double tolerance, std::uint64_t max_queries) {
  caliber::SweepRequest request;
  request.tolerance = tolerance;
  request.max_queries = max_queries;
  return request;
}

py::tuple rebuilt_by(const char* function, py::tuple args) {
  return py::make_tuple(py::module_::import("caliber").attr(function), std::move(args));
}

caliber::Error not_picklable(const char* name, const std::string& instead) {
  return caliber::Error(caliber::ErrorCode::bad_argument, name, std::string("cannot be pickled: ") + instead);
}

std::string float_text(double value) { return py::repr(py::float_(value)); }

std::string bracket_repr(const char* name, const std::string& what) {
  return std::string("<caliber.") + name + ": " + what + ">";
}

std::string count_of(std::size_t n, const char* thing, const char* plural) {
  if (n == 1) return "1 " + std::string(thing);
  return std::to_string(n) + " " + (plural != nullptr ? std::string(plural) : std::string(thing) + "s");
}

}  // namespace caliber_python
