// libFuzzer target for every reader of a file a user edits or hands over: scene, material,  // SPDX-License-Identifier: Apache-2.0
// data set (its dataset.json and its CSV), fitted model, the Gmsh, legacy VTK and VTU mesh
// readers, the MCAP reader of session recordings (with the integrity judgement and recover) and the
// trainer's exercise files; JSON nested past the bound (seeded 100,000 deep); and the rule for names
// that become paths (a plain name never leaves its folder nor carries a control character). Whatever the bytes, a reader returns or throws InputError
// (one line naming the file); any other exception, a crash, a hang or an out-of-bounds read is a failure (built with ASan + UBSan by
// tests/fuzz/run_fuzz.sh).
//
// The first byte picks the reader; the rest is the file. Files are written to a folder of this
// process on tmpfs, since the readers take paths (as users give them).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/common/plain_name.hpp"
#include "viscera/lab/dataset.hpp"
#include "viscera/lab/model_file.hpp"
#include "viscera/mcap/integrity.hpp"
#include "viscera/mcap/mcap_reader.hpp"
#include "viscera/runtime/scene_file.hpp"
#include "viscera/tissue/material/material_file.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/training/exercise.hpp"

namespace {

const std::filesystem::path& folder() {
  static const std::filesystem::path dir = [] {
    const auto base = std::filesystem::exists("/dev/shm") ? std::filesystem::path("/dev/shm") : std::filesystem::temp_directory_path();
    auto d = base / ("viscera-readers-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

std::string write(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const auto path = folder() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

void write_text(const std::string& name, const std::string& text) { std::ofstream(folder() / name, std::ios::trunc) << text; }

// A well-formed data set around the fuzzed file, so the fuzzer reaches past the first checks.
const char* kDatasetJson =
    R"({"name": "f", "mode": "uniaxial", "specimen": {"length_m": 0.01, "width_m": 0.002, "thickness_m": 0.002, "density_kg_m3": 1000},
        "tests": [{"file": "a.csv", "control": "strain"}, {"file": "b.csv", "control": "stress"}]})";
const char* kCsv = "time_s,strain,stress_pa\n0,0,0\n1,0.01,10\n2,0.02,21\n";

// A session recording as the replayer and `viscera-record info` read it: the summary and every
// chunk, attachment and metadata record it indexes; then the data section walked as `recover`
// walks it, into a new file.
void read_mcap(const std::string& path) {
  viscera::mcap::McapReader reader(path);
  if (const auto summary = reader.summary()) {
    for (const auto& c : summary->chunks) (void)reader.read_chunk(c);
    for (const auto& a : summary->attachments) (void)reader.read_attachment(a);
    for (const auto& m : summary->metadata) (void)reader.read_metadata(m);
  }
  const auto copy = folder() / "recovered.mcap";
  std::filesystem::remove(copy);  // the last input's copy: recover writes a new file only
  (void)viscera::mcap::recover(path, copy.string());
  viscera::mcap::McapReader again(path);
  (void)viscera::mcap::check_integrity(again);
}

/// A name the rule accepts stays inside its folder and prints as itself.
void check_plain_name(std::string_view name) {
  if (!viscera::common::is_plain_name(name)) return;
  const std::filesystem::path dir("/reports");
  const auto inside = (dir / std::string(name)).lexically_normal();
  if (inside.parent_path() != dir || viscera::common::has_control_characters(name) || viscera::common::printable(name, 100) != name) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t pick = data[0] % 12;
  ++data;
  --size;
  using namespace viscera;
  try {
    switch (pick) {
      case 0: (void)runtime::read_scene_file(write("scene.json", data, size)); break;
      case 1: (void)tissue::read_material_file(write("material.json", data, size)); break;
      case 2: (void)lab::read_model(write("model.json", data, size)); break;
      case 3: (void)tissue::read_gmsh(write("mesh.msh", data, size)); break;
      case 4: (void)tissue::read_legacy_vtk(write("mesh.vtk", data, size)); break;
      case 5: (void)tissue::read_vtu(write("mesh.vtu", data, size)); break;
      case 6:
        write("dataset.json", data, size);
        write_text("a.csv", kCsv);
        write_text("b.csv", kCsv);
        (void)lab::read_dataset(folder().string());
        break;
      case 7:
        write_text("dataset.json", kDatasetJson);
        write("a.csv", data, size);
        write_text("b.csv", kCsv);
        (void)lab::read_dataset(folder().string());
        break;
      case 8: (void)common::parse_json(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json"); break;
      case 9: read_mcap(write("session.mcap", data, size)); break;
      case 10: (void)training::read_exercise_file(write("exercise.json", data, size)); break;
      case 11: check_plain_name(std::string_view(reinterpret_cast<const char*>(data), size)); break;
    }
  } catch (const common::InputError&) {
    // the one error a reader may give
  }
  return 0;
}
