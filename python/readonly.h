#pragma once
// Result objects whose numpy arrays Python reads but cannot change: each attribute returns a
// read-only view of the object's array whose base is the object (so that neither the view nor
// its base reaches the array itself).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <utility>
#include <vector>

namespace caliber_python {

/// A read-only view of the array `Member` of the object `self` (of class C): what its attribute
/// returns. The view's base is `self`, not the array, so that nothing reached through it can
/// change the array's dtype, shape or flags; `self` keeps the data alive.
template <class C, auto Member>
pybind11::object view_of(pybind11::object self) {
  const C& object = self.cast<const C&>();
  const pybind11::array& a = object.*Member;
  const std::vector<pybind11::ssize_t> shape(a.shape(), a.shape() + a.ndim()), strides(a.strides(), a.strides() + a.ndim());
  pybind11::array view(a.dtype(), shape, strides, a.data(), self);
  view.attr("flags").attr("writeable") = false;  // and not to be set again: its base is no writeable buffer
  return view;
}

}  // namespace caliber_python
