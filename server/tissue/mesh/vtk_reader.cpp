// VTK readers: legacy ASCII unstructured grid (.vtk, versions 2-4 "CELLS n size" layout and  // SPDX-License-Identifier: Apache-2.0
// 5.1 "OFFSETS/CONNECTIVITY" layout) and ASCII XML unstructured grid (.vtu).
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include <pugixml.hpp>

#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/common/number_text.hpp"
#include "viscera/tissue/mesh/mesh_builder.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/text_cursor.hpp"

namespace viscera::tissue {

using common::InputError;
using common::printable;
using common::read_text_file;

namespace {

constexpr long long kVtkTetra = 10;

// VTK volume cell types other than the linear tetrahedron.
bool is_other_volume_cell(long long type) { return type == 11 || type == 12 || type == 13 || type == 14 || type == 24 || type == 25 || type == 42; }

long long to_integer(TextCursor& in, std::string_view t, std::string_view field) {
  std::string why;
  const auto v = common::read_integer(t, &why);
  if (!v) in.fail(field, why);
  return *v;
}

/// `lines`: each cell's line in the file (empty: `line` for all).
void add_cells(const std::string& path, MeshBuilder& b, const std::vector<long long>& offsets, const std::vector<long long>& connectivity,
               const std::vector<long long>& types, const std::vector<long>& lines, long cells_line) {
  const std::size_t n = types.size();
  const long line = cells_line;
  if (offsets.size() != n + 1)
    throw InputError(path, line, "offsets", "has " + std::to_string(offsets.size()) + " entries for " + std::to_string(n) + " cells");
  for (std::size_t c = 0; c < n; ++c) {
    const long long begin = offsets[c], end = offsets[c + 1];
    const long cell_line = c < lines.size() ? lines[c] : line;
    if (begin < 0 || end < begin || end > static_cast<long long>(connectivity.size()))
      throw InputError(path, cell_line, "cell " + std::to_string(c), "offsets out of range");
    if (types[c] == kVtkTetra) {
      if (end - begin != 4)
        throw InputError(path, cell_line, "cell " + std::to_string(c), "tetrahedron with " + std::to_string(end - begin) + " points");
      b.add_tet({connectivity[begin], connectivity[begin + 1], connectivity[begin + 2], connectivity[begin + 3]}, static_cast<long long>(c),
                cell_line);
    } else if (is_other_volume_cell(types[c])) {
      throw InputError(path, cell_line, "cell " + std::to_string(c) + " type",
                       std::to_string(types[c]) +
                           " is a volume cell other than the linear "
                           "tetrahedron (10), which is all viscera simulates");
    }
  }
}

}  // namespace

TetMesh read_legacy_vtk(const std::string& path) {
  TextCursor in = TextCursor::from_file(path);
  const std::string header = in.rest_of_line();
  if (!header.starts_with("# vtk DataFile Version")) in.fail("header", "not a legacy VTK file (first line '" + printable(header) + "')");
  const bool v5 = header.find("5.") != std::string::npos;
  in.rest_of_line();  // title
  const std::string_view encoding = in.token("encoding");
  if (encoding != "ASCII") in.fail("encoding", "'" + printable(encoding) + "' is not supported (ASCII)");
  if (in.token("DATASET") != "DATASET") in.fail("DATASET", "missing");
  const std::string_view kind = in.token("DATASET");
  if (kind != "UNSTRUCTURED_GRID") in.fail("DATASET", "'" + printable(kind) + "' is not an UNSTRUCTURED_GRID");

  MeshBuilder b(path);
  std::vector<long long> offsets, connectivity, types;
  std::vector<long> lines;  // of each cell (CELLS of versions 2-4: a cell per line)
  long cells_line = 0;
  bool have_points = false, have_cells = false, have_types = false;
  while (!in.at_end()) {
    const std::string key(in.token("keyword"));
    if (key == "POINTS") {
      const long long n = in.integer_in("POINTS count", 1, 1'000'000'000);
      in.token("POINTS data type");
      for (long long i = 0; i < n; ++i) {
        const long line = in.next_line();
        Vec3 p;
        p.x() = in.real("point x");
        p.y() = in.real("point y");
        p.z() = in.real("point z");
        b.add_node(i, p, line);
      }
      have_points = true;
    } else if (key == "CELLS" && !v5) {
      cells_line = in.line();
      const long long n = in.integer_in("CELLS count", 0, 1'000'000'000);
      in.integer("CELLS size");
      offsets.assign(1, 0);
      for (long long c = 0; c < n; ++c) {
        lines.push_back(in.next_line());
        const long long k = in.integer_in("cell point count", 1, 1000);
        for (long long j = 0; j < k; ++j) connectivity.push_back(in.integer("cell point index"));
        offsets.push_back(static_cast<long long>(connectivity.size()));
      }
      have_cells = true;
    } else if (key == "CELLS" && v5) {
      cells_line = in.line();
      in.integer("CELLS offsets count");
      in.integer("CELLS connectivity count");
    } else if (key == "OFFSETS") {
      in.token("OFFSETS type");
      // Count is the CELLS line's; read until CONNECTIVITY.
      while (!in.at_end()) {
        const std::string_view t = in.token("offset");
        if (t == "CONNECTIVITY") break;
        offsets.push_back(to_integer(in, t, "offset"));
      }
      in.token("CONNECTIVITY type");
      while (!in.at_end()) {
        const std::string_view t = in.token("connectivity");
        if (t == "CELL_TYPES") {
          const long long n = in.integer("CELL_TYPES count");
          for (long long c = 0; c < n; ++c) types.push_back(in.integer("cell type"));
          have_types = true;
          break;
        }
        connectivity.push_back(to_integer(in, t, "connectivity"));
      }
      have_cells = true;
    } else if (key == "CELL_TYPES") {
      const long long n = in.integer_in("CELL_TYPES count", 0, 1'000'000'000);
      for (long long c = 0; c < n; ++c) types.push_back(in.integer("cell type"));
      have_types = true;
    } else if (key == "POINT_DATA" || key == "CELL_DATA" || key == "FIELD" || key == "METADATA") {
      break;  // attribute data follow; the mesh is complete
    } else {
      in.fail("keyword", "unexpected '" + printable(key) + "'");
    }
  }
  if (!have_points) throw InputError(path, 0, "POINTS", "missing");
  if (!have_cells) throw InputError(path, 0, "CELLS", "missing");
  if (!have_types) throw InputError(path, 0, "CELL_TYPES", "missing");
  add_cells(path, b, offsets, connectivity, types, lines, cells_line);
  return b.build();
}

namespace {

template <typename T>
std::vector<T> parse_ascii_array(const std::string& path, const pugi::xml_node& array, const char* name) {
  const std::string format = array.attribute("format").as_string("ascii");
  if (format != "ascii")
    throw InputError(path, 0, std::string("DataArray ") + name, "format '" + format + "' is not supported (save the VTU as ASCII)");
  std::istringstream ss(array.child_value());
  std::vector<T> out;
  std::string tok;
  while (ss >> tok) {
    std::string why;
    std::optional<T> v;
    if constexpr (std::is_floating_point_v<T>) {
      if (const auto x = common::read_number(tok, &why)) v = static_cast<T>(*x);
    } else {
      if (const auto x = common::read_integer(tok, &why)) v = static_cast<T>(*x);
    }
    if (!v) throw InputError(path, 0, std::string("DataArray ") + name, why);
    out.push_back(*v);
  }
  return out;
}

pugi::xml_node find_array(const pugi::xml_node& parent, const char* name) {
  for (pugi::xml_node a : parent.children("DataArray"))
    if (std::string(a.attribute("Name").as_string()) == name) return a;
  return {};
}

}  // namespace

TetMesh read_vtu(const std::string& path) {
  const std::string text = read_text_file(path, std::size_t{4} << 30);
  const auto line_at = [&](std::ptrdiff_t offset) {
    if (offset < 0 || static_cast<std::size_t>(offset) > text.size()) return 0L;
    return 1 + static_cast<long>(std::count(text.begin(), text.begin() + offset, '\n'));
  };
  pugi::xml_document doc;
  const pugi::xml_parse_result ok = doc.load_buffer(text.data(), text.size());
  if (!ok) throw InputError(path, line_at(ok.offset), "XML", std::string(ok.description()) + " at byte " + std::to_string(ok.offset));
  const pugi::xml_node file = doc.child("VTKFile");
  if (!file || std::string(file.attribute("type").as_string()) != "UnstructuredGrid")
    throw InputError(path, 0, "VTKFile", "not a VTK UnstructuredGrid file");
  const pugi::xml_node piece = file.child("UnstructuredGrid").child("Piece");
  if (!piece) throw InputError(path, 0, "Piece", "missing");
  const long long np = piece.attribute("NumberOfPoints").as_llong(-1);
  const long long nc = piece.attribute("NumberOfCells").as_llong(-1);
  if (np <= 0) throw InputError(path, 0, "NumberOfPoints", "missing or not positive");
  if (nc <= 0) throw InputError(path, 0, "NumberOfCells", "missing or not positive");

  const auto points = parse_ascii_array<double>(path, piece.child("Points").child("DataArray"), "Points");
  if (static_cast<long long>(points.size()) != 3 * np)
    throw InputError(path, 0, "Points", std::to_string(points.size()) + " values for " + std::to_string(np) + " points (expected 3 per point)");
  const pugi::xml_node cells = piece.child("Cells");
  const auto connectivity = parse_ascii_array<long long>(path, find_array(cells, "connectivity"), "connectivity");
  auto offsets = parse_ascii_array<long long>(path, find_array(cells, "offsets"), "offsets");
  const auto types = parse_ascii_array<long long>(path, find_array(cells, "types"), "types");
  if (static_cast<long long>(types.size()) != nc)
    throw InputError(path, 0, "types", std::to_string(types.size()) + " entries for NumberOfCells " + std::to_string(nc));
  offsets.insert(offsets.begin(), 0);  // VTU offsets are cell ends

  MeshBuilder b(path);
  const long points_line = line_at(piece.child("Points").child("DataArray").offset_debug());
  for (long long i = 0; i < np; ++i) b.add_node(i, Vec3(points[3 * i], points[3 * i + 1], points[3 * i + 2]), points_line);
  add_cells(path, b, offsets, connectivity, types, {}, line_at(find_array(cells, "connectivity").offset_debug()));
  return b.build();
}

TetMesh read_tet_mesh(const std::string& path) {
  const auto ends = [&](const char* ext) { return path.ends_with(ext); };
  if (ends(".msh")) return read_gmsh(path);
  if (ends(".vtk")) return read_legacy_vtk(path);
  if (ends(".vtu")) return read_vtu(path);
  throw InputError(path, 0, "extension", "unknown mesh format (expected .msh, .vtk or .vtu)");
}

}  // namespace viscera::tissue
