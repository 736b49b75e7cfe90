#pragma once
// Bounded TypeErrors. When no overload of a pybind11 function takes the arguments given, pybind11
// raises a TypeError that lists the supported signatures and then the repr of every argument: a
// list of 100,000 poses passed with one wrong keyword gives a message of megabytes. Every public
// function and method of the module is wrapped so that such a message comes out as one line of
// bounded length: the signatures on one line, then each argument's repr when short, else its type
// and length.

#include <pybind11/pybind11.h>

#include <cstddef>
#include <deque>
#include <initializer_list>
#include <string>

namespace caliber_python {

/// The longest message left as it is, and the longest a bounded message keeps of the part before
/// the arguments (the signatures).
inline constexpr std::size_t kMessageMost = 400;
inline constexpr std::size_t kSignaturesMost = 1000;
/// An argument's repr is shown up to this many characters; a container of more than kItemsShown
/// items is shown by its type and length, without its repr.
inline constexpr std::size_t kReprMost = 60;
inline constexpr Py_ssize_t kItemsShown = 8;

/// A short description of o: its repr when short, else its type (and length when it has one).
inline std::string describe(PyObject* o) {
  const std::string type = Py_TYPE(o)->tp_name;
  if (PyObject_HasAttrString(o, "__len__") != 0) {
    const Py_ssize_t n = PyObject_Length(o);
    if (n < 0) {
      PyErr_Clear();
    } else if (n > kItemsShown) {
      return type + " of length " + std::to_string(n);
    }
  }
  PyObject* repr = PyObject_Repr(o);
  if (repr == nullptr) {
    PyErr_Clear();
    return type;
  }
  // Cut by characters, not bytes, so that the text stays valid UTF-8.
  const bool long_repr = PyUnicode_GetLength(repr) > static_cast<Py_ssize_t>(kReprMost);
  PyObject* shown = long_repr ? PyUnicode_Substring(repr, 0, static_cast<Py_ssize_t>(kReprMost)) : repr;
  Py_ssize_t size = 0;
  const char* text = shown != nullptr ? PyUnicode_AsUTF8AndSize(shown, &size) : nullptr;
  std::string out = text != nullptr ? std::string(text, static_cast<std::size_t>(size)) : type;
  if (text == nullptr) PyErr_Clear();
  if (long_repr) {
    Py_XDECREF(shown);
    out = type + " " + out + "...";
  }
  Py_DECREF(repr);
  for (char& c : out) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return out;
}

/// Text on one line: every run of white space that holds a line break becomes one space.
inline std::string one_line(const std::string& text) {
  std::string out;
  bool in_break = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n' || c == '\r') {
      in_break = true;
      continue;
    }
    if (in_break && (c == ' ' || c == '\t')) continue;
    if (in_break) {
      if (!out.empty()) out += ' ';
      in_break = false;
    }
    out += c;
  }
  return out;
}

/// The bounded message for a TypeError whose text is `message` (see bound_type_error).
inline std::string bounded_message(const std::string& message, PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames) {
  const std::size_t invoked = message.find("\nInvoked with:");
  std::string out = one_line(message.substr(0, invoked));
  if (out.size() > kSignaturesMost) out = out.substr(0, kSignaturesMost) + "...";
  if (invoked == std::string::npos) return out;
  out += " Invoked with: ";
  // A constructor's self (the new object) is left out, as pybind11 leaves it out.
  const Py_ssize_t first = message.find("incompatible constructor arguments") != std::string::npos ? 1 : 0;
  bool some = false;
  for (Py_ssize_t i = first; i < nargs; ++i) {
    out += (some ? ", " : "") + describe(args[i]);
    some = true;
  }
  const Py_ssize_t named = kwnames != nullptr ? PyTuple_GET_SIZE(kwnames) : 0;
  for (Py_ssize_t k = 0; k < named; ++k) {
    const char* name = PyUnicode_AsUTF8(PyTuple_GET_ITEM(kwnames, k));
    if (name == nullptr) PyErr_Clear();
    out += (some ? ", " : "") + std::string(name != nullptr ? name : "?") + "=" + describe(args[nargs + k]);
    some = true;
  }
  return out;
}

/// With a TypeError set whose message is long or spans lines: replaces it with one line, the
/// message's part before pybind11's "Invoked with:" (at most kSignaturesMost characters), then the
/// arguments of the call (vectorcall form) described briefly. Any other error is left as it is,
/// and so is this one when the bounded message cannot be made (out of memory).
inline void bound_type_error(PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames) noexcept {
  if (PyErr_Occurred() == nullptr || PyErr_ExceptionMatches(PyExc_TypeError) == 0) return;
  PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;
  PyErr_Fetch(&type, &value, &traceback);
  PyErr_NormalizeException(&type, &value, &traceback);
  std::string out;
  try {
    std::string message;
    if (PyObject* text = value != nullptr ? PyObject_Str(value) : nullptr) {
      Py_ssize_t size = 0;
      if (const char* utf8 = PyUnicode_AsUTF8AndSize(text, &size)) message.assign(utf8, static_cast<std::size_t>(size));
      Py_DECREF(text);
    }
    PyErr_Clear();
    if (message.size() > kMessageMost || message.find('\n') != std::string::npos)
      out = bounded_message(message, args, nargs, kwnames);
  } catch (...) {
    out.clear();
  }
  PyErr_Clear();
  PyObject* text = out.empty() ? nullptr : PyUnicode_DecodeUTF8(out.data(), static_cast<Py_ssize_t>(out.size()), "replace");
  PyObject* replacement = text != nullptr ? PyObject_CallOneArg(type, text) : nullptr;
  Py_XDECREF(text);
  if (replacement == nullptr) {  // short already, or not made: the original error
    PyErr_Clear();
    PyErr_Restore(type, value, traceback);
    return;
  }
  Py_XDECREF(value);
  PyErr_Restore(type, replacement, traceback);
}

/// Calls `original` (the wrapped function, held as the wrapper's self) with the call's arguments,
/// bounding a TypeError it raises.
inline PyObject* call_bounded(PyObject* original, PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames) {
  PyObject* result = PyObject_Vectorcall(original, args, static_cast<std::size_t>(nargs), kwnames);
  if (result == nullptr) bound_type_error(args, nargs, kwnames);
  return result;
}

/// A function that calls `original` (a builtin function) and bounds its TypeErrors: the same
/// name, doc and module.
inline pybind11::object bounded(pybind11::handle original, pybind11::handle module_name) {
  // Each wrapper's method definition, name and doc live as long as the process, as the module's
  // own do (held from a global, never freed).
  struct Held {
    std::string name, doc;
    PyMethodDef def{};
  };
  static auto* const held = new std::deque<Held>;
  Held& h = held->emplace_back();
  h.name = pybind11::str(original.attr("__name__"));
  const pybind11::object doc = original.attr("__doc__");
  if (!doc.is_none()) h.doc = pybind11::str(doc);
  h.def = PyMethodDef{h.name.c_str(), reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(&call_bounded)),
                      METH_FASTCALL | METH_KEYWORDS, doc.is_none() ? nullptr : h.doc.c_str()};
  PyMethodDef* const def = &h.def;
  PyObject* wrapper = PyCFunction_NewEx(def, original.ptr(), module_name.ptr());
  if (wrapper == nullptr) throw pybind11::error_already_set();
  return pybind11::reinterpret_steal<pybind11::object>(wrapper);
}

/// Wraps (bounded) every public function of module m except those named in `skip`, and every
/// public method, static method, __init__, __repr__, __len__ and __reduce__ of its classes.
inline void bound_type_errors(pybind11::module_& m, std::initializer_list<const char*> skip) {
  namespace py = pybind11;
  const py::object module_name = m.attr("__name__");
  const std::string module = py::str(module_name);
  const py::object staticmethod = py::module_::import("builtins").attr("staticmethod");
  const auto is_public = [](const std::string& name) { return name.empty() || name[0] != '_'; };
  const py::dict names = m.attr("__dict__").attr("copy")();  // m's attributes change below
  for (const auto& [key, value] : names) {
    const std::string name = py::str(key);
    bool skipped = !is_public(name);
    for (const char* s : skip) skipped = skipped || name == s;
    if (skipped) continue;
    if (PyCFunction_Check(value.ptr()) != 0) {
      m.attr(key) = bounded(value, module_name);
    } else if (PyType_Check(value.ptr()) != 0 && py::hasattr(value, "__module__") &&
               py::str(value.attr("__module__")).cast<std::string>() == module) {
      const py::object cls = py::reinterpret_borrow<py::object>(value);
      for (const auto& [mkey, method] : py::dict(cls.attr("__dict__"))) {
        const std::string mname = py::str(mkey);
        const bool wrapped_dunder = mname == "__init__" || mname == "__repr__" || mname == "__len__" || mname == "__reduce__";
        if (!is_public(mname) && !wrapped_dunder) continue;
        if (PyInstanceMethod_Check(method.ptr()) != 0) {
          const py::handle function = PyInstanceMethod_GET_FUNCTION(method.ptr());
          if (PyCFunction_Check(function.ptr()) == 0) continue;
          PyObject* wrapped = PyInstanceMethod_New(bounded(function, module_name).ptr());
          if (wrapped == nullptr) throw py::error_already_set();
          cls.attr(mkey) = py::reinterpret_steal<py::object>(wrapped);
        } else if (py::isinstance(method, staticmethod)) {
          const py::object function = method.attr("__func__");
          if (PyCFunction_Check(function.ptr()) == 0) continue;
          cls.attr(mkey) = staticmethod(bounded(function, module_name));
        }
      }
    }
  }
}

}  // namespace caliber_python
