#include "viscera/common/json_input.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <vector>

#include <sys/stat.h>

#include "viscera/common/input_error.hpp"
#include "viscera/common/plain_name.hpp"

namespace viscera::common {

using nlohmann::json;

std::string read_text_file(const std::string& path, std::size_t max_bytes) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw InputError(path, 0, "", std::string("cannot open file: ") + std::strerror(errno));
  // A FIFO or device would block or never end: only regular files are read.
  if (S_ISDIR(st.st_mode)) throw InputError(path, 0, "", "is a directory, not a file");
  if (!S_ISREG(st.st_mode)) throw InputError(path, 0, "", "is not a regular file (a FIFO, socket or device?)");
  if (static_cast<std::size_t>(st.st_size) > max_bytes)
    throw InputError(path, 0, "", "is " + std::to_string(st.st_size) + " bytes, more than the " + std::to_string(max_bytes) + " this file may have");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "", "cannot open file");
  std::string text(static_cast<std::size_t>(st.st_size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  return text;
}

namespace {

/// Builds the document with nlohmann's own DOM builder, and on the way notes where the parser
/// stopped (for the line of any error) and keys given twice in one object (nlohmann keeps the
/// last silently).
class CheckedDomBuilder {
 public:
  explicit CheckedDomBuilder(json& root) : dom_(root, false) {}

  bool null() { return value() && dom_.null(); }
  bool boolean(bool v) { return value() && dom_.boolean(v); }
  bool number_integer(json::number_integer_t v) { return value() && dom_.number_integer(v); }
  bool number_unsigned(json::number_unsigned_t v) { return value() && dom_.number_unsigned(v); }
  bool number_float(json::number_float_t v, const std::string& s) { return value() && dom_.number_float(v, s); }
  bool string(std::string& v) { return value() && dom_.string(v); }
  bool binary(json::binary_t& v) { return value() && dom_.binary(v); }
  bool start_object(std::size_t n) {
    if (!value() || !deeper()) return false;
    frames_.push_back({true, {}, {}, 0});
    return dom_.start_object(n);
  }
  bool key(std::string& k) {
    Frame& f = frames_.back();
    if (!f.keys.insert(k).second) {
      duplicate_ = path() + (path().empty() ? "" : ".") + k;
      return false;
    }
    f.key = k;
    return dom_.key(k);
  }
  bool end_object() {
    frames_.pop_back();
    return dom_.end_object();
  }
  bool start_array(std::size_t n) {
    if (!value() || !deeper()) return false;
    frames_.push_back({false, {}, {}, 0});
    return dom_.start_array(n);
  }
  bool end_array() {
    frames_.pop_back();
    return dom_.end_array();
  }
  bool parse_error(std::size_t position, const std::string& /*last_token*/, const nlohmann::detail::exception& e) {
    error_position_ = position;
    error_ = e.what();
    // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." -> the part after "]".
    if (const auto close = error_.find("] "); close != std::string::npos) error_ = error_.substr(close + 2);
    return false;
  }

  std::size_t error_position() const { return error_position_; }
  const std::string& error() const { return error_; }
  const std::string& duplicate() const { return duplicate_; }
  bool too_deep() const { return too_deep_; }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;
    std::size_t index;
  };
  /// An object or array may open only below kMaxJsonDepth: every later walk of the document
  /// (printing a value in a message, nlohmann's dump) recurses once per level.
  bool deeper() {
    if (frames_.size() < kMaxJsonDepth) return true;
    too_deep_ = true;
    return false;
  }
  /// A value starts: an element of the enclosing array takes the next index.
  bool value() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
    return true;
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) {
      if (&f == &frames_.back() && f.object) break;  // the key being read is appended by the caller
      if (f.object)
        p += (p.empty() ? "" : ".") + f.key;
      else
        p += "[" + std::to_string(f.index - 1) + "]";
    }
    return p;
  }

  nlohmann::detail::json_sax_dom_parser<json> dom_;
  std::vector<Frame> frames_;
  std::size_t error_position_ = 0;
  std::string error_, duplicate_;
  bool too_deep_ = false;
};

}  // namespace

json parse_json(std::string_view text, const std::string& source) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  json root;
  CheckedDomBuilder builder(root);
  if (!json::sax_parse(text.begin(), text.end(), &builder)) {
    if (!builder.duplicate().empty()) throw InputError(source, 0, builder.duplicate(), "given twice (each field once)");
    if (builder.too_deep()) throw InputError(source, 0, "JSON", "objects and arrays nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    const std::size_t upto = std::min(builder.error_position(), text.size());
    const long line = 1 + static_cast<long>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(upto), '\n'));
    throw InputError(source, line, "JSON", printable(builder.error(), 200));
  }
  return root;
}

std::optional<json> try_parse_json(std::string_view text, std::string* why) {
  try {
    return parse_json(text, "JSON");
  } catch (const InputError& e) {
    if (why) *why = e.what();
    return std::nullopt;
  }
}

json read_json_file(const std::string& path) { return parse_json(read_text_file(path, std::size_t{16} << 20), path); }

std::string show_json(const json& value, std::size_t max_chars) {
  if (value.is_number_float()) return short_number(value.get<double>());
  return printable(value.dump(-1, ' ', false, json::error_handler_t::replace), max_chars);
}

JsonObject::JsonObject(const json& value, std::string source, std::string path) : value_(value), source_(std::move(source)), path_(std::move(path)) {
  if (!value_.is_object()) throw InputError(source_, 0, path_.empty() ? "JSON" : path_, show_json(value_) + " is not an object");
}

std::string JsonObject::field(std::string_view key) const { return path_.empty() ? std::string(key) : path_ + "." + std::string(key); }

void JsonObject::fail(std::string_view key, const std::string& message) const { throw InputError(source_, 0, field(key), message); }

void JsonObject::require_known(std::initializer_list<const char*> known) const {
  for (const auto& item : value_.items()) {
    const std::string& key = item.key();
    if (std::any_of(known.begin(), known.end(), [&](const char* k) { return key == k; })) continue;
    std::string list;
    for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + k;
    fail(printable(key), "unknown field (known here: " + list + ")");
  }
}

double JsonObject::number(const char* key, double lo, double hi) const {
  if (!has(key)) fail(key, "missing");
  const json& v = value_[key];
  if (!v.is_number()) fail(key, show_json(v) + " is not a number");
  const double x = v.get<double>();
  if (!std::isfinite(x) || !(x >= lo && x <= hi)) fail(key, show_json(v) + " is outside [" + short_number(lo) + ", " + short_number(hi) + "]");
  return x;
}

double JsonObject::number(const char* key, double lo, double hi, double fallback) const { return has(key) ? number(key, lo, hi) : fallback; }

long long JsonObject::integer(const char* key, long long lo, long long hi) const {
  const double x = number(key, static_cast<double>(lo), static_cast<double>(hi));
  if (x != std::floor(x)) fail(key, show_json(value_[key]) + " is not a whole number");
  return static_cast<long long>(x);
}

long long JsonObject::integer(const char* key, long long lo, long long hi, long long fallback) const {
  return has(key) ? integer(key, lo, hi) : fallback;
}

std::string JsonObject::text(const char* key) const {
  if (!has(key)) fail(key, "missing");
  const json& v = value_[key];
  if (!v.is_string()) fail(key, show_json(v) + " is not a string");
  std::string s = v.get<std::string>();
  if (has_control_characters(s)) fail(key, "'" + printable(s, 80) + "' holds a control character (a newline, an escape): text fields are printed");
  return s;
}

std::string JsonObject::text(const char* key, const std::string& fallback) const { return has(key) ? text(key) : fallback; }

std::string JsonObject::choice(const char* key, std::initializer_list<const char*> choices, const std::string& fallback) const {
  std::string v = text(key, fallback);
  if (std::any_of(choices.begin(), choices.end(), [&](const char* c) { return v == c; })) return v;
  std::string list;
  for (const char* c : choices) list += std::string(list.empty() ? "" : " | ") + c;
  fail(key, "'" + printable(v) + "' is not one of " + list);
}

bool JsonObject::boolean(const char* key, bool fallback) const {
  if (!has(key)) return fallback;
  const json& v = value_[key];
  if (!v.is_boolean()) fail(key, show_json(v) + " is not true or false");
  return v.get<bool>();
}

JsonObject JsonObject::object(const char* key) const {
  if (!has(key)) fail(key, "missing (an object)");
  return JsonObject(value_[key], source_, field(key));
}

const json& JsonObject::array(const char* key, std::size_t min_size) const {
  if (!has(key)) fail(key, "missing (an array)");
  const json& v = value_[key];
  if (!v.is_array()) fail(key, show_json(v) + " is not an array");
  if (v.size() < min_size) fail(key, "has " + std::to_string(v.size()) + " elements, at least " + std::to_string(min_size) + " expected");
  return v;
}

std::vector<double> JsonObject::numbers(const char* key, std::size_t count, double lo, double hi) const {
  const json& v = array(key);
  if (v.size() != count) fail(key, show_json(v) + " must be " + std::to_string(count) + " numbers");
  std::vector<double> out;
  for (std::size_t k = 0; k < count; ++k) {
    const json& x = v[k];
    const std::string name = std::string(key) + "[" + std::to_string(k) + "]";
    if (!x.is_number()) fail(name, show_json(x) + " is not a number");
    const double d = x.get<double>();
    if (!std::isfinite(d) || !(d >= lo && d <= hi)) fail(name, show_json(x) + " is outside [" + short_number(lo) + ", " + short_number(hi) + "]");
    out.push_back(d);
  }
  return out;
}

}  // namespace viscera::common
