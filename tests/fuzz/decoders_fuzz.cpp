// libFuzzer target for every message decoder: arbitrary bytes must be rejected or decoded, never  // SPDX-License-Identifier: Apache-2.0
// crash, hang or read out of bounds (built with ASan + UBSan by tests/fuzz/run_fuzz.sh).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "viscera/protocol/messages.hpp"

using namespace viscera::protocol;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  std::string why;
  if (auto c = decode_command(bytes, &why)) (void)encode(*c);  // re-encoding a decoded value must work
  if (auto f = decode_force(bytes, &why)) (void)encode(*f);
  if (auto r = decode_session_request(bytes, &why)) (void)encode(*r);
  if (auto s = decode_scene(bytes, &why)) (void)encode(*s);
  if (auto t = decode_telemetry(bytes, &why)) (void)encode(*t);
  if (auto t = decode_surface_topology(bytes, &why)) (void)encode(*t);
  if (auto m = decode_mesh_frame(bytes, &why)) (void)encode(*m);
  if (auto e = decode_event(bytes, &why)) (void)encode(*e);
  return 0;
}
