// The half_wing template placed automatically on the ONERA M6 wing (root face removed) and fitted
// by SurfaceFitter, with chosen template resolution and depth: prints per pass the control points,
// max / RMS sample distance and time, then the five largest distances, where they are, the CAD
// face their foot lies on and the cosine between the limit normal and the target normal there.
//
//   build/bench/bench_m6_template_fit [chordwise] [spanwise] [max_level] [stagnation] [along] [reject]
//   (defaults: the template's resolution (also for "-"), 5 0.9 0 1; stagnation: FitOptions::stagnationRatio, along 1: projectAlongNormals,
//   reject 0: FitOptions::rejectOpposingFeet off, the plain closest points)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/cad/shape_io.h"
#include "core/fit/surface_fitter.h"
#include "core/polyhedron/placement.h"
#include "core/polyhedron/target_analysis.h"

int main(int argc, char** argv) {
  using namespace bvmesh;
  const auto templateParameter = [&](int i) { return argc > i && std::string(argv[i]) != "-" ? argv[i] : ""; };
  const std::string chordwise = templateParameter(1);
  const std::string spanwise = templateParameter(2);
  const int maxLevel = argc > 3 ? std::atoi(argv[3]) : 5;
  const double stagnation = argc > 4 ? std::atof(argv[4]) : 0.9;
  const bool along = argc > 5 && std::atoi(argv[5]) != 0;
  const bool reject = argc <= 6 || std::atoi(argv[6]) != 0;
  const auto start = std::chrono::steady_clock::now();
  const polyhedron::HalfModelShape half = polyhedron::removeSymmetryFace(
      cad::readShapeFile(std::string(BVMESH_DATA_DIR) + "/AileM6_with_sharp_TE.stp"));
  auto target = std::make_shared<const target::Target>(half.shape);
  polyhedron::PlacementOptions placement;
  if (!chordwise.empty()) placement.parameters["chordwise"] = chordwise;
  if (!spanwise.empty()) placement.parameters["spanwise"] = spanwise;
  const polyhedron::PlacedPolyhedron placed =
      polyhedron::placeTemplate(polyhedron::readTemplate(std::string(BVMESH_DATA_DIR) +
                                                         "/../../resources/templates/half_wing.template"),
                                *target, placement);
  std::printf("placed %d vertices, %d faces in %.2f s; unmapped: %s\n", placed.mesh.numVertices(),
              placed.mesh.numFaces(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              placed.mapping.complete() ? "none" : placed.mapping.describeUnmapped().c_str());
  fit::FitOptions options;
  options.tolerance = 8e-3;
  options.maxLevel = maxLevel;
  options.stagnationRatio = stagnation;
  options.projectAlongNormals = along;
  options.rejectOpposingFeet = reject;
  options.symmetryPlane = placed.symmetryPlane;
  fit::SurfaceFitter fitter(target, placed.mesh, placed.mapping.map, options);
  std::printf(
      "| level | pass | control points | max distance (mm) | RMS (mm) | seconds "
      "|\n|---|---|---|---|---|---|\n");
  fitter.run([](const fit::PassRecord& r) {
    std::printf("| %d | %d | %d | %.3e | %.3e | %.1f |\n", r.level, r.correction, r.controlPoints,
                r.maxDistance, r.rmsDistance, r.seconds);
    std::fflush(stdout);
  });
  const RowMatrixX3d positions = fitter.limitPositions();
  const RowMatrixX3d normals = fitter.computeLimitSamples().normals(fitter.mesh().vertices());
  const target::ProjectionResult& feet = fitter.project();
  std::vector<std::pair<double, Eigen::Index>> worst;
  for (Eigen::Index i = 0; i < positions.rows(); ++i)
    worst.emplace_back((positions.row(i) - feet.points.row(i)).norm(), i);
  std::partial_sort(worst.begin(), worst.begin() + 5, worst.end(), std::greater<>());
  for (int k = 0; k < 5; ++k) {
    const Eigen::Index i = worst[static_cast<size_t>(k)].second;
    std::printf("distance %.3e mm at (%.1f, %.1f, %.1f), face %d, normal cosine %.3f\n",
                worst[static_cast<size_t>(k)].first, positions(i, 0), positions(i, 1), positions(i, 2),
                feet.faces[i], normals.row(i).dot(feet.normals.row(i)));
  }
  return 0;
}
