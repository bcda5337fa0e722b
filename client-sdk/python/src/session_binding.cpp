// viscera._viscera.session: the client SDK (viscera::client::Client) for Python. Calls that wait  // SPDX-License-Identifier: Apache-2.0
// release the interpreter lock; no Python code ever runs on a DDS thread (state is polled), so a
// DDS callback can never wait for the lock that the main thread holds.
#include <pybind11/chrono.h>
#include <pybind11/stl.h>

#include "viscera/client/client.hpp"
#include "viscera/client/tick_phase.hpp"
#include "viscera/common/command_line.hpp"

#include "bindings.hpp"
#include "numpy_views.hpp"

namespace viscera::python {

namespace {

using client::Client;
namespace protocol = viscera::protocol;

/// A timeout [s] as nanoseconds (a 1 kHz loop waits fractions of a millisecond).
std::chrono::nanoseconds ns(double seconds) {
  if (!(seconds >= 0 && seconds <= 86400)) throw common::UsageError("timeout_s must lie in [0, 86400], not " + std::to_string(seconds));
  return std::chrono::nanoseconds(static_cast<long long>(seconds * 1e9));
}
/// For the calls that take milliseconds: rounded up, so that a short wait still waits.
std::chrono::milliseconds ms(double seconds) { return std::chrono::ceil<std::chrono::milliseconds>(ns(seconds)); }

protocol::Vector3 vector3(const std::vector<double>& v, const char* what) {
  if (v.size() != 3) throw common::UsageError(std::string(what) + ": 3 coordinates [m], not " + std::to_string(v.size()));
  return {v[0], v[1], v[2]};
}

}  // namespace

void bind_session(py::module_& m) {
  py::enum_<client::ServerState>(m, "ServerState")
      .value("waiting", client::ServerState::waiting)
      .value("alive", client::ServerState::alive)
      .value("lost", client::ServerState::lost);
  py::class_<protocol::InstrumentInfo>(m, "Instrument", "An instrument of the scene.")
      .def_readonly("instrument_id", &protocol::InstrumentInfo::instrument_id, "the instrument (the scene file's id)")
      .def_readonly("grasper", &protocol::InstrumentInfo::grasper, "True for a grasper (jaws)")
      .def_readonly("scalpel", &protocol::InstrumentInfo::scalpel, "True for a scalpel (its blade cuts while button 1 is held)")
      .def_readonly("blade_length_m", &protocol::InstrumentInfo::blade_length_m, "A scalpel's blade [m] (0 for other instruments)")
      .def_readonly("tip_radius_m", &protocol::InstrumentInfo::tip_radius_m, "[m] radius of the tip sphere")
      .def_readonly("owner_client_id", &protocol::InstrumentInfo::owner_client_id, "0: free");
  py::class_<protocol::MaterialInfo>(m, "Material", "The organ's material as the scene state shows it (SI).")
      .def_readonly("name", &protocol::MaterialInfo::name, "its name")
      .def_readonly("youngs_modulus_pa", &protocol::MaterialInfo::youngs_modulus_pa, "[Pa] Young's modulus (0: not isotropic)")
      .def_readonly("poisson_ratio", &protocol::MaterialInfo::poisson_ratio, "Poisson ratio [-]")
      .def_readonly("density_kg_m3", &protocol::MaterialInfo::density_kg_m3, "[kg/m^3] density")
      .def_readonly("shear_q", &protocol::MaterialInfo::shear_q, "quality factor Q of the constant-Q shear damping (0: elastic)")
      .def_readonly("damping_per_s", &protocol::MaterialInfo::damping_per_s, "[1/s] mass-proportional damping");
  py::class_<protocol::RequestOutcome>(m, "RequestOutcome", "What the server did with a request.")
      .def_readonly("accepted", &protocol::RequestOutcome::accepted, "whether the server did it")
      .def_readonly("message", &protocol::RequestOutcome::message, "what the server did, or why not (one line)")
      .def_property_readonly(
          "action", [](const protocol::RequestOutcome& o) { return std::string(protocol::action_name(o.action)); },
          "the request it answers: load_scene, set_material, ...")
      .def("__bool__", [](const protocol::RequestOutcome& o) { return o.accepted; })
      .def("__repr__", [](const protocol::RequestOutcome& o) {
        return std::string("RequestOutcome(") + (o.accepted ? "accepted" : "refused") + ": " + o.message + ")";
      });
  py::class_<protocol::Scene>(m, "Scene", "The server's scene state.")
      .def_readonly("name", &protocol::Scene::name, "its name")
      .def_readonly("physics_rate_hz", &protocol::Scene::physics_rate_hz, "[Hz] the physics rate")
      .def_readonly("paused", &protocol::Scene::paused, "whether the physics is paused")
      .def_readonly("instruments", &protocol::Scene::instruments, "the scene's instruments and their owners")
      .def_readonly("bounds_min_m", &protocol::Scene::bounds_min, "[m] lower corner of the organ's bounding box (x, y, z)")
      .def_readonly("bounds_max_m", &protocol::Scene::bounds_max, "[m] upper corner of the organ's bounding box (x, y, z)")
      .def_readonly("generation", &protocol::Scene::generation, "+1 per scene loaded: a claim made before it is gone")
      .def_readonly("material", &protocol::Scene::material, "the organ's material")
      .def_readonly("available_scenes", &protocol::Scene::available_scenes, "the scenes the server can load by name")
      .def_readonly("preparing", &protocol::Scene::preparing, "the scene or material being built in the background (empty if none)")
      .def_readonly("unreadable_scenes", &protocol::Scene::unreadable_scenes, "'name: error' for scene files that do not read");
  py::class_<protocol::Force>(m, "Force", "A force on an instrument, answering a command.")
      .def_readonly("instrument_id", &protocol::Force::instrument_id, "the instrument (the scene file's id)")
      .def_readonly("command_seq", &protocol::Force::command_seq, "the command it answers (its sequence number)")
      .def_readonly("force_n", &protocol::Force::force, "[N] force on the tool (x, y, z)")
      .def_readonly("torque_n_m", &protocol::Force::torque, "[N m] torque on the tool (x, y, z)")
      .def_readonly("in_contact", &protocol::Force::in_contact, "whether the tool touches the tissue")
      .def_readonly("contact_point_m", &protocol::Force::contact_point, "[m] where the local force model was linearised")
      .def_readonly("contact_normal", &protocol::Force::contact_normal, "unit normal out of the tissue at the contact")
      .def_readonly("penetration_m", &protocol::Force::penetration_m, "[m] how deep the tip is in the tissue (0 out of contact)")
      .def_readonly("tick", &protocol::Force::tick, "the physics tick it belongs to")
      .def_readonly("server_stamp_ns", &protocol::Force::server_stamp_ns, "[ns] the server's clock when sent (DDS time)")
      .def_readonly("max_edge_strain", &protocol::Force::max_edge_strain, "the organ's largest edge strain |L - L0| / L0 over that tick [-]")
      .def_readonly("cutting", &protocol::Force::cutting,
                    "a scalpel's blade cutting: its button held, or pressed through above the scene's cut force")
      .def_readonly("cut_edge_strain", &protocol::Force::cut_edge_strain,
                    "a cutting scalpel's: the largest edge strain of the tetrahedra it cut that tick, just after it cut them [-]")
      .def_readonly("tip_strain", &protocol::Force::tip_strain,
                    "the tissue's strain at the instrument after that tick: principal stretch strain |lambda - 1| averaged within the "
                    "scene's strain radius of where it touches (0 out of contact) [-]")
      .def_readonly("friction_mu", &protocol::Force::friction_mu,
                    "Coulomb friction at the contact: the tangential force is at most this times the normal one (0: none) [-]");
  py::class_<protocol::Event>(m, "Event", "A session event (server) or an annotation (client).")
      .def_property_readonly(
          "kind", [](const protocol::Event& e) { return std::string(protocol::event_name(e.kind)); },
          "annotation, instrument_claimed, contact_started, scene_loaded, ... (docs/PROTOCOL.md)")
      .def_property_readonly(
          "reason", [](const protocol::Event& e) { return std::string(protocol::event_reason_name(e.reason)); },
          "instrument_released: by_owner, owner_silent, scene_replaced or handed_back; else unspecified")
      .def_readonly("source_client_id", &protocol::Event::source_client_id, "who wrote it: 0 the server, else the client")
      .def_readonly("instrument_id", &protocol::Event::instrument_id, "the instrument (the scene file's id)")
      .def_readonly("client_id", &protocol::Event::client_id, "the client concerned (claimer, owner, requester), 0 if none")
      .def_readonly("sim_time_s", &protocol::Event::sim_time_s, "[s] simulated time")
      .def_readonly("stamp_ns", &protocol::Event::stamp_ns, "[ns] the writer's clock (DDS time)")
      .def_readonly("text", &protocol::Event::text, "the text (an annotation, a refusal's reason), at most 1024 bytes")
      .def_readonly("tick", &protocol::Event::tick, "the physics tick it belongs to")
      .def_readonly("scene", &protocol::Event::scene, "scene_loaded: the scene loaded");
  py::class_<protocol::TelemetryReport>(m, "Telemetry", "The server's health report (about one a second).")
      .def_readonly("steps", &protocol::TelemetryReport::steps, "physics ticks run so far")
      .def_readonly("physics_rate_hz", &protocol::TelemetryReport::physics_rate_hz, "[Hz] the physics rate")
      .def_readonly("step_p99_us", &protocol::TelemetryReport::step_p99_us, "[us] 99th percentile of the tick's duration")
      .def_readonly("late_ticks", &protocol::TelemetryReport::late_ticks, "ticks that ended after their slot")
      .def_readonly("missed_slots", &protocol::TelemetryReport::missed_slots, "slots of the fixed-rate grid that passed with no tick")
      .def_readonly("rejected_messages", &protocol::TelemetryReport::rejected_messages, "messages dropped: failed verification or ownership");
  py::class_<protocol::SurfaceTopology, std::shared_ptr<protocol::SurfaceTopology>>(m, "SurfaceTopology", "The organ's boundary surface.")
      .def_readonly("mesh_id", &protocol::SurfaceTopology::mesh_id, "the organ mesh (SurfaceTopology.mesh_id; +1 per scene loaded)")
      .def_readonly("organ_name", &protocol::SurfaceTopology::organ_name, "the organ's name")
      .def_readonly("vertex_count", &protocol::SurfaceTopology::vertex_count, "vertices of the surface")
      .def_readonly("topology_generation", &protocol::SurfaceTopology::topology_generation, "0 as loaded, higher after each change a cut made")
      .def_property_readonly(
          "triangles",
          [](const py::object& self) {
            const auto& t = self.cast<const protocol::SurfaceTopology&>().triangles;
            return view_array<std::uint32_t>(t.data(), {static_cast<py::ssize_t>(t.size() / 3), 3}, {12, 4}, self);
          },
          "(triangles, 3) vertex indices, outward by the right-hand rule; a read-only view")
      .def_property_readonly(
          "rest_positions",
          [](const py::object& self) {
            const auto& p = self.cast<const protocol::SurfaceTopology&>().rest_positions;
            return view_array<float>(p.data(), {static_cast<py::ssize_t>(p.size() / 3), 3}, {12, 4}, self);
          },
          "(vertices, 3) float32 [m] rest positions; a read-only view");
  py::class_<protocol::MeshFrame, std::shared_ptr<protocol::MeshFrame>>(m, "MeshFrame", "The deformed surface at one instant.")
      .def_readonly("mesh_id", &protocol::MeshFrame::mesh_id, "the organ mesh (SurfaceTopology.mesh_id; +1 per scene loaded)")
      .def_readonly("frame", &protocol::MeshFrame::frame, "1, 2, ... per mesh")
      .def_readonly("sim_time_s", &protocol::MeshFrame::sim_time_s, "[s] simulated time")
      .def_readonly("tick", &protocol::MeshFrame::tick, "the physics tick it belongs to")
      .def_readonly("topology_generation", &protocol::MeshFrame::topology_generation,
                    "the surface (SurfaceTopology.topology_generation) its vertices are of")
      .def_property_readonly(
          "positions",
          [](const py::object& self) {
            const auto& p = self.cast<const protocol::MeshFrame&>().positions;
            return view_array<float>(p.data(), {static_cast<py::ssize_t>(p.size() / 3), 3}, {12, 4}, self);
          },
          "(vertices, 3) float32 [m]: a read-only view of the received frame, no copy; it keeps the frame alive");
  py::class_<client::ClaimResult>(m, "ClaimResult", "What became of a claim (truthy when claimed).")
      .def_readonly("claimed", &client::ClaimResult::claimed, "whether the instrument is this client's now")
      .def_readonly("why", &client::ClaimResult::why, "when not claimed: the server's reason, or the timeout")
      .def("__bool__", [](const client::ClaimResult& c) { return c.claimed; });
  py::class_<client::LatencyStats>(m, "LatencyStats", "Command-to-force round trips [us].")
      .def_readonly("samples", &client::LatencyStats::samples, "round trips measured")
      .def_readonly("p50_us", &client::LatencyStats::p50_us, "[us] median round trip")
      .def_readonly("p99_us", &client::LatencyStats::p99_us, "[us] 99th percentile round trip")
      .def_readonly("max_us", &client::LatencyStats::max_us, "[us] longest round trip");

  using Outcome = std::optional<protocol::RequestOutcome>;
  const auto unlocked = py::call_guard<py::gil_scoped_release>();
  py::class_<Client>(m, "Client",
                     "One client of a viscera-server: a DDS participant under one client id. Use it from one thread "
                     "(send_tip may run on another thread than the requests).")
      .def(py::init<std::uint32_t, std::uint32_t, const std::string&>(), py::arg("domain_id"), py::arg("client_id"), py::arg("partition") = "",
           unlocked)
      .def_property_readonly("client_id", &Client::id, "this client's id")
      .def(
          "wait_for_scene", [](Client& c, double timeout_s) { return c.wait_for_scene(ms(timeout_s)); }, py::arg("timeout_s"), unlocked,
          "Waits up to timeout_s [s] for the server's scene state; None if none came.")
      .def("scene", &Client::scene, unlocked, "The newest scene state, without waiting (None if none).")
      .def(
          "claim", [](Client& c, std::uint32_t id, double timeout_s) { return c.claim(id, ms(timeout_s)); }, py::arg("instrument_id"),
          py::arg("timeout_s") = 2.0, unlocked)
      .def("release", &Client::release, py::arg("instrument_id"), unlocked)
      .def(
          "pause", [](Client& c, double t) { return c.control(protocol::Action::pause, ms(t)); }, py::arg("timeout_s") = 2.0, unlocked)
      .def(
          "resume", [](Client& c, double t) { return c.control(protocol::Action::resume, ms(t)); }, py::arg("timeout_s") = 2.0, unlocked)
      .def(
          "reset", [](Client& c, double t) { return c.control(protocol::Action::reset, ms(t)); }, py::arg("timeout_s") = 2.0, unlocked)
      .def(
          "load_scene",
          [](Client& c, const std::string& name, double t, std::optional<std::uint64_t> seed) -> Outcome { return c.load_scene(name, ms(t), seed); },
          py::arg("name"), py::arg("timeout_s") = 30.0, py::arg("seed") = std::nullopt, unlocked)
      .def(
          "set_material",
          [](Client& c, std::optional<double> e, std::optional<double> nu, std::optional<double> rho, std::optional<double> q,
             std::optional<double> damping, std::optional<std::string> file_text, const std::string& file_name, double t) -> Outcome {
            protocol::MaterialChange change;
            change.youngs_modulus_pa = e;
            change.poisson_ratio = nu;
            change.density_kg_m3 = rho;
            change.shear_q = q;
            change.damping_per_s = damping;
            change.file_text = std::move(file_text);
            change.file_name = file_name;
            if (change.empty()) throw common::UsageError("set_material: give at least one parameter or a file");
            return c.set_material(change, ms(t));
          },
          py::kw_only(), py::arg("youngs_modulus_pa") = std::nullopt, py::arg("poisson_ratio") = std::nullopt,
          py::arg("density_kg_m3") = std::nullopt, py::arg("shear_q") = std::nullopt, py::arg("damping_per_s") = std::nullopt,
          py::arg("file_text") = std::nullopt, py::arg("file_name") = "material.json", py::arg("timeout_s") = 30.0, unlocked)
      .def(
          "set_physics_rate", [](Client& c, double hz, double t) -> Outcome { return c.set_physics_rate(hz, ms(t)); }, py::arg("rate_hz"),
          py::arg("timeout_s") = 10.0, unlocked)
      .def(
          "take_over", [](Client& c, std::uint32_t id, double t) -> Outcome { return c.take_over(id, ms(t)); }, py::arg("instrument_id"),
          py::arg("timeout_s") = 2.0, unlocked)
      .def(
          "hand_back", [](Client& c, std::uint32_t id, double t) -> Outcome { return c.hand_back(id, ms(t)); }, py::arg("instrument_id"),
          py::arg("timeout_s") = 2.0, unlocked)
      .def(
          "send_tip",
          [](Client& c, std::uint32_t id, const std::vector<double>& tip, double jaw, std::uint32_t buttons) {
            const auto p = vector3(tip, "tip_m");
            py::gil_scoped_release released;
            c.send_tip(id, p, jaw, buttons);
          },
          py::arg("instrument_id"), py::arg("tip_m"), py::arg("jaw_opening_rad") = 0.5, py::arg("buttons") = 0,
          "Sends the instrument's tip position [m] (scene frame), jaw opening [rad] and buttons (a bit mask).")
      .def("poll_force", &Client::poll_force, py::arg("instrument_id"), unlocked, "The newest force that arrived, if any.")
      .def(
          "wait_force",
          [](Client& c, std::uint32_t id, double timeout_s) { return c.wait_force(id, std::chrono::steady_clock::now() + ms(timeout_s)); },
          py::arg("instrument_id"), py::arg("timeout_s") = 0.01, unlocked,
          "Waits up to timeout_s [s] for the force answering the newest command; returns the newest force seen either way.")
      .def("round_trip", &Client::round_trip, "Command-to-force round trips measured so far.")
      .def("last_tick_end_ns", &Client::last_tick_end_ns, py::arg("instrument_id"),
           "[ns] when the server ended the newest tick whose force for the instrument was taken (DDS time), for TickPhase; None before")
      .def(
          "surface",
          [](Client& c) -> std::shared_ptr<protocol::SurfaceTopology> {
            std::optional<protocol::SurfaceTopology> t;
            {
              py::gil_scoped_release released;
              t = c.surface();
            }
            return t ? std::make_shared<protocol::SurfaceTopology>(std::move(*t)) : nullptr;
          },
          "The organ's boundary surface once it arrived (the first call subscribes to the mesh streams); None before.")
      .def(
          "poll_mesh_frame",
          [](Client& c) -> std::shared_ptr<protocol::MeshFrame> {
            std::optional<protocol::MeshFrame> f;
            {
              py::gil_scoped_release released;
              f = c.poll_mesh_frame();
            }
            return f ? std::make_shared<protocol::MeshFrame>(std::move(*f)) : nullptr;
          },
          "The newest surface frame since the last call, checked against the topology; None if none.")
      .def_property_readonly("mesh_frames_received", &Client::mesh_frames_received, "surface frames received so far")
      .def("poll_events", &Client::poll_events, unlocked, "Events since the last call, in order (the first call subscribes).")
      .def("poll_telemetry", &Client::poll_telemetry, unlocked, "Health reports since the last call (the first call subscribes).")
      .def("annotate", &Client::annotate, py::arg("text"), unlocked, "Publishes an annotation (at most 1024 bytes) for recorders and consoles.")
      .def_property_readonly("server_state", &Client::server_state, "whether the server is there (its DDS liveliness)")
      .def_property_readonly("rejected", &Client::rejected, "Payloads that failed verification and were dropped.")
      .def_property_readonly("last_rejection", &Client::last_rejection, "why the newest rejected payload was (\"\" if none)");
  py::class_<client::TickPhase>(m, "TickPhase",
                                "Keeps a periodic loop at a fixed phase after the server's physics ticks (the C++ device loop's "
                                "scheduler): its commands arrive in the server's idle time, each tick takes a command of the same age.")
      .def(py::init([](double period_s, double offset_s, double max_step_s) {
             if (!(period_s > 0 && period_s <= 1)) throw common::UsageError("period_s must lie in (0, 1] s");
             if (!(offset_s >= 0 && offset_s < period_s)) throw common::UsageError("offset_s must lie in [0, period_s)");
             if (!(max_step_s > 0 && max_step_s <= period_s)) throw common::UsageError("max_step_s must lie in (0, period_s]");
             const auto ns = [](double s) { return std::chrono::nanoseconds(static_cast<long long>(s * 1e9)); };
             return client::TickPhase(ns(period_s), ns(offset_s), ns(max_step_s));
           }),
           py::arg("period_s"), py::arg("offset_s") = 100e-6, py::arg("max_step_s") = 20e-6,
           "period_s: the loop's period [s] (the server's tick); offset_s: where to run after a tick's end [s]; max_step_s: the largest "
           "correction per period [s].")
      .def(
          "error_ns",
          [](const client::TickPhase& p, std::int64_t next_ns, std::int64_t tick_end_ns) { return p.error(next_ns, tick_end_ns).count(); },
          py::arg("next_ns"), py::arg("tick_end_ns"), "[ns] signed distance of next_ns from the nearest target time (DDS time)")
      .def(
          "correction_ns",
          [](const client::TickPhase& p, std::int64_t next_ns, std::int64_t tick_end_ns) { return p.correction(next_ns, tick_end_ns).count(); },
          py::arg("next_ns"), py::arg("tick_end_ns"), "[ns] what to add to the loop's next time (an eighth of -error, at most max_step_s)");
  m.def("now_ns", &client::now_ns, "The protocol's clock [ns] (DDS time, the wall clock).");
}

}  // namespace viscera::python
