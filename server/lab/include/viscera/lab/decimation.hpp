#pragma once  // SPDX-License-Identifier: Apache-2.0
// Large tests made small enough to fit: a test of a million rows (a logger at 10 kHz) carries no
// more shape than a few thousand well-placed samples, and every fit and held-out evaluation costs
// time in proportion to the rows. decimate() keeps measured samples (never averages, so the noise
// of each kept point is the measurement's), placed evenly along the test's path in (time, strain)
// normalised by their spans: dense where the strain changes fast (ramps, cycles), sparse in holds.
#include <cstddef>

#include "viscera/lab/dataset.hpp"

namespace viscera::lab {

/// The tests with more than `max_points` rows reduced to at most `max_points` (the first and last
/// kept). Where a test has no stress_sd_pa column, the kept points get the noise level estimated on
/// all its rows, so that the noise the analysis compares against is the full test's.
Dataset decimate(const Dataset& d, std::size_t max_points);

}  // namespace viscera::lab
