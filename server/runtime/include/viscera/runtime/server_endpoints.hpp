#pragma once  // SPDX-License-Identifier: Apache-2.0
// What the server reads from its clients and writes to them, as payloads (FlatBuffers, verified
// by the server). DdsEndpoints is the real one, over Cyclone DDS (protocol/); a test passes its
// own, so the server's logic runs without a network. In lockstep a driver sends the ticks and
// reads what each produced through a LockstepLink.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "viscera/protocol/dds.hpp"

namespace viscera::runtime {

/// One organ's surface: its topology (late joiners get it) and its frames. A new scene opens a new
/// stream and closes the old, so a late joiner gets only the current surface.
class MeshStream {
 public:
  virtual ~MeshStream() = default;
  virtual void write_topology(std::uint32_t mesh_id, std::span<const std::uint8_t> payload) = 0;
  virtual void write_frame(std::uint32_t mesh_id, std::span<const std::uint8_t> payload) = 0;
  /// Readers of the topology matched since the stream was opened: it grows when one joins.
  virtual std::uint64_t topology_readers_ever() const { return 0; }
};

class ServerEndpoints {
 public:
  using Take = std::function<void(const protocol::Received&)>;
  virtual ~ServerEndpoints() = default;
  /// Instrument commands that arrived, each passed to `f`; returns how many.
  virtual int take_commands(const Take& f) = 0;
  /// Blocks until a command may be there or the timeout passes.
  virtual bool wait_commands(std::chrono::nanoseconds timeout) = 0;
  virtual int take_session_requests(const Take& f) = 0;
  virtual void write_force(std::uint32_t instrument_id, std::span<const std::uint8_t> payload) = 0;
  virtual void write_scene(std::span<const std::uint8_t> payload) = 0;
  virtual void write_telemetry(std::span<const std::uint8_t> payload) = 0;
  virtual void write_event(std::span<const std::uint8_t> payload) = 0;
  /// The files the organ was built from (schema 7, SceneFiles).
  virtual void write_scene_files(std::span<const std::uint8_t> payload) = 0;
  virtual std::unique_ptr<MeshStream> open_mesh_stream() = 0;
  /// Whether the senders' identities are authenticated (DDS Security): client ids are then bound
  /// to the certificate that first used them (ClientBinding).
  virtual bool authenticated() const { return false; }
};

/// A lockstep driver's ticks (LockstepStep payloads) and the server's answers (LockstepResult).
class LockstepLink {
 public:
  virtual ~LockstepLink() = default;
  /// Calls `f` for each step that arrived within `timeout`, in the order sent; returns how many.
  virtual int take_steps(std::chrono::nanoseconds timeout, const std::function<void(std::span<const std::uint8_t>)>& f) = 0;
  virtual void write_result(std::span<const std::uint8_t> payload) = 0;
};

/// The server's endpoints on a DDS domain: one participant in one partition ("" : the default),
/// the streams' QoS of docs/PROTOCOL.md; with `lockstep`, also the lockstep streams.
class DdsEndpoints final : public ServerEndpoints, public LockstepLink {
 public:
  explicit DdsEndpoints(std::uint32_t domain_id, const std::string& partition = {}, bool lockstep = false);
  int take_commands(const Take& f) override { return commands_.take(f); }
  bool wait_commands(std::chrono::nanoseconds timeout) override { return commands_.wait(timeout); }
  int take_session_requests(const Take& f) override { return sessions_.take(f); }
  void write_force(std::uint32_t instrument_id, std::span<const std::uint8_t> p) override { forces_.write(instrument_id, p); }
  void write_scene(std::span<const std::uint8_t> p) override { scene_.write(0, p); }
  void write_telemetry(std::span<const std::uint8_t> p) override { telemetry_.write(0, p); }
  void write_event(std::span<const std::uint8_t> p) override { events_.write(0, p); }
  void write_scene_files(std::span<const std::uint8_t> p) override { scene_files_.write(0, p); }
  std::unique_ptr<MeshStream> open_mesh_stream() override;
  bool authenticated() const override { return authenticated_; }
  /// Lockstep only (constructed with `lockstep`).
  int take_steps(std::chrono::nanoseconds timeout, const std::function<void(std::span<const std::uint8_t>)>& f) override;
  void write_result(std::span<const std::uint8_t> p) override;

 private:
  protocol::Participant participant_;
  protocol::Reader commands_, sessions_;
  protocol::Writer forces_, scene_, telemetry_, events_, scene_files_;
  std::unique_ptr<protocol::Reader> steps_;
  std::unique_ptr<protocol::Writer> results_;
  bool authenticated_ = protocol::security_configured();
};

}  // namespace viscera::runtime
