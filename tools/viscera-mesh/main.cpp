// viscera-mesh: a patient's organ from a label map: tetrahedra of the organ's labels (CGAL Mesh_3),  // SPDX-License-Identifier: Apache-2.0
// a Gmsh mesh with a physical group per label, a scene the server loads as it is, a report of the
// mesh's fidelity and quality and a picture (docs/MESHING.md). Its source is Apache-2.0; the program
// links CGAL's Mesh_3, so its binary as a whole carries GPL-3.0-or-later (NOTICE).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include <nlohmann/json.hpp>

#include "viscera/common/command_line.hpp"
#include "viscera/common/existing_output.hpp"
#include "viscera/common/file_bytes.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/plain_name.hpp"
#include "viscera/common/same_file.hpp"

#include "make_organ.hpp"

namespace {

using viscera::common::InputError;
using viscera::common::UsageError;

/// The comma-separated items of a flag's value (an empty item stays, to be refused by its reader).
std::vector<std::string> items(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    out.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

std::vector<std::int32_t> label_list(const std::string& flag, const std::string& text) {
  std::vector<std::int32_t> out;
  for (const std::string& item : items(text)) {
    char* stop = nullptr;
    const long long v = std::strtoll(item.c_str(), &stop, 10);
    if (item.empty() || *stop != '\0' || v < -2'147'483'648LL || v > 2'147'483'647LL || v == 0)
      throw UsageError("--" + flag + ": '" + viscera::common::printable(item) + "' is not a label (a non-zero integer)");
    out.push_back(static_cast<std::int32_t>(v));
  }
  return out;
}

/// --region LABEL:NAME:MATERIAL[,LABEL:NAME:MATERIAL...]
std::vector<viscera::meshing::RegionLabel> region_list(const std::string& text) {
  std::vector<viscera::meshing::RegionLabel> out;
  for (const std::string& item : items(text)) {
    const std::size_t a = item.find(':'), b = a == std::string::npos ? a : item.find(':', a + 1);
    if (b == std::string::npos) throw UsageError("--region: '" + viscera::common::printable(item) + "' is not LABEL:NAME:MATERIAL");
    viscera::meshing::RegionLabel r;
    r.label = label_list("region", item.substr(0, a)).at(0);
    r.name = item.substr(a + 1, b - a - 1);
    r.material = item.substr(b + 1);
    if (!viscera::common::is_plain_name(r.name))
      throw UsageError("--region: the name '" + viscera::common::printable(r.name) + "' is not 1-64 letters, digits, '.', '_' or '-'");
    if (r.material.empty()) throw UsageError("--region: '" + viscera::common::printable(item) + "' names no material file");
    out.push_back(r);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  viscera::common::CommandLine cl("viscera-mesh",
                                  "Turns a label map (NIfTI .nii or .nii.gz: TotalSegmentator, 3D Slicer) into an organ the server runs: a Gmsh\n"
                                  "mesh of the organ's labels (CGAL Mesh_3, one physical group per label, the interfaces conforming), a scene file\n"
                                  "(materials per label, where the organ is held, the instruments), a report (each label's mesh volume against its\n"
                                  "voxels, the surface's distance to the label boundary, element quality, the explicit step, each stage's time) and\n"
                                  "a picture (docs/MESHING.md). Writes OUT/NAME.msh, NAME.json, NAME.svg and reports/NAME.json.\n"
                                  "Exit status 2: bad arguments or input (one line names the file, field and value).");
  cl.usage(
      "viscera-mesh LABELMAP.nii[.gz] --organ LABELS --material FILE --out DIR [--name NAME] [--region LABEL:NAME:FILE,...] "
      "[--tets N | --edge-mm MM] [--hold-touching LABELS] [--hold-crop]");
  cl.flag("organ", "LABELS", "the labels of the organ's own tissue, comma-separated (TotalSegmentator: 5 is the liver)");
  cl.flag("organ-name", "NAME", "the organ's physical group", "organ");
  cl.flag("material", "FILE", "the organ's material file (data/materials/liver-viscoelastic.json)");
  cl.flag("region", "LABEL:NAME:FILE,...", "labels inside the organ with a material of their own (4:gallbladder:gallbladder.json)");
  cl.flag("nodule", "MM:FILE",
          "a spherical nodule of this radius and material under the organ's upper surface, 2-5 mm deep, its centre drawn by the "
          "server (seed 1): the palpation exercise's region 'nodule'");
  cl.flag("tets", "N", "about this many tetrahedra (200 to 2,000,000); the edge length is found by up to 4 meshings", "12000");
  cl.flag("edge-mm", "MM", "instead of --tets: the tetrahedra's edge length bound [mm]");
  cl.flag("facet-distance-mm", "MM", "how far the surface may stray from the label boundary [mm] (default: the smallest voxel edge)");
  cl.flag("sliver-deg", "DEG", "the smallest dihedral angle sliver perturbation and exudation aim at [deg]", "20");
  cl.option_switch("optimize", "also run CGAL's ODT smoothing before the sliver removal (better shaped, slower)");
  cl.flag("hold-touching", "LABELS", "hold the organ where it touches these labels (63: the inferior vena cava)");
  cl.flag("hold-distance-mm", "MM", "a face touches a label whose voxel centre lies this close (default: one voxel diagonal)");
  cl.option_switch("hold-crop", "hold the organ where the image's crop cut it (the faces beyond its outermost voxel centres)");
  cl.flag("frame", "FRAME", "table: the patient supine, anterior up (+z), head along +y, the organ centred; patient: NIfTI's RAS [m]", "table");
  cl.flag("out", "DIR", "the folder written (created if missing)");
  cl.flag("name", "NAME", "the scene's name and the files' stem", "patient-organ");
  cl.flag("seed", "N", "CGAL's random choices (the same seed, the same mesh)", "1");
  cl.option_switch("replace", "replace NAME's files in DIR if they exist (never through a symbolic link)");
  cl.option_switch("quiet", "no progress lines");
  cl.allow_positional(1);
  try {
    if (!cl.parse(argc, argv)) return 0;
    if (cl.positional().size() != 1) throw UsageError("expected one label map (see --help)");
    if (!cl.given("organ")) throw UsageError("--organ: which labels make the organ (e.g. --organ 5 for TotalSegmentator's liver)");
    if (!cl.given("material")) throw UsageError("--material: the organ's material file (e.g. data/materials/liver-viscoelastic.json)");
    if (!cl.given("out")) throw UsageError("--out: the folder to write the organ into");
    viscera::meshing::OrganRequest r;
    r.label_map = cl.positional()[0];
    r.organ_labels = label_list("organ", cl.text("organ"));
    r.organ_name = cl.text("organ-name");
    if (!viscera::common::is_plain_name(r.organ_name))
      throw UsageError("--organ-name: '" + viscera::common::printable(r.organ_name) + "' is not 1-64 letters, digits, '.', '_' or '-'");
    r.material = cl.text("material");
    if (cl.given("region")) r.regions = region_list(cl.text("region"));
    for (const auto& region : r.regions)
      if (cl.given("nodule") && region.name == "nodule") throw UsageError("--region: the name 'nodule' is --nodule's; name the region otherwise");
    if (cl.given("nodule")) {
      const std::string v = cl.text("nodule");
      const std::size_t colon = v.find(':');
      const std::string radius = colon == std::string::npos ? std::string() : v.substr(0, colon);
      char* stop = nullptr;
      const double mm = radius.empty() ? 0 : std::strtod(radius.c_str(), &stop);
      if (radius.empty() || *stop != '\0' || !(mm >= 1 && mm <= 50) || colon + 1 == v.size())
        throw UsageError("--nodule: '" + viscera::common::printable(v) + "' is not RADIUS_MM:MATERIAL with a radius of 1-50 mm");
      r.nodule_radius_m = mm * 1e-3;
      r.nodule_material = v.substr(colon + 1);
    }
    if (cl.given("edge-mm") && cl.given("tets")) throw UsageError("--edge-mm and --tets: give one (the size, or the count)");
    if (cl.given("edge-mm"))
      r.edge_m = cl.number_in("edge-mm", 0.1, 500) * 1e-3;
    else
      r.target_tets = static_cast<std::size_t>(cl.integer_in("tets", 200, 2'000'000));
    if (cl.given("facet-distance-mm")) r.facet_distance_m = cl.number_in("facet-distance-mm", 0.01, 100) * 1e-3;
    r.sliver_bound_deg = cl.number_in("sliver-deg", 1, 30);
    r.optimize = cl.has("optimize");
    if (cl.given("hold-touching")) r.hold.touching = label_list("hold-touching", cl.text("hold-touching"));
    if (cl.given("hold-distance-mm")) r.hold.touch_distance_m = cl.number_in("hold-distance-mm", 0.01, 100) * 1e-3;
    r.hold.crop = cl.has("hold-crop");
    const std::string frame = cl.text("frame");
    if (frame != "table" && frame != "patient") throw UsageError("--frame: '" + viscera::common::printable(frame) + "' is not table or patient");
    r.table_frame = frame == "table";
    r.out_dir = cl.text("out");
    r.name = cl.text("name");
    if (!viscera::common::is_plain_name(r.name))
      throw UsageError("--name: '" + viscera::common::printable(r.name) + "' is not 1-64 letters, digits, '.', '_' or '-'");
    r.seed = static_cast<unsigned>(cl.integer_in("seed", 0, 4'294'967'295ULL));
    r.replace = cl.has("replace");
    r.quiet = cl.has("quiet");
    return viscera::meshing::make_organ(r);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "viscera-mesh: %s\n", e.what());
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "viscera-mesh: %s\n", e.what());
    return 2;
  }
}
