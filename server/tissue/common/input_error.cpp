#include "common/input_error.hpp"

namespace viscera::tissue {

namespace {
std::string compose(const std::string& source, long line, const std::string& field,
                    const std::string& message) {
  std::string s = source;
  if (line > 0) s += ":" + std::to_string(line);
  if (!field.empty()) s += ": " + field;
  return s + ": " + message;
}
}  // namespace

InputError::InputError(std::string source, long line, std::string field, const std::string& message)
    : std::runtime_error(compose(source, line, field, message)),
      source_(std::move(source)),
      line_(line),
      field_(std::move(field)) {}

}  // namespace viscera::tissue
