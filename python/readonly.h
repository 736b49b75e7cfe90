#pragma once
// Result objects whose numpy arrays Python reads but cannot change: each array is made read-only
// once written, and each attribute returns a view of it (a new numpy object, so that changing the
// view's shape or dtype leaves the object's own array as it is).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <initializer_list>

namespace caliber_python {

/// Makes each array read-only (its object's methods write before this, never after).
inline void freeze(std::initializer_list<pybind11::array*> arrays) {
  for (pybind11::array* a : arrays) a->attr("flags").attr("writeable") = false;
}

/// A view of the array `Member` of an object of class C: what its attribute returns.
template <class C, auto Member>
pybind11::object view_of(const C& object) {
  return (object.*Member).attr("view")();
}

}  // namespace caliber_python
