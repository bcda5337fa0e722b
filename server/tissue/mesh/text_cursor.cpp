#include "viscera/tissue/mesh/text_cursor.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>

#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/common/number_text.hpp"

namespace viscera::tissue {

using common::InputError;
using common::printable;
using common::read_text_file;

namespace {
// One definition of whitespace for skipping and for ending a token: with two (a form feed was
// "space" to one and not to the other) a token could be empty and a scan never advance.
bool is_space(char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
}  // namespace

TextCursor::TextCursor(std::string source, std::string text) : source_(std::move(source)), text_(std::move(text)) {}

TextCursor TextCursor::from_file(const std::string& path) {
  std::string text = read_text_file(path, std::size_t{4} << 30);
  if (const auto nul = text.find('\0'); nul != std::string::npos) {
    const long line = 1 + static_cast<long>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(nul), '\n'));
    throw InputError(path, line, "", "holds binary data (a NUL byte at byte " + std::to_string(nul) + "): not a text mesh file; save it as ASCII");
  }
  return TextCursor(path, std::move(text));
}

long TextCursor::next_line() {
  skip_space();
  return line_;
}

void TextCursor::skip_space() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n')
      ++line_;
    else if (!is_space(c))
      break;
    ++pos_;
  }
}

bool TextCursor::at_end() {
  skip_space();
  return pos_ >= text_.size();
}

void TextCursor::fail(std::string_view field, const std::string& message) const { throw InputError(source_, line_, std::string(field), message); }

std::string_view TextCursor::token(std::string_view field) {
  skip_space();
  if (pos_ >= text_.size()) fail(field, "unexpected end of file (truncated?)");
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
  return std::string_view(text_).substr(start, pos_ - start);
}

double TextCursor::real(std::string_view field) {
  std::string why;
  const auto v = common::read_number(token(field), &why);
  if (!v) fail(field, why);
  return *v;
}

long long TextCursor::integer(std::string_view field) {
  std::string why;
  const auto v = common::read_integer(token(field), &why);
  if (!v) fail(field, why);
  return *v;
}

long long TextCursor::integer_in(std::string_view field, long long lo, long long hi) {
  const long long v = integer(field);
  if (v < lo || v > hi) fail(field, common::outside(v, lo, hi));
  return v;
}

std::string TextCursor::rest_of_line() {
  const std::size_t start = pos_;
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  std::string s = text_.substr(start, pos_ - start);
  if (pos_ < text_.size()) {
    ++pos_;
    ++line_;
  }
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

bool TextCursor::skip_past(std::string_view marker) {
  while (!at_end())
    if (token("") == marker) return true;
  return false;
}

}  // namespace viscera::tissue
