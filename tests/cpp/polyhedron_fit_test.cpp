// The templates placed automatically on the test geometries and fitted by SurfaceFitter without
// a manual step. Independent truths: the CAD vertices and planes of the STEP files (read off the
// files with FreeCAD), and the fitter's own sample-to-target distances.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "core/cad/shape_io.h"
#include "core/fit/surface_fitter.h"
#include "core/mesh/mesh_io.h"
#include "core/polyhedron/placement.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron {
namespace {

const std::string kData = BVMESH_TEST_DATA_DIR;
const std::string kTemplates = std::string(BVMESH_TEST_DATA_DIR) + "/../../resources/templates";
const std::string kOutput = BVMESH_TEST_OUTPUT_DIR;

PolyhedronTemplate libraryTemplate(const std::string& name) {
  return readTemplate(kTemplates + "/" + name + ".template");
}

// Runs the fitter, writes its history as a Markdown table and returns the final max distance.
fit::FitSummary runAndRecord(fit::SurfaceFitter& fitter, const std::string& name) {
  const fit::FitSummary summary = fitter.run();
  std::FILE* out = std::fopen((kOutput + "/" + name + "_fit.md").c_str(), "w");
  std::fprintf(
      out, "| level | pass | control points | max distance | RMS | seconds |\n|---|---|---|---|---|---|\n");
  for (const fit::PassRecord& r : summary.history) {
    std::fprintf(out, "| %d | %d | %d | %.3e | %.3e | %.1f |\n", r.level, r.correction, r.controlPoints,
                 r.maxDistance, r.rmsDistance, r.seconds);
    std::printf("%s level %d pass %d: %d control points, max %.3e, RMS %.3e (%.1f s)\n", name.c_str(),
                r.level, r.correction, r.controlPoints, r.maxDistance, r.rmsDistance, r.seconds);
  }
  std::fclose(out);
  return summary;
}

// Largest sample distance of the fitter's current state at least `away` from `point`, and where.
std::pair<double, Eigen::Vector3d> maxDistanceAwayFrom(fit::SurfaceFitter& fitter,
                                                       const Eigen::Vector3d& point, double away) {
  const RowMatrixX3d positions = fitter.limitPositions();
  const target::ProjectionResult& feet = fitter.project();
  std::pair<double, Eigen::Vector3d> worst{0.0, Eigen::Vector3d::Zero()};
  for (Eigen::Index i = 0; i < positions.rows(); ++i) {
    if ((positions.row(i).transpose() - point).norm() < away) continue;
    const double d = (positions.row(i) - feet.points.row(i)).norm();
    if (d > worst.first) worst = {d, positions.row(i).transpose()};
  }
  return worst;
}

int chainOfKind(const FeatureMapping& mapping, FeatureCurveKind kind) {
  int found = -1;
  for (size_t c = 0; c < mapping.chains.size(); ++c) {
    if (mapping.chains[c].kind == kind) {
      EXPECT_EQ(found, -1) << "more than one chain of this kind";
      found = static_cast<int>(c);
    }
  }
  return found;
}

TEST(PolyhedronFit, HalfWingPlacedAndFittedOnOneraM6) {
  const HalfModelShape half = removeSymmetryFace(cad::readShapeFile(kData + "/AileM6_with_sharp_TE.stp"));
  EXPECT_EQ(half.face, 8);  // FreeCAD's Face9: the root plane y = 0
  EXPECT_NEAR(half.plane.normal.y(), 1.0, 1e-12);
  auto target = std::make_shared<const target::Target>(half.shape);
  const PlacedPolyhedron placed = placeTemplate(libraryTemplate("half_wing"), *target);
  writeControlMesh(placed.mesh, kOutput + "/m6_half_wing_placed.cmesh");
  ASSERT_TRUE(placed.mapping.complete()) << placed.mapping.describeUnmapped();
  ASSERT_TRUE(placed.symmetryPlane.has_value());
  EXPECT_NEAR(std::abs(placed.symmetryPlane->normal.normalized().y()), 1.0, 1e-9);
  EXPECT_NEAR(placed.symmetryPlane->point.y(), 0.0, 1e-6);

  // The trailing-edge crease maps to the CAD trailing edge: the sharp edge chain from the root
  // trailing edge (810.49, 0, 0) to the tip trailing edge (1146.57, 1196.3, 0).
  const Eigen::Vector3d rootTE(810.491484116107, 0.0, 0.0), tipTE(1146.57039061706, 1196.29999192224, 0.0);
  const int crease = chainOfKind(placed.mapping, FeatureCurveKind::Sharp);
  ASSERT_GE(crease, 0);
  const ChainMapping& te = placed.mapping.chainMappings[static_cast<size_t>(crease)];
  ASSERT_GE(te.curve, 0);
  const FeatureCurve& teCurve = placed.curves[static_cast<size_t>(te.curve)];
  const Eigen::Vector3d a = target->vertexPosition(teCurve.startVertex),
                        b = target->vertexPosition(teCurve.endVertex);
  EXPECT_LT(std::min((a - rootTE).norm() + (b - tipTE).norm(), (a - tipTE).norm() + (b - rootTE).norm()),
            1e-3);
  EXPECT_EQ(te.cadEdges, teCurve.edges);
  // The root boundary maps to the free boundary (the root section loop), all on y = 0.
  const int root = chainOfKind(placed.mapping, FeatureCurveKind::Boundary);
  ASSERT_GE(root, 0);
  EXPECT_GE(placed.mapping.chainMappings[static_cast<size_t>(root)].curve, 0);
  for (int v : placed.mapping.chains[static_cast<size_t>(root)].vertices)
    EXPECT_NEAR(placed.mesh.vertices()(v, 1), 0.0, 1e-9);
  // Both ends of the trailing-edge crease are corners on the CAD trailing-edge vertices.
  int corners = 0;
  for (const CornerMapping& corner : placed.mapping.corners) {
    ASSERT_GE(corner.cadVertex, 0);
    const Eigen::Vector3d p = target->vertexPosition(corner.cadVertex);
    EXPECT_LT(std::min((p - rootTE).norm(), (p - tipTE).norm()), 1e-3);
    ++corners;
  }
  EXPECT_EQ(corners, 2);

  fit::FitOptions options;
  options.tolerance = 8e-3;  // 1e-5 of the root chord
  options.maxLevel = 4;      // level 5 is no better at the tip (1.00 mm)
  options.symmetryPlane = placed.symmetryPlane;
  // Closest-point projection. In the thin trailing-edge wedge near the tip the closest points of
  // neighbouring samples flip between upper and lower surface and pinch the two sides together
  // (1.54 mm at level 4). rejectOpposingFeet (on by default) casts such samples along their limit
  // normal instead (0.93 mm); what remains is a fold of the limit surface at the tip cap's
  // trailing-edge corner (limit and target normals nearly perpendicular there).
  options.stagnationRatio = 1.0;  // every correction pass of every level (the coarse levels gain most)
  fit::SurfaceFitter fitter(target, placed.mesh, placed.mapping.map, options);
  const fit::FitSummary summary = runAndRecord(fitter, "m6_half_wing");
  writeControlMesh(fitter.mesh(), kOutput + "/m6_half_wing_fitted.cmesh");
  const double overall = summary.history.back().maxDistance;
  const auto [awayFromTip, where] = maxDistanceAwayFrom(fitter, tipTE, 60.0);
  std::printf(
      "M6: max distance %.3e mm overall, %.3e mm farther than 60 mm from the tip trailing edge, at (%.1f, "
      "%.1f, %.1f)\n",
      overall, awayFromTip, where.x(), where.y(), where.z());
  EXPECT_LT(overall, 1.05);
  EXPECT_LT(awayFromTip, 0.15);
  EXPECT_EQ(summary.history.back().failedProjections, 0);
  for (int edge : fitter.mesh().boundaryEdges()) {
    for (int end = 0; end < 2; ++end)
      EXPECT_NEAR(fitter.mesh().vertices()(fitter.mesh().edges()(edge, end), 1), 0.0, 1e-9);
  }
}

TEST(PolyhedronFit, HalfCapsulePlacedAndFittedOnHemisphereCylinder) {
  // The body of the domain: its cylinder (Face4) and nose sphere (Face5); the far-field sphere,
  // the symmetry plane y = 0 and the outlet plane x = 10 are left out, so the body is open on
  // y = 0 and at x = 10.
  const TopoDS_Shape domain = cad::readShapeFile(kData + "/hemisph-cyl.stp");
  auto target = std::make_shared<const target::Target>(selectFaces(domain, {3, 4}));
  const PlacedPolyhedron placed = placeTemplate(libraryTemplate("capsule"), *target);
  writeControlMesh(placed.mesh, kOutput + "/capsule_placed.cmesh");
  ASSERT_TRUE(placed.mapping.complete()) << placed.mapping.describeUnmapped();
  EXPECT_EQ(placed.parameters.at("half"), "yes");
  EXPECT_EQ(placed.parameters.at("nose"), "round");
  EXPECT_EQ(placed.parameters.at("tail"), "open");
  ASSERT_TRUE(placed.symmetryPlane.has_value());
  EXPECT_NEAR(std::abs(placed.symmetryPlane->normal.normalized().y()), 1.0, 1e-9);
  // Two boundary chains (symmetry plane, outlet) meeting at two corners on the CAD vertices
  // (10, 0, -0.5) and (10, 0, 0.5).
  EXPECT_EQ(placed.mapping.chains.size(), 2u);
  std::vector<double> cornerZ;
  for (const CornerMapping& corner : placed.mapping.corners) {
    ASSERT_GE(corner.cadVertex, 0);
    const Eigen::Vector3d p = target->vertexPosition(corner.cadVertex);
    EXPECT_NEAR(p.x(), 10.0, 1e-9);
    cornerZ.push_back(p.z());
  }
  std::sort(cornerZ.begin(), cornerZ.end());
  ASSERT_EQ(cornerZ.size(), 2u);
  EXPECT_NEAR(cornerZ[0], -0.5, 1e-9);
  EXPECT_NEAR(cornerZ[1], 0.5, 1e-9);

  fit::FitOptions options;
  options.tolerance = 1e-4;  // 1e-5 of the body length (10)
  options.maxLevel = 5;
  options.symmetryPlane = placed.symmetryPlane;
  fit::SurfaceFitter fitter(target, placed.mesh, placed.mapping.map, options);
  const fit::FitSummary summary = runAndRecord(fitter, "capsule");
  writeControlMesh(fitter.mesh(), kOutput + "/capsule_fitted.cmesh");
  EXPECT_EQ(summary.reason, fit::StopReason::Converged);
  EXPECT_LE(summary.history.back().maxDistance, 1e-4);
}

}  // namespace
}  // namespace bvmesh::polyhedron
