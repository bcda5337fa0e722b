// Mesh readers on the real organ meshes, in every supported format, and on malformed files.  // SPDX-License-Identifier: Apache-2.0
#include <filesystem>
#include <sstream>

#include <sys/stat.h>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/vtu_writer.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
using namespace viscera::common;
namespace test = viscera::tissue::test;

namespace {

// Two tetrahedra sharing the face (1,2,3): nodes and tets in 1-based file ids.
const char* kNodes[] = {"0 0 0", "1 0 0", "0 1 0", "0 0 1", "1 1 1"};

std::string gmsh_v2(const std::string& node3 = "0 0 1", const std::string& tet2 = "2 3 4 5", int node_count = 5) {
  std::string s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 \"liver\"\n$EndPhysicalNames\n";
  s += "$Nodes\n" + std::to_string(node_count) + "\n";
  for (int i = 0; i < 5; ++i) s += std::to_string(i + 1) + " " + (i == 3 ? node3 : kNodes[i]) + "\n";
  s += "$EndNodes\n$Elements\n3\n1 2 2 1 1 2 3 4\n2 4 2 1 1 1 2 3 4\n3 4 2 1 1 " + tet2 + "\n$EndElements\n";
  return s;
}

std::string expect_error(const std::string& path) {
  try {
    read_tet_mesh(path);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << path << ": no error";
  return "";
}

}  // namespace

TEST(MeshIo, ReadsTheBundledOrgansWithTheirDocumentedCounts) {
  struct Case {
    const char* file;
    std::size_t nodes, tets;
  } cases[] = {{"meshes/liver.msh", 181, 596},
               {"meshes/liver2.msh", 507, 1493},
               {"meshes/volumetricTongue0.vtu", 1405, 5051},
               {"meshes/heart_imstk-unity.vtk", 1051, 3421}};
  for (const auto& c : cases) {
    const TetMesh m = read_tet_mesh(test::data_path(c.file));
    EXPECT_EQ(m.node_count(), c.nodes) << c.file;
    EXPECT_EQ(m.tet_count(), c.tets) << c.file;
    EXPECT_GT(mesh_volume(m), 0.0) << c.file;
  }
}

TEST(MeshIo, GmshV1V2V4AndVtkFormatsGiveTheSameMesh) {
  const TetMesh v2 = read_tet_mesh(test::write_file("two.msh", gmsh_v2()));
  ASSERT_EQ(v2.tet_count(), 2u);
  // v4.1: one node block, one triangle block, one tet block.
  std::string v4 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n";
  v4 += "$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n";
  for (const char* n : kNodes) v4 += std::string(n) + "\n";
  v4 += "$EndNodes\n$Elements\n2 3 1 3\n2 1 2 1\n1 2 3 4\n3 1 4 2\n2 1 2 3 4\n3 2 3 4 5\n$EndElements\n";
  const TetMesh m4 = read_tet_mesh(test::write_file("two_v4.msh", v4));
  std::string v1 = "$NOD\n5\n";
  for (int i = 0; i < 5; ++i) v1 += std::to_string(10 * (i + 1)) + " " + kNodes[i] + "\n";
  v1 += "$ENDNOD\n$ELM\n2\n1 4 1 1 4 10 20 30 40\n2 4 1 1 4 20 30 40 50\n$ENDELM\n";
  const TetMesh m1 = read_tet_mesh(test::write_file("two_v1.msh", v1));
  std::string vtk = "# vtk DataFile Version 3.0\ntwo tets\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n";
  for (const char* n : kNodes) vtk += std::string(n) + "\n";
  vtk += "CELLS 3 13\n4 0 1 2 3\n4 1 2 3 4\n3 0 1 2\nCELL_TYPES 3\n10\n10\n5\n";
  const TetMesh mv = read_tet_mesh(test::write_file("two.vtk", vtk));
  for (const TetMesh* m : {&m4, &m1, &mv}) {
    ASSERT_EQ(m->tets, v2.tets) << m->source;
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(m->nodes[i], v2.nodes[i]) << m->source;
  }
}

// Physical groups of dimension 3 become element sets, the same in v1 (physical region), v2 (first
// tag) and v4.1 (the volume entity's physical tags in $Entities), named from $PhysicalNames (quoted,
// spaces kept); groups of other dimensions are not element sets.
TEST(MeshIo, GmshPhysicalGroupsBecomeTheSameElementSetsInEveryVersion) {
  const std::string names = "$PhysicalNames\n3\n2 9 \"capsule\"\n3 5 \"soft tissue\"\n3 7 \"nodule\"\n$EndPhysicalNames\n";
  // v1 and v2 give an element one physical group: tet 1 in 5, tet 2 in 7.
  std::string v1 = "$NOD\n5\n";
  for (int i = 0; i < 5; ++i) v1 += std::to_string(i + 1) + " " + kNodes[i] + "\n";
  v1 += "$ENDNOD\n$ELM\n3\n1 2 9 1 3 1 2 3\n2 4 5 1 4 1 2 3 4\n3 4 7 2 4 2 3 4 5\n$ENDELM\n";
  std::string v2 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n" + names + "$Nodes\n5\n";
  for (int i = 0; i < 5; ++i) v2 += std::to_string(i + 1) + " " + kNodes[i] + "\n";
  v2 += "$EndNodes\n$Elements\n3\n1 2 2 9 1 1 2 3\n2 4 2 5 1 1 2 3 4\n3 4 3 7 2 0 2 3 4 5\n$EndElements\n";
  // v4.1: volume entity 1 in group 5, volume entity 2 in groups 5 and 7, surface 3 in group 9.
  std::string v4 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n" + names + "$Entities\n1 0 1 2\n4 0 0 0 0\n";
  v4 += "3 0 0 0 1 1 0 1 9 0\n1 0 0 0 1 1 1 1 5 1 3\n2 0 0 0 1 1 1 2 7 -5 1 -3\n$EndEntities\n";
  v4 += "$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n";
  for (const char* n : kNodes) v4 += std::string(n) + "\n";
  v4 += "$EndNodes\n$Elements\n3 3 1 3\n2 3 2 1\n1 1 2 3\n3 1 4 1\n2 1 2 3 4\n3 2 4 1\n3 2 3 4 5\n$EndElements\n";
  const TetMesh m1 = read_tet_mesh(test::write_file("groups_v1.msh", v1)), m2 = read_tet_mesh(test::write_file("groups_v2.msh", v2)),
                m4 = read_tet_mesh(test::write_file("groups_v4.msh", v4));
  for (const TetMesh* m : {&m1, &m2}) {
    ASSERT_EQ(m->element_sets.size(), 2u) << m->source;
    EXPECT_EQ(m->element_sets[0].tag, 5);
    EXPECT_EQ(m->element_sets[0].tets, std::vector<std::int32_t>{0});
    EXPECT_EQ(m->element_sets[1].tag, 7);
    EXPECT_EQ(m->element_sets[1].tets, std::vector<std::int32_t>{1});
  }
  EXPECT_EQ(m1.element_sets[0].name, "");  // v1 has no names
  EXPECT_EQ(m2.element_sets[0].name, "soft tissue");
  EXPECT_EQ(m2.element_sets[1].name, "nodule");
  ASSERT_EQ(m4.element_sets.size(), 2u);
  EXPECT_EQ(m4.element_sets[0].name, "soft tissue");
  EXPECT_EQ(m4.element_sets[0].tets, (std::vector<std::int32_t>{0, 1}));
  EXPECT_EQ(m4.element_sets[1].name, "nodule");
  EXPECT_EQ(m4.element_sets[1].tets, std::vector<std::int32_t>{1});
  EXPECT_EQ(find_element_set(m4, "nodule"), &m4.element_sets[1]);
  EXPECT_EQ(find_element_set(m4, "5"), &m4.element_sets[0]);
  EXPECT_EQ(find_element_set(m4, "capsule"), nullptr);  // a surface group
  EXPECT_EQ(find_element_set(m4, "9"), nullptr);
  // Malformed groups name the field.
  std::string unquoted = v2;
  unquoted.replace(unquoted.find("\"nodule\""), 8, "nodule");
  EXPECT_NE(expect_error(test::write_file("unquoted.msh", unquoted)).find("physical name: 'nodule' is not a quoted name"), std::string::npos);
  std::string short_entities = v4;
  short_entities.replace(short_entities.find("1 5 1 3\n"), 8, "1 5 1\n");
  EXPECT_NE(expect_error(test::write_file("entities.msh", short_entities)).find("entity"), std::string::npos);
  std::string negative = v2;
  negative.replace(negative.find("3 4 3 7 2 0"), 11, "3 4 3 -7 2 0");
  EXPECT_NE(expect_error(test::write_file("negative.msh", negative)).find("element 3 physical tag: -7 is outside [0, "), std::string::npos);
}

TEST(MeshIo, VtuRoundTripKeepsTheMeshAndCarriesFields) {
  const auto liver = test::liver2();
  std::vector<Vec3> x = liver->nodes, v(liver->nodes.size(), Vec3(0.1, 0, 0));
  for (auto& p : x) p.z() *= 1.01;  // 1% stretch along z
  const std::string path = test::tmp_path("liver2_frame.vtu");
  write_vtu(path, *liver, x, v);
  const TetMesh back = read_tet_mesh(path);  // the deformed positions
  ASSERT_EQ(back.tets, liver->tets);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_LT((back.nodes[i] - x[i]).norm(), 1e-9);
  // Green strain of a 1% stretch: E_zz = (1.01^2 - 1) / 2 on every cell.
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::size_t at = text.find("Name=\"green_strain\"");
  ASSERT_NE(at, std::string::npos);
  std::istringstream values(text.substr(text.find('>', at) + 1));
  double E[6];
  for (double& e : E) values >> e;
  EXPECT_NEAR(E[2], (1.01 * 1.01 - 1.0) / 2.0, 1e-9);
  for (int k : {0, 1, 3, 4, 5}) EXPECT_NEAR(E[k], 0.0, 1e-9);
}

TEST(MeshIo, MalformedFilesGiveOneClearErrorNamingFileAndField) {
  struct Case {
    std::string name, text, expect;
  };
  std::string truncated = gmsh_v2();
  truncated.resize(truncated.find("$Elements") + 14);
  const std::vector<Case> cases = {
      {"nan.msh", gmsh_v2("0 nan 1"), "node y: 'nan' is not a finite number"},
      {"garbage.msh", gmsh_v2("0 x1 1"), "node y: 'x1' is not a number"},
      // Element errors name the element by its number in the file and its line (element 3 is on line 20).
      {"range.msh", gmsh_v2("0 0 1", "2 3 4 9"), ":20: element 3: references node 9, which does not exist"},
      {"truncated.msh", truncated, "unexpected end of file"},
      {"count.msh", gmsh_v2("0 0 1", "2 3 4 5", 4), "expected '$EndNodes', found '5'"},
      {"inverted.msh", gmsh_v2("0 0 1", "2 4 3 5"), ":20: element 3: is inverted"},
      {"flat.msh", gmsh_v2("1 1 0"), "is degenerate"},
      {"dup.msh", gmsh_v2("0 0 1", "1 2 4 3"), ":20: element 3: duplicates element 2"},
      {"repeat.msh", gmsh_v2("0 0 1", "2 3 3 5"), ":20: element 3: repeats a vertex"},
      // Bytes from the file are never printed raw: a control character shows as \xNN.
      {"control.msh", gmsh_v2("0 \x01\x1b[2J 1"), "node y: '\\x01\\x1B[2J' is not a number"},
      {"nul.msh", std::string("$MeshFormat\n2.2 0 8\n\0\0\x7f", 23), ":3: holds binary data (a NUL byte at byte 20)"},
      {"unused.msh",
       [] {
         std::string s = gmsh_v2("0 0 1", "1 2 3 4", 5);
         return s;
       }(),
       ""},
      {"tet10.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1\n1 11 0 1 1 1 1 1 1 1 1 1 1\n$EndElements\n",
       "element 1 type: 11 is a volume element other than the linear tetrahedron"},
      {"binary.msh", "$MeshFormat\n2.2 1 8\n$EndMeshFormat\n", "binary .msh files are not supported"},
      // 100 bytes that claim 10^9 nodes: read as far as the file goes (it took 10.6 GB when the
      // reader allocated what the header claimed).
      {"claims.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1000000000 1 1000000000\n3 1 0 1000000000\n", "unexpected end of file"},
      {"bad.vtk", "# vtk DataFile Version 3.0\nx\nBINARY\n", "encoding: 'BINARY' is not supported"},
      {"hex.vtk",
       "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 float\n0 0 0\nCELLS 1 9\n8 0 0 0 0 0 0 0 0\nCELL_TYPES 1\n12\n",
       "cell 0 type: 12 is a volume cell"},
      {"bad.vtu",
       "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"4\" NumberOfCells=\"1\"><Points><DataArray "
       "format=\"binary\">AAAA</DataArray></Points></Piece></UnstructuredGrid></VTKFile>",
       "DataArray Points: format 'binary' is not supported"},
      {"broken.vtu", "<VTKFile type=\"UnstructuredGrid\"><Unstruct", "XML:"},
      {"mesh.obj", "v 0 0 0\n", "unknown mesh format"},
  };
  for (const auto& c : cases) {
    if (c.name == "unused.msh") continue;  // covered below with a real unreferenced node
    const std::string path = test::write_file(c.name, c.text);
    const std::string msg = expect_error(path);
    EXPECT_NE(msg.find(path), std::string::npos) << c.name << ": " << msg;
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.name << ": " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  }
  // Node 5 is used only when the second tet is there: drop that tet to leave it unreferenced.
  std::string unused = gmsh_v2();
  unused.replace(unused.find("$Elements\n3"), 11, "$Elements\n2");
  unused.erase(unused.find("3 4 2 1 1 2 3 4 5\n"), 18);
  const std::string msg = expect_error(test::write_file("unused.msh", unused));
  EXPECT_NE(msg.find(":14: node 5: is used by no tetrahedron"), std::string::npos) << msg;
  EXPECT_NE(expect_error(test::tmp_path("does_not_exist.msh")).find("cannot open file"), std::string::npos);
  // Only regular files are read: a FIFO would block the reader forever, a directory is no mesh.
  const std::string fifo = test::tmp_path("fifo.msh");
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(expect_error(fifo).find("fifo.msh: is not a regular file"), std::string::npos);
  std::filesystem::create_directories(test::tmp_path("folder.vtu"));
  EXPECT_NE(expect_error(test::tmp_path("folder.vtu")).find("folder.vtu: is a directory"), std::string::npos);
}

TEST(MeshIo, EveryKindOfWhitespaceSeparatesTokens) {
  // A form feed or vertical tab between tokens (found by the readers' fuzzer: before, one part of
  // the tokenizer skipped it and the other did not, and skipping an unknown section never ended).
  std::string text = gmsh_v2();
  text.replace(text.find("$PhysicalNames"), 0, "$Comments\n\f\vnote\f$EndComments\n");
  text.replace(text.find("1 0 0"), 1, "1\f");
  const TetMesh m = read_tet_mesh(test::write_file("whitespace.msh", text));
  EXPECT_EQ(m.tet_count(), 2u);
}
