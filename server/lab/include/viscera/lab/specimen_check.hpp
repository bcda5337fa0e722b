#pragma once  // SPDX-License-Identifier: Apache-2.0
// A model run on the tetrahedral specimen (viscera's GPS, implicit, inertia) beside its
// material-point law, test by test, as viscera-lab analyze reports it: each test within a bounded
// wall time with a progress line, where the specimen first leaves the law, and, when the specimen
// cannot follow, why, with the analysis going on with the law.
#include <functional>
#include <string>

#include "viscera/lab/analysis.hpp"

namespace viscera::lab {

/// Wall time one test may take on the specimen before its run stops and says where it was.
inline constexpr double kSpecimenSecondsPerTest = 60.0;

/// Runs `m` on every test's specimen; `say` receives a progress line per test.
SpecimenCheck check_on_specimen(const MaterialModel& m, const Dataset& d, const std::function<void(const std::string&)>& say);

}  // namespace viscera::lab
