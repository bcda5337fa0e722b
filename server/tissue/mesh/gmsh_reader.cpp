// Gmsh .msh readers: legacy v1 ($NOD/$ELM), ASCII v2 ($MeshFormat 2.x) and ASCII v4.1.
#include <string>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/mesh/mesh_builder.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/text_cursor.hpp"

namespace viscera::tissue {

using common::InputError;
using common::printable;

namespace {

constexpr long long kTet4 = 4;

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
    if (v1) {
      in.integer("element physical region");
      in.integer("element elementary region");
      const long long count = in.integer("element node count");
      if (count != nodes)
        in.fail("element " + std::to_string(id) + " node count", std::to_string(count) + " does not match type " + std::to_string(type));
    } else {
      const long long tags = in.integer_in("element tag count", 0, 64);
      for (long long k = 0; k < tags; ++k) in.integer("element tag");
    }
    std::array<long long, 4> ids{};
    for (int k = 0; k < nodes; ++k) {
      const long long v = in.integer("element node id");
      if (k < 4) ids[k] = v;
    }
    if (type == kTet4) b.add_tet(ids, id, line);
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
    std::vector<long long> tags(count);
    std::vector<long> lines(count);
    for (auto& t : tags) t = in.integer("node tag");
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

void read_elements_v4(TextCursor& in, MeshBuilder& b) {
  const long long blocks = in.integer_in("element block count", 0, 100'000'000);
  in.integer_in("element count", 0, 1'000'000'000);
  in.integer("min element tag");
  in.integer("max element tag");
  for (long long blk = 0; blk < blocks; ++blk) {
    in.integer("entity dimension");
    in.integer("entity tag");
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
      if (type == kTet4) b.add_tet(ids, id, line);
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
        read_elements_v4(in, b);
      elements = true;
    } else if (section.starts_with("$")) {
      // Any other section ($PhysicalNames, $Entities, $NodeData...): skip to its end marker.
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
