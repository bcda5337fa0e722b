#pragma once  // SPDX-License-Identifier: Apache-2.0
// A small, strict command-line parser shared by viscera's programs: every flag is declared with
// its help text; unknown flags, missing values and bad numbers give one clear line.
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace viscera::common {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CommandLine {
 public:
  CommandLine(std::string program, std::string summary);

  /// Declares --name VALUE (default shown in help) or, with is_switch, a boolean --name.
  void flag(const std::string& name, const std::string& value_name, const std::string& help, std::optional<std::string> default_value = std::nullopt);
  void option_switch(const std::string& name, const std::string& help);

  /// The usage line of --help (default "PROGRAM [options]"), e.g. "viscera-lab analyze DIR --out DIR".
  void usage(std::string line) { usage_ = std::move(line); }
  /// Accepts up to n arguments that are not flags (default none: they are errors).
  void allow_positional(std::size_t n) { max_positional_ = n; }
  const std::vector<std::string>& positional() const { return positional_; }

  /// Parses argv. Returns false if --help was given (help already printed to stdout).
  bool parse(int argc, char** argv);

  /// Given on the command line, or declared with a default.
  bool has(const std::string& name) const;
  /// Given on the command line (a default does not count).
  bool given(const std::string& name) const { return values_.count(name) > 0; }
  std::string text(const std::string& name) const;
  double number(const std::string& name) const;
  /// A number that must satisfy lo <= v <= hi.
  double number_in(const std::string& name, double lo, double hi) const;
  long integer(const std::string& name) const;
  /// A whole number with lo <= v <= hi ("1.5" and "1e400" are refused, never truncated). Written
  /// as a decimal or in exponent form ("1e6"), up to 2^53.
  std::uint64_t integer_in(const std::string& name, std::uint64_t lo, std::uint64_t hi) const;
  /// Comma-separated numbers, exactly `count` of them.
  std::vector<double> numbers(const std::string& name, std::size_t count) const;
  std::string help() const;

 private:
  struct Flag {
    std::string value_name, help;
    std::optional<std::string> default_value;
    bool is_switch = false;
  };
  std::string program_, summary_, usage_;
  std::vector<std::string> order_;
  std::map<std::string, Flag> flags_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
  std::size_t max_positional_ = 0;
};

}  // namespace viscera::common
