// Sewing on reading: IGES written face by face (no topology) from the STEP test files, two
// patches with a deliberate gap, and IGES 128 surfaces that OCCT's default transfer skips.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRep_Builder.hxx>
#include <Geom_Plane.hxx>
#include <IGESControl_Reader.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Pln.hxx>
#include <gp_Trsf.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/cad/isolated_reader.h"
#include "core/cad/shape_io.h"
#include "core/cad/shape_repair.h"
#include "core/cad/shape_summary.h"
#include "core/common/errors.h"

namespace bvmesh::cad {
namespace {

const std::string kDataDir = BVMESH_TEST_DATA_DIR;
const std::string kOutputDir = BVMESH_TEST_OUTPUT_DIR;
const std::string kWing = kDataDir + "/AileM6_with_sharp_TE.stp";
const std::string kCapsule = kDataDir + "/hemisph-cyl.stp";

std::vector<int> kindCounts(const ShapeSummary& summary) {
  std::vector<int> counts;
  for (EdgeKind kind : {EdgeKind::Smooth, EdgeKind::Sharp, EdgeKind::Free, EdgeKind::Seam, EdgeKind::NonManifold,
                        EdgeKind::Degenerate})
    counts.push_back(summary.countEdges(kind));
  return counts;
}

std::vector<double> sortedLengths(const ShapeSummary& summary, EdgeKind kind) {
  std::vector<double> lengths;
  for (const EdgeInfo& edge : summary.edges)
    if (edge.kind == kind) lengths.push_back(edge.length);
  std::sort(lengths.begin(), lengths.end());
  return lengths;
}

// The STEP file written face by face to IGES, read back sewn and unsewn: the sewn edges must
// have the STEP's kinds (same counts, same sharp edges by length).
void expectSewnIgesMatchesStep(const std::string& step, const std::string& name) {
  const RepairedShape fromStep = readShapeFileRepaired(step);
  EXPECT_FALSE(fromStep.report.sewingAttempted) << "the STEP file's faces already share their edges";
  EXPECT_TRUE(fromStep.report.watertight());
  const std::string iges = kOutputDir + "/" + name + "_faces.igs";
  writeIgesFaces(fromStep.shape, iges);

  const RepairedShape unsewn = readShapeFileRepaired(iges, RepairOptions{false, 0.0});
  const ShapeSummary loose = summarizeShape(unsewn.shape);
  EXPECT_EQ(loose.countEdges(EdgeKind::Sharp), 0) << "as written, no edge is shared: every one is free";
  EXPECT_GT(loose.countEdges(EdgeKind::Free), 0);
  EXPECT_FALSE(unsewn.report.watertight());

  const RepairedShape sewn = readShapeFileRepaired(iges);
  const ShapeSummary expected = summarizeShape(fromStep.shape);
  const ShapeSummary actual = summarizeShape(sewn.shape);
  EXPECT_TRUE(sewn.report.sewingApplied) << sewn.report.keptReason;
  EXPECT_TRUE(sewn.report.watertight());
  EXPECT_TRUE(sewn.report.madeSolid);
  EXPECT_EQ(actual.solidCount, 1);
  EXPECT_EQ(actual.faceCount(), expected.faceCount());
  EXPECT_EQ(kindCounts(actual), kindCounts(expected));
  const std::vector<double> sharpExpected = sortedLengths(expected, EdgeKind::Sharp);
  const std::vector<double> sharpActual = sortedLengths(actual, EdgeKind::Sharp);
  ASSERT_EQ(sharpActual.size(), sharpExpected.size());
  for (std::size_t i = 0; i < sharpActual.size(); ++i)
    EXPECT_NEAR(sharpActual[i], sharpExpected[i], 1e-4 * sharpExpected[i] + 1e-6) << "sharp edge " << i;
  EXPECT_EQ(sewn.report.gapsClosed, actual.countEdges(EdgeKind::Smooth) + actual.countEdges(EdgeKind::Sharp));
  EXPECT_LE(sewn.report.largestGapClosed, sewn.report.tolerance);
  EXPECT_TRUE(sewn.report.openGaps.empty());
  EXPECT_TRUE(sewn.report.overlaps.empty());
  EXPECT_TRUE(fromStep.report.overlaps.empty());
  EXPECT_EQ(describeRepair(sewn.report).front(), "watertight: yes (every edge is shared by exactly two faces)");
}

TEST(CadRepair, SewnM6IgesHasTheEdgeKindsOfTheStep) { expectSewnIgesMatchesStep(kWing, "m6"); }

TEST(CadRepair, SewnHemisphereCylinderIgesHasTheEdgeKindsOfTheStep) {
  expectSewnIgesMatchesStep(kCapsule, "hemisphere_cylinder");
}

// Two unit squares side by side in z = 0, the second moved by `gap` along x, written to IGES.
std::string twoPatches(double gap, const std::string& name) {
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  const Handle(Geom_Plane) plane = new Geom_Plane(gp_Pln());
  builder.Add(compound, BRepBuilderAPI_MakeFace(plane, 0.0, 1.0, 0.0, 1.0, 1e-7).Face());
  builder.Add(compound, BRepBuilderAPI_MakeFace(plane, 1.0 + gap, 2.0 + gap, 0.0, 1.0, 1e-7).Face());
  const std::string path = kOutputDir + "/" + name + ".igs";
  writeIgesFaces(compound, path);
  return path;
}

const double kPatchesSize = std::sqrt(5.0);  // the diagonal of the two squares

TEST(CadRepair, SmallGapIsClosedAndMeasured) {
  const double gap = 1e-4 * kPatchesSize;
  const RepairedShape read = readShapeFileRepaired(twoPatches(gap, "gap_1e-4"));
  EXPECT_TRUE(read.report.sewingApplied) << read.report.keptReason;
  EXPECT_EQ(read.report.gapsClosed, 1);
  EXPECT_NEAR(read.report.largestGapClosed, gap, 0.05 * gap);
  EXPECT_TRUE(read.report.openGaps.empty());
  EXPECT_EQ(read.report.freeEdges, 6);  // the outline of the 2 x 1 rectangle
  EXPECT_EQ(read.report.closedFreeLoops, 1);
  EXPECT_FALSE(read.report.watertight());
  EXPECT_EQ(summarizeShape(read.shape).countEdges(EdgeKind::Smooth), 1);
}

TEST(CadRepair, WideGapIsLeftOpenAndNamed) {
  const double gap = 1e-2 * kPatchesSize;
  const RepairedShape read = readShapeFileRepaired(twoPatches(gap, "gap_1e-2"));
  EXPECT_TRUE(read.report.sewingAttempted);
  EXPECT_FALSE(read.report.sewingApplied);
  EXPECT_FALSE(read.report.keptReason.empty());
  EXPECT_LT(read.report.tolerance, gap);
  ASSERT_EQ(read.report.openGaps.size(), 1u);
  const OpenGap& open = read.report.openGaps[0];
  EXPECT_NEAR(open.width, gap, 1e-3 * gap);
  EXPECT_NE(open.face, open.otherFace);
  // Where: on the facing edges, x = 1 or 1 + gap, halfway along y.
  EXPECT_NEAR(open.where[0], 1.0 + 0.5 * gap, 0.6 * gap);
  EXPECT_NEAR(open.where[1], 0.5, 0.1);
  const std::vector<std::string> lines = describeRepair(read.report);
  EXPECT_EQ(lines.front().rfind("watertight: no (8 free edges", 0), 0u) << lines.front();
  const bool named = std::any_of(lines.begin(), lines.end(), [](const std::string& line) {
    return line.find("gaps left open: 1") != std::string::npos;
  });
  EXPECT_TRUE(named);
  // The report survives the trip from the reader process: same gap.
  const RepairReport again = decodeRepairReport(encodeRepairReport(read.report));
  ASSERT_EQ(again.openGaps.size(), 1u);
  EXPECT_DOUBLE_EQ(again.openGaps[0].width, open.width);
  EXPECT_EQ(again.keptReason, read.report.keptReason);

  // A tolerance given by the caller closes it.
  const RepairedShape forced = readShapeFileRepaired(kOutputDir + "/gap_1e-2.igs", RepairOptions{true, 2.0 * gap});
  EXPECT_TRUE(forced.report.sewingApplied) << forced.report.keptReason;
  EXPECT_EQ(forced.report.gapsClosed, 1);
  EXPECT_NEAR(forced.report.largestGapClosed, gap, 0.05 * gap);
  EXPECT_TRUE(forced.report.openGaps.empty());
}

// Faces that cover the same region: two unit squares overlapping by half, and the M6 with its
// root face written twice. Sewing cannot join them (it never gives an edge a third face); the
// report names the pair and the area, and it survives the trip from the reader process.
TEST(CadRepair, OverlappingFacesAreNamedWithTheirArea) {
  const RepairedShape squares = readShapeFileRepaired(twoPatches(-0.5, "overlap_half"));
  ASSERT_EQ(squares.report.overlaps.size(), 1u);
  const FaceOverlap& half = squares.report.overlaps[0];
  EXPECT_NE(half.face, half.otherFace);
  EXPECT_NEAR(half.area, 0.5, 0.01);
  EXPECT_NEAR(half.where[0], 0.75, 0.01);
  EXPECT_NEAR(half.where[1], 0.5, 0.01);
  const std::vector<std::string> lines = describeRepair(squares.report);
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(), [](const std::string& line) {
    return line.rfind("overlapping faces: 1 pairs", 0) == 0;
  }));
  const RepairReport again = decodeRepairReport(encodeRepairReport(squares.report));
  ASSERT_EQ(again.overlaps.size(), 1u);
  EXPECT_DOUBLE_EQ(again.overlaps[0].area, half.area);

  const TopoDS_Shape wing = readShapeFile(kWing);
  BRep_Builder builder;
  TopoDS_Compound twice;
  builder.MakeCompound(twice);
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(wing, TopAbs_FACE, faces);
  for (int i = 1; i <= faces.Extent(); ++i) builder.Add(twice, faces(i));
  builder.Add(twice, faces(9));  // the root plane y = 0 (FreeCAD's Face9)
  writeIgesFaces(twice, kOutputDir + "/m6_root_twice.igs");
  const RepairedShape read = readShapeFileRepaired(kOutputDir + "/m6_root_twice.igs");
  ASSERT_EQ(read.report.overlaps.size(), 1u);
  const FaceOverlap& root = read.report.overlaps[0];
  GProp_GProps properties;
  BRepGProp::SurfaceProperties(faces(9), properties);
  const double rootArea = properties.Mass();          // 44474 mm2
  EXPECT_NEAR(root.area, rootArea, 0.03 * rootArea);  // measured 43838
  EXPECT_NEAR(root.where[1], 0.0, 1e-6);
}

TEST(CadRepair, BadToleranceIsRejected) {
  const TopoDS_Shape shape = readShapeFile(kCapsule);
  EXPECT_THROW(repairShape(shape, RepairOptions{true, -1.0}), InvalidInputError);
  EXPECT_THROW(repairShape(shape, RepairOptions{true, std::nan("")}), InvalidInputError);
  EXPECT_THROW(repairShape(TopoDS_Shape()), InvalidInputError);
  EXPECT_THROW(readShapeFileIsolated(kCapsule, ReaderLimits{}, RepairOptions{true, -1.0}), InvalidInputError);
}

// A minimal IGES writer: entities as (type, form, parameter text), every status 00000000.
struct IgesEntity {
  int type;
  int form;
  std::string parameters;  // without the type number and the final ';'
};

std::string igesText(const std::vector<IgesEntity>& entities) {
  auto card = [](const std::string& text, char section, int number) {
    char tail[16];
    std::snprintf(tail, sizeof(tail), "%c%07d", section, number);
    std::string line = text;
    line.resize(72, ' ');
    return line + tail + "\n";
  };
  const std::string global =
      "1H,,1H;,4Htest,8Htest.igs,4Htest,4Htest,32,308,15,308,15,4Htest,1.,2,2HMM,1,1.,15H20260101.000000,1E-07,"
      "10.,,,11,0,15H20260101.000000;";
  std::string g, d, p;
  int gLines = 0, pLines = 0;
  for (size_t i = 0; i < global.size(); i += 72) g += card(global.substr(i, 72), 'G', ++gLines);
  for (std::size_t k = 0; k < entities.size(); ++k) {
    const int de = 2 * static_cast<int>(k) + 1;
    std::string text = std::to_string(entities[k].type) + "," + entities[k].parameters + ";";
    const int start = pLines + 1;
    int count = 0;
    for (size_t i = 0; i < text.size(); i += 64) {
      char pointer[16];
      std::snprintf(pointer, sizeof(pointer), "%8d", de);
      std::string chunk = text.substr(i, 64);
      chunk.resize(64, ' ');
      p += card(chunk + pointer, 'P', ++pLines);
      ++count;
    }
    char line[96];
    std::snprintf(line, sizeof(line), "%8d%8d%8d%8d%8d%8d%8d%8d%8s", entities[k].type, start, 0, 0, 0, 0, 0, 0,
                  "00000000");
    d += card(line, 'D', de);
    std::snprintf(line, sizeof(line), "%8d%8d%8d%8d%8d%8s%8s%8s%8d", entities[k].type, 0, 0, count,
                  entities[k].form, "", "", "", 0);
    d += card(line, 'D', de + 1);
  }
  char terminate[80];
  std::snprintf(terminate, sizeof(terminate), "S%7dG%7dD%7dP%7d", 1, gLines, static_cast<int>(2 * entities.size()),
                pLines);
  return card("bvmesh test: untrimmed rational B-spline surfaces", 'S', 1) + g + d + p + card(terminate, 'T', 1);
}

// Entity 128, biquadratic, rational, 3 x 3 poles z(i, j) with the given weights (first index
// fastest, as IGES lists them).
std::string rationalPatch(double x0, double (*z)(int, int), const double (&weights)[3][3]) {
  std::ostringstream out;
  out.precision(17);
  out << "2,2,2,2,0,0,0,0,0,0.,0.,0.,1.,1.,1.,0.,0.,0.,1.,1.,1.";
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) out << "," << weights[i][j];
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) out << "," << x0 + i << "," << j << "," << z(i, j);
  out << ",0.,1.,0.,1.";
  return out.str();
}

double zLeft(int i, int j) { return 0.1 * (i - 1) * (j - 1); }
double zRight(int i, int j) { return 0.1 * (j - 1) * (1 - i); }  // meets zLeft along x = 2

TEST(CadRepair, IgesSurfacesHeldByASingleParentAssociativityAreRead) {
  // The same weights along x = 2 on both patches, so they meet exactly there.
  const double weights[3][3] = {{1.0, 0.8, 1.0}, {0.9, 0.7, 0.9}, {1.0, 0.8, 1.0}};
  const std::string path = kOutputDir + "/rational_128_single_parent.igs";
  std::ofstream(path) << igesText({{128, 0, rationalPatch(0.0, zLeft, weights)},
                                   {128, 0, rationalPatch(2.0, zRight, weights)},
                                   {402, 9, "1,1,1,3"}});  // single parent: patch 1 parent of patch 2
  {
    // The cause: both surfaces are referenced by the associativity, which OCCT does not
    // transfer, so the default transfer finds no root.
    IGESControl_Reader reader;
    ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
    EXPECT_EQ(reader.NbRootsForTransfer(), 0);
  }
  const RepairedShape read = readShapeFileRepaired(path);
  EXPECT_EQ(read.report.facesRead, 2);
  EXPECT_EQ(summarizeShape(read.shape).countFacesOfType("BSplineSurface"), 2);
  ASSERT_EQ(read.report.notes.size(), 1u);
  EXPECT_NE(read.report.notes[0].find("402 form 9"), std::string::npos) << read.report.notes[0];
  EXPECT_NE(read.report.notes[0].find("2 of 2 surface entities"), std::string::npos) << read.report.notes[0];
  // Written without topology, sewn on reading along x = 2.
  EXPECT_TRUE(read.report.sewingApplied) << read.report.keptReason;
  EXPECT_EQ(read.report.gapsClosed, 1);
  EXPECT_LT(read.report.largestGapClosed, 1e-6);

  // A file with no surface at all (two points in the same associativity) still names the problem.
  const std::string empty = kOutputDir + "/no_surface.igs";
  std::ofstream(empty) << igesText({{116, 0, "0.,0.,0."}, {116, 0, "1.,0.,0."}, {402, 9, "1,1,1,3"}});
  try {
    readShapeFileRepaired(empty);
    ADD_FAILURE() << "a file without surfaces must not read";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("no shape that can be transferred"), std::string::npos) << error.what();
  }
}

// A reader that dies after reading, while sewing (here: on purpose, SIGSEGV once it has said the
// read is done, unless sewing is off): the caller gets the faces as read and a note.
TEST(CadRepair, ReaderDyingWhileSewingGivesTheFacesAsRead) {
  const std::string real = cadReaderExecutable();
  const std::string script = kOutputDir + "/reader_dying_while_sewing.sh";
  std::ofstream(script) << "#!/bin/sh\n"
                        << "case \" $* \" in *\" --sew off \"*) exec \"" << real << "\" \"$@\";; esac\n"
                        << "echo 'bvmesh-cad-reader: read' >&2\n"
                        << "kill -SEGV $$\n";
  ASSERT_EQ(std::system(("chmod +x '" + script + "'").c_str()), 0);
  ASSERT_EQ(setenv("BVMESH_CAD_READER", script.c_str(), 1), 0);
  const RepairedShape read = readShapeFileRepaired(kCapsule);
  unsetenv("BVMESH_CAD_READER");
  EXPECT_EQ(summarizeShape(read.shape).faceCount(), 5);
  EXPECT_FALSE(read.report.sewingAttempted);
  ASSERT_FALSE(read.report.notes.empty());
  EXPECT_NE(read.report.notes.back().find("sewing failed in the reader process"), std::string::npos)
      << read.report.notes.back();
  EXPECT_NE(read.report.notes.back().find("crashed"), std::string::npos) << read.report.notes.back();
}

}  // namespace
}  // namespace bvmesh::cad
