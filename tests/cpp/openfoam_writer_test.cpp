// The OpenFOAM writer: mirrored and turned blocks, a box domain's outer faces patched quad by quad,
// upper-triangular face order checked on the files, checkMesh run on them, and an unwritable path.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "block_fixtures.h"
#include "core/common/errors.h"
#include "core/grid/hex_topology.h"
#include "core/grid/refinement.h"
#include "core/io/openfoam_writer.h"

namespace bvmesh::grid {
namespace {

using Eigen::Vector3d;

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::vector<long> readLabels(const std::filesystem::path& path) {
  const std::string text = readText(path);
  const size_t body = text.find('(', text.find("}"));
  std::istringstream numbers(text.substr(body + 1));
  std::vector<long> labels;
  long value;
  while (numbers >> value) labels.push_back(value);
  return labels;
}

std::string checkMesh(const std::filesystem::path& root) {
  const std::string command = "WM_PROJECT_DIR=/usr/share/openfoam checkMesh -allGeometry -allTopology -case '" +
                              root.string() + "' 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return "";
  std::string output;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
  pclose(pipe);
  return output;
}

bool haveCheckMesh() { return std::system("command -v checkMesh > /dev/null 2>&1") == 0; }

TEST(OpenFoamWriter, MirroredAndTurnedBlocksPassCheckMesh) {
  const test::BoxBlocks box = test::boxBlocks(0.08, false, 2);
  RefinementOptions options;
  options.edgePoints = 6;
  const RefinedGrid refined = refineBlockMesh(box.mesh, options);
  const HexTopology topology(refined.grid);
  EXPECT_TRUE(topology.mirrored(5));
  const std::filesystem::path root = std::filesystem::path(BVMESH_TEST_OUTPUT_DIR) / "grid_openfoam_turned";
  std::filesystem::remove_all(root);
  io::writeOpenFoamCase(topology, root.string());
  if (!haveCheckMesh()) GTEST_SKIP() << "checkMesh is not installed";
  const std::string output = checkMesh(root);
  EXPECT_NE(output.find("Mesh OK."), std::string::npos) << output;
  EXPECT_NE(output.find("cells:            1000"), std::string::npos) << output;
}

TEST(OpenFoamWriter, AFanRoundASharpEdgeIsPrismsThatPassCheckMesh) {
  RefinementOptions options;
  options.normalPoints = 9;
  options.tangentialSpacing = 0.25;
  const RefinedGrid refined = refineBlockMesh(test::fanWedgeBlocks(10.0 * M_PI / 180.0), options);
  const HexTopology topology(refined.grid);
  const std::filesystem::path root = std::filesystem::path(BVMESH_TEST_OUTPUT_DIR) / "grid_openfoam_fan";
  std::filesystem::remove_all(root);
  io::writeOpenFoamCase(topology, root.string());
  const GridBlock& fan = refined.grid.blocks()[2];
  const Eigen::Index prisms = static_cast<Eigen::Index>(fan.size[0] - 1) * (fan.size[1] - 1);
  const std::string faces = readText(root / "constant" / "polyMesh" / "faces");
  size_t triangles = 0;
  for (size_t at = faces.find("\n3("); at != std::string::npos; at = faces.find("\n3(", at + 1)) ++triangles;
  EXPECT_EQ(triangles, static_cast<size_t>(fan.size[0] * (fan.size[1] - 1)));  // the prisms' span faces
  if (!haveCheckMesh()) GTEST_SKIP() << "checkMesh is not installed";
  const std::string output = checkMesh(root);
  EXPECT_NE(output.find("Mesh OK."), std::string::npos) << output;
  EXPECT_NE(output.find("cells:            " + std::to_string(topology.cellCount())), std::string::npos) << output;
  EXPECT_TRUE(std::regex_search(output, std::regex("prisms: +" + std::to_string(prisms) + "\n"))) << output;
}

TEST(OpenFoamWriter, BoxDomainOuterFacesArePatchedQuadByQuad) {
  // The one-layer box in a box domain whose edges its top and bottom faces reach over. Each quad
  // goes to the patch its centre lies on (worked out by the fixture on its own); without the
  // domain the faces keep the part their middle lies on, which puts inlet and outlet quads into
  // the side patch.
  const volume::BlockMesh mesh = test::boxInBoxDomain();
  RefinementOptions options;
  options.edgePoints = 9;
  const RefinedGrid byMiddles = refineBlockMesh(mesh, options);
  EXPECT_EQ(byMiddles.outerFacesSplit, 0);
  options.outerDomain = test::boxDomain();
  const RefinedGrid refined = refineBlockMesh(mesh, options);
  std::map<volume::BoundaryCondition, Eigen::Index> expected;
  int split = 0;
  for (const GridBlock& block : refined.grid.blocks()) {
    for (int f = 0; f < 6; ++f) {
      if (block.faces[static_cast<size_t>(f)].condition == volume::BoundaryCondition::Connected) continue;
      const std::array<int, 2> counts = volume::faceGridCounts(block.size, f);
      bool mixed = false;
      for (int b = 0; b + 1 < counts[1]; ++b) {
        for (int a = 0; a + 1 < counts[0]; ++a) {
          Vector3d centre = Vector3d::Zero();
          for (const auto& [da, db] : {std::pair{0, 0}, {1, 0}, {0, 1}, {1, 1}}) {
            centre += 0.25 * block.points.row(block.facePoint(f, a + da, b + db)).transpose();
          }
          const volume::BoundaryCondition truth = test::boxDomainPart(centre);
          EXPECT_EQ(block.quadCondition(f, a, b), truth) << centre.transpose();
          mixed |= truth != block.faces[static_cast<size_t>(f)].condition;
          ++expected[truth];
        }
      }
      split += mixed;
    }
  }
  EXPECT_EQ(refined.outerFacesSplit, split);
  EXPECT_EQ(split, 8);  // the top and bottom faces of the four blocks
  const HexTopology topology(refined.grid);
  ASSERT_EQ(topology.patches().size(), 3u);
  for (const BoundaryPatch& patch : topology.patches()) EXPECT_EQ(patch.size, expected[patch.condition]) << patch.name;
  const HexTopology plain(byMiddles.grid);
  bool differs = false;
  for (const BoundaryPatch& patch : plain.patches()) differs |= patch.size != expected[patch.condition];
  EXPECT_TRUE(differs);
  const std::filesystem::path root = std::filesystem::path(BVMESH_TEST_OUTPUT_DIR) / "grid_openfoam_box_domain";
  std::filesystem::remove_all(root);
  io::writeOpenFoamCase(topology, root.string());
  const std::string boundary = readText(root / "constant" / "polyMesh" / "boundary");
  for (const auto& [condition, faces] : expected) {
    const std::string name = volume::boundaryConditionName(condition);
    const std::regex patch(name + "\\s*\\{[^}]*nFaces\\s+" + std::to_string(faces) + ";");
    EXPECT_TRUE(std::regex_search(boundary, patch)) << name << " " << faces << "\n" << boundary;
  }
  if (!haveCheckMesh()) GTEST_SKIP() << "checkMesh is not installed";
  const std::string output = checkMesh(root);
  EXPECT_NE(output.find("Mesh OK."), std::string::npos) << output;
}

TEST(OpenFoamWriter, BoxCaseIsUpperTriangularAndPassesCheckMesh) {
  const test::BoxBlocks box = test::boxBlocks(0.08, true, 1);
  RefinementOptions options;
  options.edgePoints = 6;
  options.normalPoints = 7;
  const RefinedGrid refined = refineBlockMesh(box.mesh, options);
  const HexTopology topology(refined.grid);
  // The box: 10 x 10 x 6 cells.
  EXPECT_EQ(topology.cellCount(), 10 * 10 * 6);
  EXPECT_EQ(topology.internalFaceCount(), 9 * 10 * 6 + 10 * 9 * 6 + 10 * 10 * 5);
  ASSERT_EQ(topology.patches().size(), 3u);
  EXPECT_EQ(topology.patches()[0].name, "wall");
  EXPECT_EQ(topology.patches()[0].size, 100);
  EXPECT_EQ(topology.patches()[1].name, "symmetry");
  EXPECT_EQ(topology.patches()[1].size, 60);
  const std::filesystem::path root = std::filesystem::path(BVMESH_TEST_OUTPUT_DIR) / "grid_openfoam_box";
  std::filesystem::remove_all(root);
  io::writeOpenFoamCase(topology, root.string());
  const std::vector<long> owner = readLabels(root / "constant/polyMesh/owner");
  const std::vector<long> neighbour = readLabels(root / "constant/polyMesh/neighbour");
  ASSERT_EQ(static_cast<Eigen::Index>(neighbour.size()), topology.internalFaceCount());
  for (size_t f = 0; f < neighbour.size(); ++f) {
    EXPECT_LT(owner[f], neighbour[f]);
    if (f > 0) {
      EXPECT_TRUE(owner[f - 1] < owner[f] || (owner[f - 1] == owner[f] && neighbour[f - 1] < neighbour[f]));
    }
  }
  EXPECT_FALSE(std::filesystem::exists(root / "constant/polyMesh/owner.partial"));
  if (!haveCheckMesh()) GTEST_SKIP() << "checkMesh is not installed";
  const std::string output = checkMesh(root);
  EXPECT_NE(output.find("Mesh OK."), std::string::npos) << output;
  EXPECT_NE(output.find("cells:            600"), std::string::npos) << output;
}

TEST(OpenFoamWriter, UnwritablePathIsNamed) {
  const test::BoxBlocks box = test::boxBlocks(0.0, true, 1);
  RefinementOptions options;
  options.edgePoints = 3;
  options.normalPoints = 3;
  const RefinedGrid refined = refineBlockMesh(box.mesh, options);
  const HexTopology topology(refined.grid);
  const std::filesystem::path blocker = std::filesystem::path(BVMESH_TEST_OUTPUT_DIR) / "grid_openfoam_blocker";
  std::ofstream(blocker.string()) << "a file, not a folder";
  try {
    io::writeOpenFoamCase(topology, (blocker / "case").string());
    FAIL();
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("grid_openfoam_blocker"), std::string::npos);
  }
}

}  // namespace
}  // namespace bvmesh::grid
