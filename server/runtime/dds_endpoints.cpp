#include "viscera/runtime/server_endpoints.hpp"  // SPDX-License-Identifier: Apache-2.0

namespace viscera::runtime {

namespace proto = viscera::protocol;

namespace {
class DdsMeshStream final : public MeshStream {
 public:
  explicit DdsMeshStream(proto::Participant& p) : topology_(p, proto::Stream::surface_topology), frames_(p, proto::Stream::mesh_frame) {}
  void write_topology(std::uint32_t mesh_id, std::span<const std::uint8_t> payload) override { topology_.write(mesh_id, payload); }
  void write_frame(std::uint32_t mesh_id, std::span<const std::uint8_t> payload) override { frames_.write(mesh_id, payload); }
  std::uint64_t topology_readers_ever() const override { return topology_.matched_ever(); }

 private:
  proto::Writer topology_, frames_;
};
}  // namespace

DdsEndpoints::DdsEndpoints(std::uint32_t domain_id, const std::string& partition, bool lockstep)
    : participant_(domain_id, partition, proto::kServerRole),
      commands_(participant_, proto::Stream::instrument_command),
      sessions_(participant_, proto::Stream::session_request),
      forces_(participant_, proto::Stream::force_feedback),
      scene_(participant_, proto::Stream::scene_state),
      telemetry_(participant_, proto::Stream::telemetry),
      events_(participant_, proto::Stream::event),
      scene_files_(participant_, proto::Stream::scene_files) {
  if (lockstep) {
    steps_ = std::make_unique<proto::Reader>(participant_, proto::Stream::lockstep_step);
    results_ = std::make_unique<proto::Writer>(participant_, proto::Stream::lockstep_result);
  }
}

int DdsEndpoints::take_steps(std::chrono::nanoseconds timeout, const std::function<void(std::span<const std::uint8_t>)>& f) {
  if (!steps_) return 0;
  int n = steps_->take([&](const proto::Received& r) { f(r.payload); });
  if (n == 0 && steps_->wait(timeout)) n = steps_->take([&](const proto::Received& r) { f(r.payload); });
  return n;
}

void DdsEndpoints::write_result(std::span<const std::uint8_t> p) {
  if (results_) results_->write(0, p);
}

std::unique_ptr<MeshStream> DdsEndpoints::open_mesh_stream() { return std::make_unique<DdsMeshStream>(participant_); }

}  // namespace viscera::runtime
