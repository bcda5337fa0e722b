#pragma once  // SPDX-License-Identifier: Apache-2.0
// Numbers read from text (command lines, CSV and mesh files, recordings' metadata), and the one
// wording of what is wrong with one, so that every program says it the same way:
//   'abc' is not a number        'nan' is not a finite number
//   '2.5' is not a whole number  -5 is outside [1, 3600]
#include <optional>
#include <string>
#include <string_view>

namespace viscera::common {

/// The whole of `text` as a finite number; otherwise nullopt, and `why` (if given) says why.
std::optional<double> read_number(std::string_view text, std::string* why = nullptr);
/// The whole of `text` as a whole number ("12", "-3", "1e3"; exact up to 2^53 when written with an
/// exponent or a point); otherwise nullopt, and `why` says why.
std::optional<long long> read_integer(std::string_view text, std::string* why = nullptr);
/// "V is outside [LO, HI]": reals with six significant digits, whole numbers exactly.
std::string outside(double v, double lo, double hi);
std::string outside(long long v, long long lo, long long hi);

}  // namespace viscera::common
