#pragma once  // SPDX-License-Identifier: Apache-2.0
// What a console may ask of a server, checked before it is sent: the material parameters with
// their ranges, and scene names. viscera-control (command line) and viscera-console (browser)
// check with these, so both refuse the same values with the same words.
#include <array>
#include <optional>
#include <string>

#include "viscera/protocol/messages.hpp"

namespace viscera::client {

/// A material parameter a console may change at run time, with its range (SI).
struct MaterialParameter {
  const char* name;  ///< as a console spells it: "youngs-modulus-pa"
  const char* value_name;  ///< in usage lines: "E"
  const char* help;
  double lo, hi;
  std::optional<double> protocol::MaterialChange::*field;
};
const std::array<MaterialParameter, 5>& material_parameters();

/// "NAME: VALUE is outside [LO, HI]", or nothing when lo <= value <= hi.
std::optional<std::string> outside_range(const std::string& name, double value, double lo, double hi);

/// A scene of the server's folder, by name: [A-Za-z0-9._-], 1 to 64, not starting with '.'.
bool is_scene_name(const std::string& name);
/// Why `name` is not a scene name (the words both consoles use).
std::string not_a_scene_name(const std::string& name);

/// A file's name as a material change carries it (protocol: [A-Za-z0-9._-], 1-64, no leading
/// '.'): the path's last part, other characters replaced by '_', cut to 64.
std::string plain_file_name(const std::string& path);

/// The longest annotation text [bytes].
inline constexpr std::size_t kMaxAnnotationBytes = 1024;

}  // namespace viscera::client
