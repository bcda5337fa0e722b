#pragma once  // SPDX-License-Identifier: Apache-2.0
// numpy arrays over C++ buffers without copying them: the array owns the vector it views (moved
// into a capsule), or views memory of an object that it keeps alive. Read-only either way.
#include <memory>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

namespace viscera::python {

namespace py = pybind11;

/// Marks an array read-only (numpy refuses writes with "assignment destination is read-only").
template <class T>
py::array_t<T> read_only(py::array_t<T> a) {
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

/// The vector's elements as an array of that shape (C order), owning the vector: no copy.
template <class T>
py::array_t<T> owning_array(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto held = std::make_unique<std::vector<T>>(std::move(v));
  const T* data = held->data();
  py::capsule owner(held.get(), [](void* p) { std::unique_ptr<std::vector<T>>(static_cast<std::vector<T>*>(p)).reset(); });
  static_cast<void>(held.release());  // the capsule owns it now
  return read_only(py::array_t<T>(std::move(shape), data, owner));
}
template <class T>
py::array_t<T> owning_array(std::vector<T>&& v) {
  const auto n = static_cast<py::ssize_t>(v.size());
  return owning_array(std::move(v), {n});
}

/// A view of `count` elements at `data` with that shape and strides [bytes], kept valid by `owner`.
template <class T>
py::array_t<T> view_array(const T* data, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides, py::handle owner) {
  return read_only(py::array_t<T>(std::move(shape), std::move(strides), data, owner));
}

}  // namespace viscera::python
