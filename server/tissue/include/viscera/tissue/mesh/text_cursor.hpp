#pragma once  // SPDX-License-Identifier: Apache-2.0
// A whitespace tokenizer over a whole text file that knows its line numbers, so that every
// parse error names the file, the line and the field.
#include <string>
#include <string_view>

namespace viscera::tissue {

class TextCursor {
 public:
  TextCursor(std::string source, std::string text);

  /// Reads a whole text file; throws InputError naming the path if it cannot be read, is not a
  /// regular file, or holds binary data (a NUL byte).
  static TextCursor from_file(const std::string& path);

  bool at_end();
  long line() const { return line_; }
  /// The line on which the next token starts (skips the whitespace before it).
  long next_line();
  const std::string& source() const { return source_; }

  /// Next whitespace-separated token; throws InputError ("unexpected end of file") at the end.
  std::string_view token(std::string_view field);
  /// Next token parsed as a number; NaN/inf and garbage are errors naming the field.
  double real(std::string_view field);
  long long integer(std::string_view field);
  /// Integer in [lo, hi].
  long long integer_in(std::string_view field, long long lo, long long hi);
  /// Consumes the rest of the current line.
  std::string rest_of_line();
  /// Skips tokens until (and including) the one equal to `marker`; false if never found.
  bool skip_past(std::string_view marker);

  [[noreturn]] void fail(std::string_view field, const std::string& message) const;

 private:
  void skip_space();
  std::string source_;
  std::string text_;
  std::size_t pos_ = 0;
  long line_ = 1;
};

}  // namespace viscera::tissue
