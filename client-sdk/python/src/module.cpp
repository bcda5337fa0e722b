// _viscera: the extension module under the viscera Python package (client-sdk/python/viscera),  // SPDX-License-Identifier: Apache-2.0
// a submodule per part: recording, tissue, lab, session. docs/PYTHON.md.
#include <pybind11/pybind11.h>

#include "viscera/common/command_line.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"

#include "bindings.hpp"

namespace viscera::python {

void bind_errors(pybind11::module_& m) {
  // The programs' one-line messages, as exceptions: bad input (a file, a field, a value), a bad
  // argument, a simulation that went unstable.
  pybind11::register_exception<common::InputError>(m, "InputError", PyExc_ValueError);
  pybind11::register_exception<common::UsageError>(m, "UsageError", PyExc_ValueError);
  pybind11::register_exception<tissue::SimulationError>(m, "SimulationError", PyExc_RuntimeError);
}

}  // namespace viscera::python

PYBIND11_MODULE(_viscera, m) {
  m.doc() = "viscera's C++ core for Python: recordings, the tissue core, the lab and live sessions (docs/PYTHON.md).";
  viscera::python::bind_errors(m);
  auto recording = m.def_submodule("recording", "Session recordings (MCAP) read by viscera's own reader.");
  viscera::python::bind_recording(recording);
  auto tissue = m.def_submodule("tissue", "The tissue core: meshes, force models, integrators (SI units).");
  viscera::python::bind_tissue(tissue);
  auto lab = m.def_submodule("lab", "viscera-lab: data sets, the analysis, predictions.");
  viscera::python::bind_lab(lab);
  auto session = m.def_submodule("session", "A client of a running viscera-server over DDS.");
  viscera::python::bind_session(session);
}
