#pragma once  // SPDX-License-Identifier: Apache-2.0
// The lines and cells of a delimited text file (a data set's CSV, a test machine's export): lines
// one at a time with a UTF-8 byte-order mark (spreadsheet exports) taken off, cells with the
// spaces, carriage returns and double quotes around them taken off.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::lab {

class CsvLines {
 public:
  explicit CsvLines(std::string_view text) : text_(text) {
    if (text_.starts_with("\xEF\xBB\xBF")) text_.remove_prefix(3);
  }
  /// The next line without its line end: "\n", "\r\n", or a lone "\r" (classic Mac OS, and
  /// some test machines' exports); nullopt at the end.
  std::optional<std::string_view> next() {
    if (text_.empty()) return std::nullopt;
    const std::size_t end = text_.find_first_of("\r\n");
    const std::string_view line = text_.substr(0, end);
    std::size_t skip = end == std::string_view::npos ? text_.size() : end + 1;
    if (end != std::string_view::npos && text_[end] == '\r' && end + 1 < text_.size() && text_[end + 1] == '\n') ++skip;
    text_.remove_prefix(skip);
    return line;
  }

 private:
  std::string_view text_;
};

/// The cells of `line` separated by `separator`.
inline std::vector<std::string> csv_cells(std::string_view line, char separator = ',') {
  std::vector<std::string> out;
  for (;;) {
    const std::size_t at = line.find(separator);
    std::string_view cell = line.substr(0, at);
    while (!cell.empty() && (cell.back() == '\r' || cell.back() == ' ' || cell.back() == '"')) cell.remove_suffix(1);
    while (!cell.empty() && (cell.front() == ' ' || cell.front() == '"')) cell.remove_prefix(1);
    out.emplace_back(cell);
    if (at == std::string_view::npos) return out;
    line.remove_prefix(at + 1);
  }
}

}  // namespace viscera::lab
