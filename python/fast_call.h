#pragma once
// A module function called through CPython's vectorcall protocol (METH_FASTCALL | METH_KEYWORDS),
// for a call a planner makes millions of times (caliber.query). pybind11's dispatcher builds an
// argument tuple and a keyword dict, looks each parameter up in the dict by a string it creates
// for the lookup and keeps the arguments in vectors: on a distance query of two tetrahedra, a large
// share of the instructions spent above the C++ call (bench/results/amd-epyc-2c/batch/README.md).
// The fast path below reads the arguments of the common types itself (bound caliber objects, str,
// float, int, bool, None); a call it does not take whole (another type, a missing, unknown or
// repeated argument, an error of any kind) goes to the pybind11 function it stands for, which
// answers or raises as before.

#include <pybind11/pybind11.h>

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>
#include <typeinfo>

namespace caliber_python::fast {

/// The arguments of a vectorcall by parameter: out[i] for names[i], null where not given. False
/// when the call names an unknown or repeated parameter or gives more than `positional` arguments
/// by position.
template <std::size_t N>
bool gather(PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames, const std::array<const char*, N>& names,
            std::size_t positional, std::array<PyObject*, N>& out) {
  out.fill(nullptr);
  if (nargs < 0 || static_cast<std::size_t>(nargs) > positional) return false;
  for (Py_ssize_t i = 0; i < nargs; ++i) out[static_cast<std::size_t>(i)] = args[i];
  if (kwnames == nullptr) return true;
  for (Py_ssize_t k = 0; k < PyTuple_GET_SIZE(kwnames); ++k) {
    PyObject* name = PyTuple_GET_ITEM(kwnames, k);
    std::size_t i = 0;
    while (i < N && PyUnicode_CompareWithASCIIString(name, names[i]) != 0) ++i;
    if (i == N || out[i] != nullptr) return false;
    out[i] = args[nargs + k];
  }
  return true;
}

/// A float or an int as a double (pybind11's double caster takes both, the int as float(int)).
inline bool as_double(PyObject* o, double& out) {
  if (PyFloat_CheckExact(o)) {
    out = PyFloat_AS_DOUBLE(o);
    return true;
  }
  if (!PyLong_CheckExact(o)) return false;
  out = PyLong_AsDouble(o);
  if (out == -1.0 && PyErr_Occurred() != nullptr) {
    PyErr_Clear();
    return false;
  }
  return true;
}

/// None (nullopt), or as_double.
inline bool as_optional_double(PyObject* o, std::optional<double>& out) {
  if (o == Py_None) return (out.reset(), true);
  double d;
  if (!as_double(o, d)) return false;
  out = d;
  return true;
}

/// An int in [0, SIZE_MAX].
inline bool as_size(PyObject* o, std::size_t& out) {
  if (!PyLong_CheckExact(o)) return false;
  out = PyLong_AsSize_t(o);
  if (out == static_cast<std::size_t>(-1) && PyErr_Occurred() != nullptr) {
    PyErr_Clear();
    return false;
  }
  return true;
}

/// True or False.
inline bool as_bool(PyObject* o, bool& out) {
  if (o != Py_True && o != Py_False) return false;
  out = o == Py_True;
  return true;
}

/// A str, as UTF-8 (valid while the str lives).
inline bool as_string(PyObject* o, std::string_view& out) {
  if (!PyUnicode_CheckExact(o)) return false;
  Py_ssize_t size = 0;
  const char* s = PyUnicode_AsUTF8AndSize(o, &size);
  if (s == nullptr) {
    PyErr_Clear();
    return false;
  }
  out = std::string_view(s, static_cast<std::size_t>(size));
  return true;
}

/// The C++ value of an instance of bound class T, or null (also for an instance whose value was
/// never built: the pybind11 function refuses it with its message). The type is looked up once,
/// not at every call as a caster does (a hash of the C++ type's name).
template <class T>
const T* as_bound(PyObject* o) {
  static const pybind11::detail::type_info* const type = pybind11::detail::get_type_info(typeid(T));
  if (type == nullptr || !PyObject_TypeCheck(o, type->type)) return nullptr;
  const auto value = reinterpret_cast<pybind11::detail::instance*>(o)->get_value_and_holder(type, false);
  if (!value || !value.holder_constructed()) return nullptr;
  return static_cast<const T*>(value.value_ptr());
}

/// Makes `def` (METH_FASTCALL | METH_KEYWORDS; its doc opens with the text signature, `name(...)`
/// then "\n--\n\n", which inspect.signature reads) module m's function `name`, standing in for
/// the pybind11 function of that name, which it returns (the fast path calls it for the calls it
/// does not take).
inline PyObject* stand_in(pybind11::module_& m, PyMethodDef& def) {
  PyObject* slow = pybind11::object(m.attr(def.ml_name)).release().ptr();  // kept for the life of the process
  PyObject* fast = PyCFunction_NewEx(&def, m.ptr(), m.attr("__name__").ptr());
  if (fast == nullptr) throw pybind11::error_already_set();
  m.attr(def.ml_name) = pybind11::reinterpret_steal<pybind11::object>(fast);
  return slow;
}

}  // namespace caliber_python::fast
