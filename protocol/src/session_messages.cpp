// Encoding and verified decoding of the messages added with lockstep and recording (schema 7):  // SPDX-License-Identifier: Apache-2.0
// the files a scene was built from, and the lockstep step and result.
#include <cstdio>

#include <openssl/evp.h>

#include "viscera/protocol/messages.hpp"

#include "lockstep_generated.h"
#include "lockstep_result_generated.h"
#include "scene_files_generated.h"
#include "verified_root.hpp"

namespace viscera::protocol {

namespace fb = viscera::wire;

namespace {

/// A step or result carries whole payloads (a mesh frame of 100k vertices is one vector).
template <typename T>
const T* verified(std::span<const std::uint8_t> bytes, const char* identifier, std::string* why) {
  return detail::verified_root<T>(bytes, why, identifier, 100000);
}

flatbuffers::Offset<flatbuffers::Vector<flatbuffers::Offset<fb::Payload>>> payloads(flatbuffers::FlatBufferBuilder& b,
                                                                                    const std::vector<std::vector<std::uint8_t>>& items) {
  std::vector<flatbuffers::Offset<fb::Payload>> out;
  out.reserve(items.size());
  for (const auto& p : items) out.push_back(fb::CreatePayload(b, b.CreateVector(p)));
  return b.CreateVector(out);
}

std::vector<std::vector<std::uint8_t>> payloads(const flatbuffers::Vector<flatbuffers::Offset<fb::Payload>>* items) {
  std::vector<std::vector<std::uint8_t>> out;
  if (items)
    for (const auto* p : *items)
      out.emplace_back(p->bytes() ? std::vector<std::uint8_t>(p->bytes()->begin(), p->bytes()->end()) : std::vector<std::uint8_t>{});
  return out;
}

}  // namespace

std::string sha256_hex(std::span<const std::uint8_t> bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  EVP_Digest(bytes.data(), bytes.size(), digest, &n, EVP_sha256(), nullptr);
  std::string hex;
  char b[3];
  for (unsigned int i = 0; i < n; ++i) {
    std::snprintf(b, sizeof b, "%02x", digest[i]);
    hex += b;
  }
  return hex;
}

std::vector<std::uint8_t> encode(const SceneFiles& f) {
  flatbuffers::FlatBufferBuilder b(1024);
  std::vector<flatbuffers::Offset<fb::LoadedFile>> files;
  for (const auto& file : f.files)
    files.push_back(
        fb::CreateLoadedFile(b, b.CreateString(file.role), b.CreateString(file.path), b.CreateString(file.sha256), b.CreateVector(file.content)));
  b.Finish(fb::CreateSceneFiles(b, f.generation, b.CreateString(f.server_version), b.CreateString(f.settings_json), b.CreateVector(files),
                                f.first_tick, f.sim_time_s),
           fb::SceneFilesIdentifier());
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

std::optional<SceneFiles> decode_scene_files(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified<fb::SceneFiles>(bytes, fb::SceneFilesIdentifier(), why);
  if (!m) return std::nullopt;
  SceneFiles f;
  f.generation = m->generation();
  f.server_version = m->server_version() ? m->server_version()->str() : "";
  f.settings_json = m->settings_json() ? m->settings_json()->str() : "";
  f.first_tick = m->first_tick();
  f.sim_time_s = m->sim_time_s();
  if (m->files())
    for (const auto* file : *m->files()) {
      LoadedFile l;
      l.role = file->role() ? file->role()->str() : "";
      l.path = file->path() ? file->path()->str() : "";
      l.sha256 = file->sha256() ? file->sha256()->str() : "";
      if (file->content()) l.content.assign(file->content()->begin(), file->content()->end());
      if (sha256_hex(l.content) != l.sha256) {
        *why = "file " + l.path + ": its content does not match its SHA-256";
        return std::nullopt;
      }
      f.files.push_back(std::move(l));
    }
  return f;
}

std::vector<std::uint8_t> encode(const LockstepStep& s) {
  flatbuffers::FlatBufferBuilder b(256);
  const auto requests = payloads(b, s.requests);
  const auto commands = payloads(b, s.commands);
  const auto answers = payloads(b, s.answers);
  b.Finish(fb::CreateLockstepStep(b, s.tick, s.sim_time_s, requests, commands, answers, s.want_frame), fb::LockstepStepIdentifier());
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

std::optional<LockstepStep> decode_lockstep_step(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified<fb::LockstepStep>(bytes, fb::LockstepStepIdentifier(), why);
  if (!m) return std::nullopt;
  return LockstepStep{m->tick(), m->sim_time_s(), payloads(m->requests()), payloads(m->commands()), payloads(m->answers()), m->want_frame()};
}

std::vector<std::uint8_t> encode(const LockstepResult& r) {
  flatbuffers::FlatBufferBuilder b(1024 + r.frame.size());
  const auto forces = payloads(b, r.forces);
  const auto events = payloads(b, r.events);
  const auto frame = r.frame.empty() ? 0 : fb::CreatePayload(b, b.CreateVector(r.frame));
  b.Finish(fb::CreateLockstepResult(b, r.tick, r.sim_time_s, forces, events, frame, b.CreateString(r.error)), fb::LockstepResultIdentifier());
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

std::optional<LockstepResult> decode_lockstep_result(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified<fb::LockstepResult>(bytes, fb::LockstepResultIdentifier(), why);
  if (!m) return std::nullopt;
  LockstepResult r{m->tick(), m->sim_time_s(), payloads(m->forces()), payloads(m->events()), {}, m->error() ? m->error()->str() : ""};
  if (m->frame() && m->frame()->bytes()) r.frame.assign(m->frame()->bytes()->begin(), m->frame()->bytes()->end());
  return r;
}

}  // namespace viscera::protocol
