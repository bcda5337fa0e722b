#pragma once  // SPDX-License-Identifier: Apache-2.0
// The submodules of viscera's extension module (_viscera), one file each.
#include <pybind11/pybind11.h>

namespace viscera::python {

void bind_errors(pybind11::module_& m);
void bind_recording(pybind11::module_& m);
void bind_tissue(pybind11::module_& m);
void bind_lab(pybind11::module_& m);
void bind_session(pybind11::module_& m);

}  // namespace viscera::python
