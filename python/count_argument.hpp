// Count: an integer argument of the Python module that a Python bool is not (bindings.hpp and
// system_continuation.cpp use it for samples, points, modes and segments).
#pragma once

#include <pybind11/pybind11.h>

namespace kirchhoff::python_bindings {

// An integer argument (a count: samples, points, modes, segments) that refuses a Python bool:
// pybind11 takes True for 1, bool being a subclass of int, so `max_points=True` ran one point.
// A bool or a float is then a TypeError naming the function's signature; integers, numpy's
// included, convert as before.
struct Count {
  int value = 0;
  Count() = default;
  Count(int v) : value(v) {}  // NOLINT: defaults are written as plain ints
  operator int() const { return value; }  // NOLINT: used where an int is
};

}  // namespace kirchhoff::python_bindings

namespace pybind11::detail {
template <>
struct type_caster<kirchhoff::python_bindings::Count> {
  PYBIND11_TYPE_CASTER(kirchhoff::python_bindings::Count, const_name("int"));
  bool load(handle src, bool convert) {
    if (!src || PyBool_Check(src.ptr())) return false;
    type_caster<int> as_int;
    if (!as_int.load(src, convert)) return false;
    value = kirchhoff::python_bindings::Count(static_cast<int>(as_int));
    return true;
  }
  static handle cast(const kirchhoff::python_bindings::Count& c, return_value_policy, handle) {
    return PyLong_FromLong(c.value);
  }
};
}  // namespace pybind11::detail
