#pragma once  // SPDX-License-Identifier: Apache-2.0
// Errors at the boundaries of every program and library (files, configuration, arguments) carry where the
// bad value came from, so that a user can act on a single line of text.
#include <stdexcept>
#include <string>
#include <string_view>

namespace viscera::common {

/// Bad input from outside the core: a file, a field or an argument. what() is one line:
/// "<source>[:<line>]: <field>: <message>".
class InputError : public std::runtime_error {
 public:
  InputError(std::string source, long line, std::string field, const std::string& message);
  const std::string& source() const { return source_; }
  long line() const { return line_; }
  const std::string& field() const { return field_; }

 private:
  std::string source_;
  long line_;
  std::string field_;
};

/// A number for messages: six significant digits ("1e+300", "0.0123", "inf").
std::string short_number(double v);
/// A number that reads back as the same double (17 significant digits).
std::string exact_number(double v);
/// Text from a file for messages: at most `max_chars` characters, bytes that are not printable
/// ASCII shown as \xNN, "..." when cut.
std::string printable(std::string_view text, std::size_t max_chars = 40);

}  // namespace viscera::common
