#include "viscera/recording/recording_tables.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <limits>
#include <map>
#include <span>
#include <type_traits>

#include "viscera/common/input_error.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/protocol/surface_assembler.hpp"

namespace viscera::recording {

namespace {

using protocol::Stream;

/// Appends one row to a table, column after column in a fixed order; in header mode it only makes
/// the columns (so that a stream with no message still has them).
class Row {
 public:
  Row(StreamTable& t, bool header) : t_(t), header_(header) {}

  template <class V>
  void put(const char* name, V v) {
    using E = std::conditional_t<
        std::is_same_v<V, bool>, std::uint8_t,
        std::conditional_t<std::is_floating_point_v<V>, double, std::conditional_t<std::is_signed_v<V>, std::int64_t, std::uint64_t>>>;
    if (header_) {
      t_.columns.push_back({name, std::vector<E>{}});
      return;
    }
    std::get<std::vector<E>>(t_.columns[i_++].values).push_back(static_cast<E>(v));
  }
  void put(const char* name, const std::string& v) {
    if (header_) {
      t_.columns.push_back({name, std::vector<std::string>{}});
      return;
    }
    std::get<std::vector<std::string>>(t_.columns[i_++].values).push_back(v);
  }
  /// x, y, z columns: "<prefix>_x_<unit>" and so on.
  void put3(const std::string& prefix, const std::string& unit, const protocol::Vector3& v) {
    static const char* const axes[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) put_named(prefix + "_" + axes[k] + (unit.empty() ? "" : "_" + unit), v[static_cast<std::size_t>(k)]);
  }
  void put_named(const std::string& name, double v) {
    if (header_) {
      t_.columns.push_back({name, std::vector<double>{}});
      return;
    }
    std::get<std::vector<double>>(t_.columns[i_++].values).push_back(v);
  }

 private:
  StreamTable& t_;
  bool header_;
  std::size_t i_ = 0;
};

double or_nan(const std::optional<double>& v) { return v ? *v : std::numeric_limits<double>::quiet_NaN(); }

void row_of(Row& r, const protocol::Command& c) {
  r.put("instrument_id", c.instrument_id);
  r.put("client_id", c.client_id);
  r.put("seq", c.seq);
  r.put("client_stamp_ns", c.client_stamp_ns);
  r.put3("tip", "m", c.tip_position);
  r.put("orientation_w", c.orientation[0]);
  r.put("orientation_x", c.orientation[1]);
  r.put("orientation_y", c.orientation[2]);
  r.put("orientation_z", c.orientation[3]);
  r.put("jaw_opening_rad", c.jaw_opening);
  r.put("buttons", c.buttons);
}

void row_of(Row& r, const protocol::Force& f) {
  r.put("instrument_id", f.instrument_id);
  r.put("client_id", f.client_id);
  r.put("command_seq", f.command_seq);
  r.put("command_client_stamp_ns", f.command_client_stamp_ns);
  r.put("server_stamp_ns", f.server_stamp_ns);
  r.put("step_time_ns", f.step_time_ns);
  r.put("tick", f.tick);
  r.put3("force", "n", f.force);
  r.put3("torque", "n_m", f.torque);
  r.put("in_contact", f.in_contact);
  r.put3("contact_point", "m", f.contact_point);
  r.put3("contact_normal", "", f.contact_normal);
  static const char* const k[] = {"stiffness_xx_n_per_m", "stiffness_xy_n_per_m", "stiffness_xz_n_per_m",
                                  "stiffness_yx_n_per_m", "stiffness_yy_n_per_m", "stiffness_yz_n_per_m",
                                  "stiffness_zx_n_per_m", "stiffness_zy_n_per_m", "stiffness_zz_n_per_m"};
  for (std::size_t i = 0; i < 9; ++i) r.put(k[i], f.stiffness[i]);
  r.put("penetration_m", f.penetration_m);
  r.put("max_edge_strain", f.max_edge_strain);
  r.put("cutting", f.cutting);
  r.put("cut_edge_strain", f.cut_edge_strain);
  r.put("tip_strain", f.tip_strain);
}

void row_of(Row& r, const protocol::SessionRequest& q) {
  r.put("client_id", q.client_id);
  r.put("action", std::string(protocol::action_name(q.action)));
  r.put("instrument_id", q.instrument_id);
  r.put("request_seq", q.request_seq);
  r.put("scene_name", q.scene_name);
  r.put("scene_seed", q.scene_seed ? static_cast<std::int64_t>(*q.scene_seed) : std::int64_t{-1});
  r.put("youngs_modulus_pa", or_nan(q.material.youngs_modulus_pa));
  r.put("poisson_ratio", or_nan(q.material.poisson_ratio));
  r.put("density_kg_m3", or_nan(q.material.density_kg_m3));
  r.put("shear_q", or_nan(q.material.shear_q));
  r.put("damping_per_s", or_nan(q.material.damping_per_s));
  r.put("material_file_name", q.material.file_text ? q.material.file_name : std::string());
  r.put("material_file_bytes", q.material.file_text ? q.material.file_text->size() : std::size_t{0});
  r.put("physics_rate_hz", q.physics_rate_hz);
  r.put("seek_s", q.seek_s);
}

void row_of(Row& r, const protocol::Scene& s) {
  r.put("name", s.name);
  r.put("generation", s.generation);
  r.put("physics_rate_hz", s.physics_rate_hz);
  r.put("paused", s.paused);
  r.put("instruments", s.instruments.size());
  r.put("preparing", s.preparing);
  r.put("material_name", s.material.name);
  r.put("youngs_modulus_pa", s.material.youngs_modulus_pa);
  r.put("poisson_ratio", s.material.poisson_ratio);
  r.put("density_kg_m3", s.material.density_kg_m3);
  r.put("shear_q", s.material.shear_q);
  r.put("damping_per_s", s.material.damping_per_s);
  r.put("regions", s.regions.size());
}

void row_of(Row& r, const protocol::TelemetryReport& t) {
  r.put("server_stamp_ns", t.server_stamp_ns);
  r.put("steps", t.steps);
  r.put("physics_rate_hz", t.physics_rate_hz);
  r.put("step_p50_us", t.step_p50_us);
  r.put("step_p99_us", t.step_p99_us);
  r.put("step_max_us", t.step_max_us);
  r.put("jitter_p99_us", t.jitter_p99_us);
  r.put("late_ticks", t.late_ticks);
  r.put("missed_slots", t.missed_slots);
  r.put("rejected_messages", t.rejected_messages);
  r.put("rejected_malformed", t.rejected_malformed);
  r.put("rejected_not_owner", t.rejected_not_owner);
  r.put("rejected_unknown_instrument", t.rejected_unknown_instrument);
  r.put("rejected_other_participant", t.rejected_other_participant);
}

void row_of(Row& r, const protocol::SurfaceTopology& t) {
  r.put("mesh_id", t.mesh_id);
  r.put("organ_name", t.organ_name);
  r.put("vertex_count", t.vertex_count);
  r.put("triangle_count", t.triangles.size() / 3);  // a patch's: those it adds
  r.put("topology_generation", t.topology_generation);
  r.put("patch", t.patch);
  r.put("base_generation", t.base_generation);
}

void row_of(Row& r, const protocol::MeshFrame& m) {
  r.put("mesh_id", m.mesh_id);
  r.put("frame", m.frame);
  r.put("sim_time_s", m.sim_time_s);
  r.put("server_stamp_ns", m.server_stamp_ns);
  r.put("tick", m.tick);
  r.put("vertex_count", m.positions.size() / 3);
}

void row_of(Row& r, const protocol::Event& e) {
  r.put("source_client_id", e.source_client_id);
  r.put("kind", std::string(protocol::event_name(e.kind)));
  r.put("instrument_id", e.instrument_id);
  r.put("client_id", e.client_id);
  r.put("sim_time_s", e.sim_time_s);
  r.put("stamp_ns", e.stamp_ns);
  r.put("tick", e.tick);
  r.put("request_seq", e.request_seq);
  r.put("reason", std::string(protocol::event_reason_name(e.reason)));
  r.put("scene", e.scene);
  r.put("text", e.text);
}

void row_of(Row& r, const protocol::SceneFiles& f) {
  r.put("generation", f.generation);
  r.put("first_tick", f.first_tick);
  r.put("sim_time_s", f.sim_time_s);
  r.put("server_version", f.server_version);
  r.put("files", f.files.size());
}

/// Messages of a stream as the recording's summary counts them (0 without statistics), at most as
/// many as its chunks could hold (an MCAP message record takes at least 31 bytes).
std::uint64_t expected_messages(const Recording& r, Stream s) {
  if (!r.summary().statistics) return 0;
  std::uint64_t capacity = 0;
  for (const auto& c : r.summary().chunks) capacity += c.uncompressed_size / 31;
  std::uint64_t n = 0;
  for (const auto& [id, ch] : r.channels())
    if (ch.stream == s)
      if (const auto it = r.summary().statistics->channel_message_counts.find(id); it != r.summary().statistics->channel_message_counts.end())
        n += it->second;
  return std::min(n, capacity);
}

/// The stream's table, its columns made and sized for `rows` (no reallocation while it fills:
/// the peak memory stays that of the table).
template <class Message>
StreamTable& table_for(RecordingTables& out, Stream s, std::uint64_t rows) {
  auto [it, fresh] = out.streams.try_emplace(protocol::stream_name(s));
  if (fresh) {
    Row header(it->second, true);
    header.put("source_id", std::uint32_t{0});
    header.put("writer", std::uint64_t{0});
    header.put("sequence", std::uint32_t{0});
    row_of(header, Message{});
    try {  // a summary's count is a hint: a file that lies about it costs no more than growing
      it->second.log_time_ns.reserve(rows);
      for (auto& c : it->second.columns) std::visit([rows](auto& v) { v.reserve(rows); }, c.values);
    } catch (const std::exception&) {
    }
  }
  return it->second;
}

template <class Message, class Decode>
const Message* add_row(RecordingTables& out, Stream s, const RecordedChannel& ch, const mcap::Message& m, Decode decode,
                       std::optional<Message>& slot) {
  StreamTable& t = out.streams.at(protocol::stream_name(s));
  std::string why;
  slot = decode(std::span<const std::uint8_t>(m.data), &why);
  if (!slot) {
    ++t.undecodable;
    t.last_error = why;
    return nullptr;
  }
  t.log_time_ns.push_back(static_cast<std::int64_t>(m.log_time));
  Row r(t, false);
  r.put("source_id", ch.source_id);
  r.put("writer", ch.writer);
  r.put("sequence", m.sequence);
  row_of(r, *slot);
  return &*slot;
}

/// `expected`: frames of every mesh in the recording, an upper bound of this mesh's (reserved at
/// its first frame: pages never filled are never touched).
void add_frame(RecordingTables& out, const mcap::Message& m, const protocol::MeshFrame& f, std::uint64_t expected) {
  FrameSeries& s = out.frames[f.mesh_id];
  s.mesh_id = f.mesh_id;
  if (!s.generation_known) {
    s.topology_generation = f.topology_generation;
    s.generation_known = true;
  }
  s.last_topology_generation = std::max(s.last_topology_generation, f.topology_generation);
  if (f.topology_generation != s.topology_generation) {  // the surface after a cut: another series
    ++s.later_generation_frames;
    return;
  }
  const auto n = static_cast<std::uint32_t>(f.positions.size() / 3);
  if (s.frame.empty() && s.vertex_count == 0) s.vertex_count = n;
  if (s.frame.empty()) try {
      s.positions.reserve(expected * 3 * s.vertex_count);
    } catch (const std::exception&) {  // a hint only, as in table_for
    }
  if (n != s.vertex_count) {
    ++s.mismatched;
    return;
  }
  s.log_time_ns.push_back(static_cast<std::int64_t>(m.log_time));
  s.frame.push_back(f.frame);
  s.tick.push_back(f.tick);
  s.sim_time_s.push_back(f.sim_time_s);
  s.positions.insert(s.positions.end(), f.positions.begin(), f.positions.end());
}

/// `message`: whole or a patch; `assembler`: the mesh's whole surfaces so far.
void add_topology(RecordingTables& out, const protocol::SurfaceTopology& message, protocol::SurfaceAssembler& assembler) {
  if (!assembler.take(message)) return;  // a patch of a surface the recording does not hold
  const protocol::SurfaceTopology& t = *assembler.surface();
  FrameSeries& s = out.frames[t.mesh_id];
  s.mesh_id = t.mesh_id;
  if (!s.generation_known) {
    s.topology_generation = t.topology_generation;
    s.generation_known = true;
  }
  s.last_topology_generation = std::max(s.last_topology_generation, t.topology_generation);
  if (t.topology_generation != s.topology_generation) return;
  if (s.frame.empty()) s.vertex_count = t.vertex_count;
  s.triangles = t.triangles;
  s.rest_positions = t.rest_positions;
}

}  // namespace

const std::vector<Stream>& tabulated_streams() {
  static const std::vector<Stream> s = {Stream::instrument_command, Stream::force_feedback, Stream::session_request,
                                        Stream::scene_state,        Stream::telemetry,      Stream::surface_topology,
                                        Stream::mesh_frame,         Stream::event,          Stream::scene_files};
  return s;
}

RecordingTables read_tables(Recording& recording, const std::set<std::string>& streams, bool with_frames) {
  std::set<Stream> wanted;
  for (const std::string& name : streams) {
    Stream s{};
    if (!protocol::parse_stream(name, &s) || std::find(tabulated_streams().begin(), tabulated_streams().end(), s) == tabulated_streams().end()) {
      std::string names;
      for (Stream t : tabulated_streams()) names += std::string(names.empty() ? "" : ", ") + protocol::stream_name(t);
      throw common::InputError(recording.path(), 0, "stream", "'" + common::printable(name) + "' is not one of " + names);
    }
    wanted.insert(s);
  }
  if (wanted.empty()) wanted.insert(tabulated_streams().begin(), tabulated_streams().end());
  if (with_frames) wanted.insert({Stream::mesh_frame, Stream::surface_topology});

  RecordingTables out;
  // Tables of every stream asked for, messages or not.
  std::optional<protocol::Command> command;
  std::optional<protocol::Force> force;
  std::optional<protocol::SessionRequest> request;
  std::optional<protocol::Scene> scene;
  std::optional<protocol::TelemetryReport> telemetry;
  std::optional<protocol::SurfaceTopology> topology;
  std::map<std::uint32_t, protocol::SurfaceAssembler> surfaces;  // per mesh
  std::optional<protocol::MeshFrame> frame;
  std::optional<protocol::Event> event;
  std::optional<protocol::SceneFiles> files;
  for (Stream s : wanted) {
    const std::uint64_t n = expected_messages(recording, s);
    switch (s) {
      case Stream::instrument_command: table_for<protocol::Command>(out, s, n); break;
      case Stream::force_feedback: table_for<protocol::Force>(out, s, n); break;
      case Stream::session_request: table_for<protocol::SessionRequest>(out, s, n); break;
      case Stream::scene_state: table_for<protocol::Scene>(out, s, n); break;
      case Stream::telemetry: table_for<protocol::TelemetryReport>(out, s, n); break;
      case Stream::surface_topology: table_for<protocol::SurfaceTopology>(out, s, n); break;
      case Stream::mesh_frame: table_for<protocol::MeshFrame>(out, s, n); break;
      case Stream::event: table_for<protocol::Event>(out, s, n); break;
      case Stream::scene_files: table_for<protocol::SceneFiles>(out, s, n); break;
      default: break;
    }
  }
  const std::uint64_t frames_expected = expected_messages(recording, Stream::mesh_frame);
  recording.for_each(
      [&](const RecordedChannel& ch, const mcap::Message& m) {
        if (!wanted.count(ch.stream)) return true;
        switch (ch.stream) {
          case Stream::instrument_command: add_row(out, ch.stream, ch, m, protocol::decode_command, command); break;
          case Stream::force_feedback: add_row(out, ch.stream, ch, m, protocol::decode_force, force); break;
          case Stream::session_request: add_row(out, ch.stream, ch, m, protocol::decode_session_request, request); break;
          case Stream::scene_state: add_row(out, ch.stream, ch, m, protocol::decode_scene, scene); break;
          case Stream::telemetry: add_row(out, ch.stream, ch, m, protocol::decode_telemetry, telemetry); break;
          case Stream::surface_topology:
            if (const auto* t = add_row(out, ch.stream, ch, m, protocol::decode_surface_topology, topology))
              add_topology(out, *t, surfaces[t->mesh_id]);
            break;
          case Stream::mesh_frame:
            if (const auto* f = add_row(out, ch.stream, ch, m, protocol::decode_mesh_frame, frame); f && with_frames)
              add_frame(out, m, *f, frames_expected);
            break;
          case Stream::event: add_row(out, ch.stream, ch, m, protocol::decode_event, event); break;
          case Stream::scene_files: add_row(out, ch.stream, ch, m, protocol::decode_scene_files, files); break;
          default: break;
        }
        return true;
      },
      0, ~std::uint64_t{0}, /*read_ahead=*/true);
  return out;
}

}  // namespace viscera::recording
