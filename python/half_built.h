#pragma once
// Python objects that never reach C++ half-built. `Model.__new__(Model)`, or a pickle that creates
// an object (NEWOBJ) and never sets its state (BUILD), gives an instance whose C++ value was never
// constructed; pybind11 would hand a method the uninitialized memory behind it. Every bound class
// registers the caster below, which refuses such an instance with caliber.Error wherever one is
// passed: as `self`, as an argument, or inside a list.

#include <pybind11/pybind11.h>

#include <string>

#include "caliber/error.h"

namespace caliber_python {

/// True when `object` is an instance of the bound class `type` whose C++ value was never
/// constructed. (The caster passes the type it already looked up: each lookup hashes the C++ type's
/// name, and a small query's arguments would pay for several.)
inline bool is_half_built(pybind11::handle object, const pybind11::detail::type_info* type) {
  if (!object || type == nullptr || !PyObject_TypeCheck(object.ptr(), type->type)) return false;
  auto* instance = reinterpret_cast<pybind11::detail::instance*>(object.ptr());
  const auto value = instance->get_value_and_holder(type, false);
  return !value || !value.holder_constructed();
}

/// Makes `method` (`__init__`, `__setstate__`) of the bound class T refuse, with caliber.Error, an
/// instance that is already built (pybind11 would silently ignore the call: the object would keep
/// its old value while the caller believes it holds the new one).
template <class T>
void refuse_second(pybind11::object cls, const char* method, const char* name) {
  pybind11::object original = cls.attr(method);
  const std::string message = std::string("is already built: ") + method + " runs once, on a new object";
  const std::string doc = pybind11::str(original.attr("__doc__"));  // copied by pybind11
  // Not named __init__ or __setstate__: pybind11 would treat the guard as a constructor and skip it.
  const std::string guard_name = std::string(method) + "once";
  auto guarded = pybind11::cpp_function(
      [original, message, name](pybind11::handle self, pybind11::args args, pybind11::kwargs kwargs) {
        if (!is_half_built(self, pybind11::detail::get_type_info(typeid(T))))
          throw caliber::Error(caliber::ErrorCode::bad_argument, name, message);
        original(self, *args, **kwargs);
      },
      pybind11::name(guard_name.c_str()), pybind11::is_method(cls), pybind11::doc(doc.c_str()));
  cls.attr(method) = guarded;
}

}  // namespace caliber_python

/// The caster of a bound class `Type` (named `name` in messages) that refuses half-built instances.
#define CALIBER_REFUSE_HALF_BUILT(Type, name)                                                                     \
  namespace pybind11::detail {                                                                                    \
  template <>                                                                                                     \
  class type_caster<Type> : public type_caster_base<Type> {                                                       \
   public:                                                                                                        \
    bool load(handle src, bool convert) {                                                                         \
      if (caliber_python::is_half_built(src, this->typeinfo)) {                                                   \
        throw caliber::Error(caliber::ErrorCode::bad_argument, name,                                              \
                             "was never built (made by __new__, or unpickled without its state); build one with " \
                             "its constructor or unpickle a complete state");                                     \
      }                                                                                                           \
      return type_caster_base<Type>::load(src, convert);                                                          \
    }                                                                                                             \
  };                                                                                                              \
  }
