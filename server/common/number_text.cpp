#include "viscera/common/number_text.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <charconv>
#include <cmath>

#include "viscera/common/input_error.hpp"

namespace viscera::common {

namespace {
std::string quoted(std::string_view text) { return "'" + printable(text) + "'"; }
}  // namespace

std::optional<double> read_number(std::string_view text, std::string* why) {
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || end != text.data() + text.size() || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    if (why) *why = quoted(text) + " is not a number";
    return std::nullopt;
  }
  if (ec == std::errc::result_out_of_range || !std::isfinite(v)) {
    if (why) *why = quoted(text) + " is not a finite number";
    return std::nullopt;
  }
  return v;
}

std::optional<long long> read_integer(std::string_view text, std::string* why) {
  long long v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (!text.empty() && ec == std::errc() && end == text.data() + text.size()) return v;
  const auto x = read_number(text, why);
  if (!x) return std::nullopt;
  if (*x != std::floor(*x) || std::abs(*x) > 9007199254740992.0) {
    if (why) *why = quoted(text) + " is not a whole number";
    return std::nullopt;
  }
  return static_cast<long long>(*x);
}

std::string outside(double v, double lo, double hi) { return short_number(v) + " is outside [" + short_number(lo) + ", " + short_number(hi) + "]"; }

std::string outside(long long v, long long lo, long long hi) {
  return std::to_string(v) + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
}

}  // namespace viscera::common
