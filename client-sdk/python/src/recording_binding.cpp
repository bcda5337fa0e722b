// viscera._viscera.recording: a recording opened by viscera's reader, its streams read into  // SPDX-License-Identifier: Apache-2.0
// columns (recording_tables.hpp) handed to numpy without copying.
#include <pybind11/stl.h>

#include "viscera/protocol/dds.hpp"
#include "viscera/recording/recording.hpp"
#include "viscera/recording/recording_tables.hpp"

#include "bindings.hpp"
#include "numpy_views.hpp"

namespace viscera::python {

namespace {

using recording::Recording;

py::object column_array(recording::Column& c) {
  return std::visit(
      [](auto& v) -> py::object {
        using V = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<V, std::vector<std::string>>) {
          py::list l(v.size());
          for (std::size_t i = 0; i < v.size(); ++i) l[i] = py::str(v[i]);
          return l;
        } else if constexpr (std::is_same_v<V, std::vector<std::uint8_t>>) {
          return owning_array(std::move(v)).attr("view")("bool");  // flags: 0 or 1, one byte each
        } else {
          return owning_array(std::move(v));
        }
      },
      c.values);
}

py::dict frames_dict(recording::FrameSeries& s) {
  py::dict d;
  const auto n = static_cast<py::ssize_t>(s.frame.size()), v = static_cast<py::ssize_t>(s.vertex_count);
  d["mesh_id"] = s.mesh_id;
  d["vertex_count"] = s.vertex_count;
  d["mismatched"] = s.mismatched;
  d["topology_generation"] = s.topology_generation;
  d["later_generation_frames"] = s.later_generation_frames;
  d["last_topology_generation"] = s.last_topology_generation;
  d["positions"] = owning_array(std::move(s.positions), {n, v, 3});
  d["log_time_ns"] = owning_array(std::move(s.log_time_ns));
  d["frame"] = owning_array(std::move(s.frame));
  d["tick"] = owning_array(std::move(s.tick));
  d["sim_time_s"] = owning_array(std::move(s.sim_time_s));
  const auto t = static_cast<py::ssize_t>(s.triangles.size() / 3);
  d["triangles"] = owning_array(std::move(s.triangles), {t, 3});
  const auto r = static_cast<py::ssize_t>(s.rest_positions.size() / 3);
  d["rest_positions"] = owning_array(std::move(s.rest_positions), {r, 3});
  return d;
}

/// {"streams": {name: {"log_time_ns", "columns" (name -> array, in order), "undecodable",
/// "last_error"}}, "frames": {mesh_id: {...}}}.
py::dict read(Recording& r, const std::set<std::string>& streams, bool with_frames) {
  recording::RecordingTables t;
  {
    py::gil_scoped_release unlocked;
    t = recording::read_tables(r, streams, with_frames);
  }
  py::dict out, tables, frames;
  for (auto& [name, table] : t.streams) {
    py::dict d, columns;
    d["log_time_ns"] = owning_array(std::move(table.log_time_ns));
    for (auto& c : table.columns) columns[py::str(c.name)] = column_array(c);
    d["columns"] = columns;
    d["undecodable"] = table.undecodable;
    d["last_error"] = table.last_error;
    tables[py::str(name)] = d;
  }
  for (auto& [id, series] : t.frames) frames[py::int_(id)] = frames_dict(series);
  out["streams"] = tables;
  out["frames"] = frames;
  return out;
}

py::list scenes(const Recording& r) {
  py::list l;
  for (const auto& s : r.scenes()) {
    py::dict d;
    d["generation"] = s.generation;
    d["first_tick"] = s.first_tick;
    d["sim_time_s"] = s.sim_time_s;
    d["server_version"] = s.server_version;
    d["settings_json"] = s.settings_json;
    d["log_time_ns"] = s.log_time_ns;
    py::list files;
    for (const auto& f : s.files) {
      py::dict fd;
      fd["role"] = f.role;
      fd["path"] = f.path;
      fd["attachment"] = f.attachment;
      fd["sha256"] = f.sha256;
      files.append(fd);
    }
    d["files"] = files;
    l.append(d);
  }
  return l;
}

/// Messages per stream, from the summary's statistics (what the recorder wrote).
std::map<std::string, std::uint64_t> message_counts(const Recording& r) {
  std::map<std::string, std::uint64_t> counts;
  if (!r.summary().statistics) return counts;
  for (const auto& [id, ch] : r.channels()) {
    const auto& per_channel = r.summary().statistics->channel_message_counts;
    const auto it = per_channel.find(id);
    counts[protocol::stream_name(ch.stream)] += it == per_channel.end() ? 0 : it->second;
  }
  return counts;
}

}  // namespace

void bind_recording(py::module_& m) {
  py::class_<Recording>(m, "Recording", "A session recording (MCAP) checked and opened by viscera's reader.")
      .def(py::init<const std::string&>(), py::arg("path"),
           "Opens a recording. Raises InputError naming the file: not MCAP, damaged, cut short (recover it with "
           "viscera-record recover), not a viscera recording, or of a newer schema.")
      .def_property_readonly("path", &Recording::path, "the file")
      .def_property_readonly("info", &Recording::info, "Metadata viscera.recording: schema_version, domain_id, partition, streams, recorder.")
      .def_property_readonly("drops", &Recording::drops, "Metadata viscera.drops: samples the recorder lost per stream (None if recovered).")
      .def_property_readonly("start_ns", &Recording::start_ns, "[ns] log time of the first message.")
      .def_property_readonly("end_ns", &Recording::end_ns, "[ns] log time of the last message.")
      .def_property_readonly("scenes", &scenes, "The scenes the server ran, each with the files it was built from.")
      .def_property_readonly("message_counts", &message_counts, "Messages per stream, from the recording's summary.")
      .def(
          "attachment",
          [](Recording& r, const std::string& name) {
            const auto bytes = r.attachment(name);
            return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
          },
          py::arg("name"), "An attached file's content (a scene's mesh, material or scene file).")
      .def("read", &read, py::arg("streams") = std::set<std::string>{}, py::arg("frames") = true,
           "Reads the streams named (all tabulated streams when empty) in one pass; the GIL is released meanwhile.");
  m.def("tabulated_streams", [] {
    std::vector<std::string> names;
    for (auto s : recording::tabulated_streams()) names.emplace_back(protocol::stream_name(s));
    return names;
  });
}

}  // namespace viscera::python
