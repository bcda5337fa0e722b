#pragma once  // SPDX-License-Identifier: Apache-2.0
// Reading hand-edited JSON files (scenes, materials, data sets, models, exercises) so that no
// input can crash a program: the file must be a regular file of bounded size, every syntax error
// and number overflow becomes one InputError naming the file and line, a key given twice is an
// error, and fields are read through JsonObject, which checks type, range and unknown keys and
// names the file and the field's path in every message.
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace viscera::common {

/// Reads a regular file of at most `max_bytes` as text; InputError naming the path otherwise
/// (missing, a directory, a FIFO or device, too large, unreadable).
std::string read_text_file(const std::string& path, std::size_t max_bytes);

/// The deepest nesting of objects and arrays any JSON input may have (files and messages alike).
inline constexpr std::size_t kMaxJsonDepth = 64;

/// Parses JSON text (a UTF-8 byte-order mark is skipped). Syntax errors, numbers that overflow a
/// double, keys given twice in one object and nesting deeper than kMaxJsonDepth throw
/// InputError(source, line, ...).
nlohmann::json parse_json(std::string_view text, const std::string& source);
/// parse_json for text that is not a file (a browser's message, a recorded scene's settings): the
/// document, or nothing with the reason in `why`.
std::optional<nlohmann::json> try_parse_json(std::string_view text, std::string* why = nullptr);
/// read_text_file (at most 16 MiB) + parse_json.
nlohmann::json read_json_file(const std::string& path);

/// A JSON value shown in an error message: at most `max_chars` characters, numbers with six
/// significant digits, non-printable bytes escaped.
std::string show_json(const nlohmann::json& value, std::size_t max_chars = 60);

/// A JSON object of a file, read field by field. `path` is the object's place in the file
/// ("" for the top level, "organ", "tests[2]") and prefixes the field names in messages.
class JsonObject {
 public:
  /// Throws InputError if `value` is not an object.
  JsonObject(const nlohmann::json& value, std::string source, std::string path = {});

  const nlohmann::json& value() const { return value_; }
  const std::string& source() const { return source_; }
  /// The field's full name in messages: "organ.mesh".
  std::string field(std::string_view key) const;
  bool has(const char* key) const { return value_.contains(key); }

  /// Throws for the first key that is not in `known`, listing the known ones.
  void require_known(std::initializer_list<const char*> known) const;

  /// A finite number in [lo, hi]; required, or `fallback` when absent.
  double number(const char* key, double lo, double hi) const;
  double number(const char* key, double lo, double hi, double fallback) const;
  /// A whole number in [lo, hi].
  long long integer(const char* key, long long lo, long long hi) const;
  long long integer(const char* key, long long lo, long long hi, long long fallback) const;
  std::string text(const char* key) const;
  std::string text(const char* key, const std::string& fallback) const;
  /// One of `choices`.
  std::string choice(const char* key, std::initializer_list<const char*> choices, const std::string& fallback) const;
  bool boolean(const char* key, bool fallback) const;
  /// A nested object (required).
  JsonObject object(const char* key) const;
  /// An array (required; at least `min_size` elements).
  const nlohmann::json& array(const char* key, std::size_t min_size = 0) const;
  /// An array of exactly `count` finite numbers, each in [lo, hi].
  std::vector<double> numbers(const char* key, std::size_t count, double lo, double hi) const;

  [[noreturn]] void fail(std::string_view key, const std::string& message) const;

 private:
  const nlohmann::json& value_;
  std::string source_, path_;
};

}  // namespace viscera::common
