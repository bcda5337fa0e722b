#pragma once  // SPDX-License-Identifier: Apache-2.0
// What a browser may ask of the console, checked like every other input: one JSON object per
// WebSocket text message, a known "type", only the fields that type takes, values in range (the
// material ranges and scene names are viscera-control's). Anything else is refused with one line
// naming the field and the value.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "viscera/protocol/messages.hpp"

namespace viscera::console {

/// The longest request a browser may send [bytes]; longer WebSocket messages close the connection.
inline constexpr std::size_t kMaxRequestBytes = 16 * 1024;

enum class RequestType {
  pause,
  resume,
  reset,
  load_scene,
  material,
  annotate,
  bookmark,
  watch,
  take_over,
  hand_back,
  move,
  open_recording,
  recordings
};
const char* request_type_name(RequestType t);

struct BrowserRequest {
  RequestType type = RequestType::pause;
  std::uint64_t id = 0;  ///< the browser's number for the request, echoed in the reply (0: none)
  std::string text;  ///< annotate: the text; bookmark: its label (may be empty); load_scene: the scene; watch: the station; open_recording: the file
  protocol::MaterialChange change;  ///< material
  std::optional<std::uint64_t> seed;  ///< load_scene: the drawn regions' seed
  std::uint32_t instrument = 0;  ///< take_over, hand_back, move
  protocol::Vector3 delta_m{};  ///< move: the step of the held instrument's tip [m], each component within +-kMaxMoveStepM
};

/// The largest step of one move request, per axis [m].
inline constexpr double kMaxMoveStepM = 0.01;

/// The request in `message`, or nothing and why (one line: field and value).
std::optional<BrowserRequest> parse_browser_request(std::string_view message, std::string* why);

}  // namespace viscera::console
