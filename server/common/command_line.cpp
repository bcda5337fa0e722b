#include "viscera/common/command_line.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <sstream>

#include "viscera/common/number_text.hpp"

namespace viscera::common {

CommandLine::CommandLine(std::string program, std::string summary) : program_(std::move(program)), summary_(std::move(summary)) {}

void CommandLine::flag(const std::string& name, const std::string& value_name, const std::string& help, std::optional<std::string> default_value) {
  order_.push_back(name);
  flags_[name] = {value_name, help, std::move(default_value), false};
}

void CommandLine::option_switch(const std::string& name, const std::string& help) {
  order_.push_back(name);
  flags_[name] = {"", help, std::nullopt, true};
}

std::string CommandLine::help() const {
  std::ostringstream s;
  s << "Usage: " << (usage_.empty() ? program_ + " [options]" : usage_) << "\n\n" << summary_ << "\n\nOptions:\n";
  for (const auto& name : order_) {
    const Flag& f = flags_.at(name);
    std::string left = "  --" + name + (f.is_switch ? "" : " " + f.value_name);
    if (left.size() < 34)
      left.resize(34, ' ');
    else
      left += "\n" + std::string(34, ' ');
    s << left << f.help;
    if (f.default_value) s << " (default: " << *f.default_value << ")";
    s << "\n";
  }
  s << "  --help                          print this help and exit\n";
  return s.str();
}

bool CommandLine::parse(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << help();
      return false;
    }
    if (!arg.starts_with("--")) {
      if (positional_.size() >= max_positional_) throw UsageError("unexpected argument '" + arg + "' (see --help)");
      positional_.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2), value;
    const auto eq = name.find('=');
    bool has_value = false;
    if (eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_value = true;
    }
    const auto it = flags_.find(name);
    if (it == flags_.end()) throw UsageError("unknown option --" + name + " (see --help)");
    if (it->second.is_switch) {
      if (has_value) throw UsageError("--" + name + " takes no value");
      values_[name] = "1";
      continue;
    }
    if (!has_value) {
      if (i + 1 >= argc) throw UsageError("--" + name + " needs a value (" + it->second.value_name + ")");
      value = argv[++i];
    }
    values_[name] = value;
  }
  return true;
}

bool CommandLine::has(const std::string& name) const { return values_.count(name) || (flags_.count(name) && flags_.at(name).default_value); }

std::string CommandLine::text(const std::string& name) const {
  if (const auto it = values_.find(name); it != values_.end()) return it->second;
  const auto& f = flags_.at(name);
  if (!f.default_value) throw UsageError("--" + name + " is required (see --help)");
  return *f.default_value;
}

namespace {
double parse_number(const std::string& name, const std::string& t) {
  std::string why;
  const auto v = read_number(t, &why);
  if (!v) throw UsageError("--" + name + ": " + why);
  return *v;
}
}  // namespace

double CommandLine::number(const std::string& name) const { return parse_number(name, text(name)); }

double CommandLine::number_in(const std::string& name, double lo, double hi) const {
  const double v = number(name);
  if (v < lo || v > hi) throw UsageError("--" + name + ": " + outside(v, lo, hi));
  return v;
}

long CommandLine::integer(const std::string& name) const {
  std::string why;
  const auto v = read_integer(text(name), &why);
  if (!v) throw UsageError("--" + name + ": " + why);
  return static_cast<long>(*v);
}

std::uint64_t CommandLine::integer_in(const std::string& name, std::uint64_t lo, std::uint64_t hi) const {
  const long long v = integer(name);
  constexpr std::uint64_t kMax = std::numeric_limits<long long>::max();
  const auto l = static_cast<long long>(std::min(lo, kMax)), h = static_cast<long long>(std::min(hi, kMax));
  if (v < l || v > h) throw UsageError("--" + name + ": " + outside(v, l, h));
  return static_cast<std::uint64_t>(v);
}

std::vector<double> CommandLine::numbers(const std::string& name, std::size_t count) const {
  std::vector<double> out;
  std::stringstream ss(text(name));
  std::string part;
  while (std::getline(ss, part, ',')) out.push_back(parse_number(name, part));
  if (out.size() != count)
    throw UsageError("--" + name + ": expected " + std::to_string(count) + " comma-separated numbers, got '" + text(name) + "'");
  return out;
}

}  // namespace viscera::common
