#pragma once  // SPDX-License-Identifier: Apache-2.0
#include <stdexcept>

namespace viscera::tissue {

/// Numerical failure detected while integrating (instability, non-convergence).
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace viscera::tissue
