// Closest-point projection throughput on the ONERA M6 wing, against two OCCT baselines measured
// in the same run on the same points:
//   BRepExtrema_DistShapeShape (vertex to shape: FreeCAD's distToShape), and
//   GeomAPI_ProjectPointOnSurf on every face's surface (FreeCAD's Surface.projectPoint; trims
//   ignored, so it does less than the others).
// bvmesh is timed cold (spatial index) and warm (previous face and (u, v) per point, after the
// points moved by 0.1% of the model size, as between two fitting passes), on 1 and 2 threads.
//
//   bench_projection [points] [baseline points] [relative deflection] [file]
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRep_Tool.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Geom_Surface.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <tuple>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "core/cad/shape_io.h"
#include "core/target/target.h"

namespace {

using bvmesh::target::Points;
using bvmesh::target::ProjectionResult;
using bvmesh::target::Target;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// CPU time of the whole process (all threads): on a shared machine, wall-clock throughput
// depends on other load, points per CPU-second much less.
double cpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// Points near the surface (tessellation nodes moved by up to 1% of the model size), like the
// limit samples of a fitting pass.
Points nearSurface(const Target& target, int count, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<Eigen::Index> node(0, target.meshNodes().rows() - 1);
  Points points(count, 3);
  for (int i = 0; i < count; ++i)
    points.row(i) = target.meshNodes().row(node(generator)) +
                    0.01 * target.report().diagonal * Eigen::RowVector3d(unit(generator), unit(generator), unit(generator));
  return points;
}

}  // namespace

int main(int argc, char** argv) {
  const int count = argc > 1 ? std::atoi(argv[1]) : 200000;
  const int baselineCount = argc > 2 ? std::atoi(argv[2]) : 200;
  const double relativeDeflection = argc > 3 ? std::atof(argv[3]) : bvmesh::target::TargetOptions{}.relativeDeflection;
  const std::string file = argc > 4 ? argv[4] : std::string(BVMESH_DATA_DIR) + "/AileM6_with_sharp_TE.stp";
  const TopoDS_Shape shape = bvmesh::cad::readShapeFile(file);

  Clock::time_point start = Clock::now();
  bvmesh::target::TargetOptions options;
  options.relativeDeflection = relativeDeflection;
  const Target target(shape, options);
  const double buildSeconds = secondsSince(start);
  std::printf("file %s: %d faces, %d triangles (relative deflection %g), target built in %.3f s\n", file.c_str(),
              target.faceCount(), target.report().triangleCount, relativeDeflection, buildSeconds);

  // The baselines time the first baselineCount of these points, bvmesh the first count (which
  // may be fewer, or none).
  const Points sample = nearSurface(target, std::max(count, baselineCount), 1);
  const Points points = sample.topRows(count);

  // Baseline 1: BRepExtrema_DistShapeShape per point.
  start = Clock::now();
  double checksum = 0;
  for (int i = 0; i < baselineCount; ++i) {
    BRepExtrema_DistShapeShape distance(
        BRepBuilderAPI_MakeVertex(gp_Pnt(sample(i, 0), sample(i, 1), sample(i, 2))).Vertex(), shape);
    checksum += distance.Value();
  }
  const double extremaPerPoint = secondsSince(start) / baselineCount;

  // Baseline 2: GeomAPI_ProjectPointOnSurf on every face's surface.
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  std::vector<Handle(Geom_Surface)> surfaces;
  for (int f = 1; f <= faces.Extent(); ++f) surfaces.push_back(BRep_Tool::Surface(TopoDS::Face(faces(f))));
  start = Clock::now();
  for (int i = 0; i < baselineCount; ++i) {
    double best = 1e300;
    for (const Handle(Geom_Surface)& surface : surfaces) {
      GeomAPI_ProjectPointOnSurf projector(gp_Pnt(sample(i, 0), sample(i, 1), sample(i, 2)), surface);
      if (projector.NbPoints() > 0) best = std::min(best, projector.LowerDistance());
    }
    checksum += best;
  }
  const double projectPerPoint = secondsSince(start) / baselineCount;

  // bvmesh: the same points, cold and warm, 1 and 2 threads.
  std::printf("baselines (%d points): BRepExtrema %.3f ms/point, GeomAPI_ProjectPointOnSurf x %d faces %.3f ms/point\n",
              baselineCount, 1e3 * extremaPerPoint, target.faceCount(), 1e3 * projectPerPoint);
  const Points moved = points + 1e-3 * target.report().diagonal * nearSurface(target, count, 2).rowwise().normalized();
  std::printf("%-8s %-5s %12s %12s %14s %16s %14s\n", "threads", "start", "points/s", "us/point", "x BRepExtrema",
              "x ProjectPoint", "points/CPU-s");
  for (int threads : {1, 2}) {
    bvmesh::target::TargetOptions threaded = options;
    threaded.threads = threads;
    const Target timed(shape, threaded);
    const ProjectionResult previous = timed.project(points);  // also warms the per-thread caches
    start = Clock::now();
    double cpu = cpuSeconds();
    const ProjectionResult cold = timed.project(moved);
    const double coldSeconds = secondsSince(start);
    const double coldCpu = cpuSeconds() - cpu;
    const bvmesh::target::SurfaceHints hints{previous.faces, previous.params};
    start = Clock::now();
    cpu = cpuSeconds();
    const ProjectionResult warm = timed.project(moved, &hints);
    const double warmSeconds = secondsSince(start);
    const double warmCpu = cpuSeconds() - cpu;
    if (count == 0) {
      std::printf("%-8d no points: %ld cold and %ld warm results\n", threads, static_cast<long>(cold.distances.size()),
                  static_cast<long>(warm.distances.size()));
      continue;
    }
    double maxDifference = 0;
    for (int i = 0; i < count; ++i) maxDifference = std::max(maxDifference, std::abs(warm.distances[i] - cold.distances[i]));
    for (const auto& [name, seconds, cpuTime] :
         {std::tuple<const char*, double, double>{"cold", coldSeconds, coldCpu}, {"warm", warmSeconds, warmCpu}}) {
      const double perPoint = seconds / count;
      std::printf("%-8d %-5s %12.0f %12.2f %14.0f %16.0f %14.0f\n", threads, name, 1.0 / perPoint, 1e6 * perPoint,
                  extremaPerPoint / perPoint, projectPerPoint / perPoint, count / cpuTime);
    }
    std::printf("         max |warm - cold| distance: %.3g (model size %.4g)\n", maxDifference, target.report().diagonal);
  }
  std::printf("(checksum %.6g)\n", checksum);
  return 0;
}
