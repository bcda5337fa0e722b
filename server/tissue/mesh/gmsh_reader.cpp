// Gmsh .msh readers: legacy v1 ($NOD/$ELM), ASCII v2 ($MeshFormat 2.x) and ASCII v4.1. The  // SPDX-License-Identifier: Apache-2.0
// tetrahedra's physical groups become the mesh's element sets: v1's physical region, v2's first
// tag, v4.1's volume entity's physical tags (from $Entities); names from $PhysicalNames.
#include <cstdlib>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "viscera/common/input_error.hpp"
#include "viscera/common/number_text.hpp"
#include "viscera/common/plain_name.hpp"
#include "viscera/tissue/mesh/mesh_builder.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/text_cursor.hpp"

namespace viscera::tissue {

using common::InputError;
using common::printable;

namespace {

constexpr long long kTet4 = 4;
constexpr long long kMaxTag = 2'147'483'647;

// Number of nodes of a Gmsh element type; -1 if unknown.
// NOLINTBEGIN(bugprone-branch-clone): a table of node counts, equal for some types
int gmsh_node_count(long long type) {
  switch (type) {
    case 1: return 2;  // line
    case 2: return 3;  // triangle
    case 3: return 4;  // quadrangle
    case 4: return 4;  // tetrahedron
    case 5: return 8;  // hexahedron
    case 6: return 6;  // prism
    case 7: return 5;  // pyramid
    case 8: return 3;  // second-order line
    case 9: return 6;  // second-order triangle
    case 10: return 9;  // second-order quadrangle
    case 11: return 10;  // second-order tetrahedron
    case 15: return 1;  // point
    default: return -1;
  }
}
// NOLINTEND(bugprone-branch-clone)

bool is_volume(long long type) { return type == 4 || type == 5 || type == 6 || type == 7 || type == 11; }

void check_type(TextCursor& in, long long type, long long element) {
  const std::string field = "element " + std::to_string(element) + " type";
  if (gmsh_node_count(type) < 0) in.fail(field, std::to_string(type) + " is not a known Gmsh element type");
  if (is_volume(type) && type != kTet4)
    in.fail(field, std::to_string(type) +
                       " is a volume element other than the linear tetrahedron (type 4), which is "
                       "all viscera simulates");
}

void expect(TextCursor& in, std::string_view marker) {
  const std::string_view t = in.token(marker);
  if (t != marker) in.fail(marker, "expected '" + std::string(marker) + "', found '" + printable(t) + "'");
}

void read_nodes_v1v2(TextCursor& in, MeshBuilder& b, std::string_view end) {
  const long long n = in.integer_in("node count", 1, 100'000'000);
  for (long long i = 0; i < n; ++i) {
    const long line = in.next_line();
    const long long id = in.integer("node id");
    Vec3 p;
    p.x() = in.real("node x");
    p.y() = in.real("node y");
    p.z() = in.real("node z");
    b.add_node(id, p, line);
  }
  expect(in, end);
}

void read_elements_v1v2(TextCursor& in, MeshBuilder& b, bool v1, std::string_view end) {
  const long long m = in.integer_in("element count", 0, 1'000'000'000);
  for (long long i = 0; i < m; ++i) {
    const long line = in.next_line();
    const long long id = in.integer("element id");
    const long long type = in.integer("element type");
    check_type(in, type, id);
    int nodes = gmsh_node_count(type);
    int physical = 0;  // 0: in no physical group
    if (v1) {
      physical = static_cast<int>(in.integer_in("element physical region", 0, kMaxTag));
      in.integer("element elementary region");
      const long long count = in.integer("element node count");
      if (count != nodes)
        in.fail("element " + std::to_string(id) + " node count", std::to_string(count) + " does not match type " + std::to_string(type));
    } else {
      const long long tags = in.integer_in("element tag count", 0, 64);
      for (long long k = 0; k < tags; ++k) {
        const long long tag = in.integer("element tag");
        if (k == 0) {  // the physical group
          if (tag < 0 || tag > kMaxTag)
            in.fail("element " + std::to_string(id) + " physical tag", common::outside(tag, 0LL, static_cast<long long>(kMaxTag)));
          physical = static_cast<int>(tag);
        }
      }
    }
    std::array<long long, 4> ids{};
    for (int k = 0; k < nodes; ++k) {
      const long long v = in.integer("element node id");
      if (k < 4) ids[k] = v;
    }
    if (type == kTet4) b.add_tet(ids, id, line, physical > 0 ? std::span<const int>(&physical, 1) : std::span<const int>());
  }
  expect(in, end);
}

void read_nodes_v4(TextCursor& in, MeshBuilder& b) {
  const long long blocks = in.integer_in("node block count", 0, 100'000'000);
  in.integer_in("node count", 0, 1'000'000'000);
  in.integer("min node tag");
  in.integer("max node tag");
  for (long long blk = 0; blk < blocks; ++blk) {
    in.integer("entity dimension");
    in.integer("entity tag");
    const long long parametric = in.integer_in("parametric", 0, 1);
    const long long count = in.integer_in("nodes in block", 0, 1'000'000'000);
    // Grown as the file proves it holds them: the header may claim 10^9 nodes in 100 bytes.
    std::vector<long long> tags;
    for (long long k = 0; k < count; ++k) tags.push_back(in.integer("node tag"));
    for (long long k = 0; k < count; ++k) {
      const long line = in.next_line();
      Vec3 p;
      p.x() = in.real("node x");
      p.y() = in.real("node y");
      p.z() = in.real("node z");
      if (parametric) in.fail("parametric", "parametric node coordinates are not supported");
      b.add_node(tags[k], p, line);
    }
  }
  expect(in, "$EndNodes");
}

/// v4.1 $Entities: the physical tags of each volume entity (points, curves and surfaces skipped).
using PhysicalsOfVolume = std::map<long long, std::vector<int>>;

std::vector<int> read_physical_tags(TextCursor& in) {
  const long long n = in.integer_in("entity physical tag count", 0, 1'000'000);
  std::vector<int> tags;
  for (long long k = 0; k < n; ++k) tags.push_back(static_cast<int>(in.integer_in("entity physical tag", -kMaxTag, kMaxTag)));
  return tags;
}

PhysicalsOfVolume read_entities_v4(TextCursor& in) {
  long long count[4];
  for (long long& c : count) c = in.integer_in("entity count", 0, 1'000'000'000);
  PhysicalsOfVolume out;
  for (int dim = 0; dim < 4; ++dim)
    for (long long k = 0; k < count[dim]; ++k) {
      const long long tag = in.integer("entity tag");
      for (int c = 0; c < (dim == 0 ? 3 : 6); ++c) in.real("entity coordinate");
      std::vector<int> physicals = read_physical_tags(in);
      if (dim > 0) {
        const long long bounding = in.integer_in("entity bounding count", 0, 1'000'000'000);
        for (long long j = 0; j < bounding; ++j) in.integer("entity bounding tag");
      }
      if (dim == 3) {
        for (int& p : physicals) p = std::abs(p);
        out[tag] = std::move(physicals);
      }
    }
  expect(in, "$EndEntities");
  return out;
}

/// $PhysicalNames: the names of the volume groups (dimension 3); a name is quoted and may hold spaces.
void read_physical_names(TextCursor& in, MeshBuilder& b) {
  const long long n = in.integer_in("physical name count", 0, 1'000'000);
  for (long long k = 0; k < n; ++k) {
    const long long dim = in.integer_in("physical name dimension", 0, 3);
    const long long tag = in.integer_in("physical name tag", 1, kMaxTag);
    std::string name = in.rest_of_line();
    const auto first = name.find_first_not_of(" \t\r"), last = name.find_last_not_of(" \t\r");
    name = first == std::string::npos ? std::string() : name.substr(first, last - first + 1);
    if (name.size() < 2 || name.front() != '"' || name.back() != '"') in.fail("physical name", "'" + printable(name) + "' is not a quoted name");
    if (common::has_control_characters(name)) in.fail("physical name", "'" + printable(name) + "' holds a control character (names are printed)");
    if (dim == 3) b.name_group(static_cast<int>(tag), name.substr(1, name.size() - 2));
  }
  expect(in, "$EndPhysicalNames");
}

void read_elements_v4(TextCursor& in, MeshBuilder& b, const PhysicalsOfVolume& physicals) {
  const long long blocks = in.integer_in("element block count", 0, 100'000'000);
  in.integer_in("element count", 0, 1'000'000'000);
  in.integer("min element tag");
  in.integer("max element tag");
  for (long long blk = 0; blk < blocks; ++blk) {
    const long long dim = in.integer("entity dimension");
    const long long entity = in.integer("entity tag");
    const auto found = physicals.find(entity);
    const std::span<const int> groups = dim == 3 && found != physicals.end() ? std::span<const int>(found->second) : std::span<const int>();
    const long long type = in.integer("element type");
    check_type(in, type, -1);
    const long long count = in.integer_in("elements in block", 0, 1'000'000'000);
    const int nodes = gmsh_node_count(type);
    for (long long k = 0; k < count; ++k) {
      const long line = in.next_line();
      const long long id = in.integer("element tag");
      std::array<long long, 4> ids{};
      for (int j = 0; j < nodes; ++j) {
        const long long v = in.integer("element node tag");
        if (j < 4) ids[j] = v;
      }
      if (type == kTet4) b.add_tet(ids, id, line, groups);
    }
  }
  expect(in, "$EndElements");
}

}  // namespace

TetMesh read_gmsh(const std::string& path) {
  TextCursor in = TextCursor::from_file(path);
  MeshBuilder b(path);
  int version = 0;  // 1, 2 or 4
  bool nodes = false, elements = false;
  PhysicalsOfVolume physicals;  // v4.1
  while (!in.at_end()) {
    const std::string section(in.token("section"));
    if (section == "$NOD") {
      version = 1;
      read_nodes_v1v2(in, b, "$ENDNOD");
      nodes = true;
    } else if (section == "$ELM") {
      if (!nodes) in.fail("$ELM", "elements before nodes");
      read_elements_v1v2(in, b, true, "$ENDELM");
      elements = true;
    } else if (section == "$MeshFormat") {
      const std::string_view v = in.token("format version");
      const long long file_type = in.integer("file type");
      in.integer("data size");
      if (file_type != 0) in.fail("file type", "binary .msh files are not supported; save as ASCII");
      if (v.starts_with("2.")) {
        version = 2;
      } else if (v == "4.1") {
        version = 4;
      } else {
        in.fail("format version", "'" + printable(v) + "' is not supported (1, 2.x, 4.1)");
      }
      expect(in, "$EndMeshFormat");
    } else if (section == "$Nodes") {
      if (version == 2)
        read_nodes_v1v2(in, b, "$EndNodes");
      else if (version == 4)
        read_nodes_v4(in, b);
      else
        in.fail("$Nodes", "no $MeshFormat before it");
      nodes = true;
    } else if (section == "$Elements") {
      if (!nodes) in.fail("$Elements", "elements before nodes");
      if (version == 2)
        read_elements_v1v2(in, b, false, "$EndElements");
      else
        read_elements_v4(in, b, physicals);
      elements = true;
    } else if (section == "$Entities" && version == 4) {
      physicals = read_entities_v4(in);
    } else if (section == "$PhysicalNames") {
      read_physical_names(in, b);
    } else if (section.starts_with("$")) {
      // Any other section ($NodeData, $Periodic...): skip to its end marker.
      const std::string end = "$End" + section.substr(1);
      if (!in.skip_past(end)) in.fail(printable(section), "section is not closed by " + printable(end));
    } else {
      in.fail("section", "expected a $Section, found '" + printable(section) + "'");
    }
  }
  if (!nodes) throw InputError(path, 0, "$Nodes", "missing: not a Gmsh mesh?");
  if (!elements) throw InputError(path, 0, "$Elements", "missing");
  return b.build();
}

}  // namespace viscera::tissue
