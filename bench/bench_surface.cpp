// Limit surface -> B-spline surfaces: time per stage against the number of quads (about 1k, 10k,
// 100k) and the growth exponent between sizes. Two families:
//   sphere: a cube with n x n quads per side projected to the unit sphere (6 large charts, 8
//           extraordinary vertices);
//   creased: an n x n bumpy grid with creases every 8th line (many 8 x 8 charts).
// Baseline in the same run: evaluating the limit surface at the fit's samples (16 per quad) alone.
// The limit evaluator is the shared one (core/subdiv), built from the ControlMesh.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <vector>

#include "core/surface/limit_bsplines.h"

namespace {

using namespace bvmesh::surface;

double seconds(const std::function<void()>& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

QuadControlMesh sphere(int n) {
  std::map<std::array<int, 3>, int> index;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 4>> quads;
  auto id = [&](const std::array<int, 3>& p) {
    auto [it, inserted] = index.emplace(p, static_cast<int>(points.size()));
    if (inserted) points.push_back(Eigen::Vector3d(p[0], p[1], p[2]).normalized());
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3;
    const int b = (axis + 2) % 3;
    for (int sign : {-1, 1}) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          std::array<int, 4> quad{};
          const int ci[4] = {i, i + 1, i + 1, i};
          const int cj[4] = {j, j, j + 1, j + 1};
          for (int k = 0; k < 4; ++k) {
            std::array<int, 3> p{};
            p[static_cast<size_t>(axis)] = sign * n;
            p[static_cast<size_t>(a)] = -n + 2 * ci[k];
            p[static_cast<size_t>(b)] = -n + 2 * cj[k];
            quad[static_cast<size_t>(sign > 0 ? k : 3 - k)] = id(p);
          }
          quads.push_back(quad);
        }
      }
    }
  }
  return makeQuadControlMesh(points, quads);
}

QuadControlMesh creasedGrid(int n) {
  auto id = [n](int i, int j) { return i * (n + 1) + j; };
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) points.emplace_back(i, j, 2.0 * std::sin(0.11 * i) * std::cos(0.07 * j));
  }
  std::vector<std::array<int, 4>> quads;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  std::vector<std::array<int, 2>> creases;
  for (int line = 8; line < n; line += 8) {
    for (int k = 0; k < n; ++k) {
      creases.push_back({id(line, k), id(line, k + 1)});
      creases.push_back({id(k, line), id(k + 1, line)});
    }
  }
  return makeQuadControlMesh(points, quads, creases);
}

struct Row {
  long faces = 0;
  size_t charts = 0;
  double layout = 0, limit = 0, fit = 0, sew = 0, baseline = 0, deviation = 0;
  double total() const { return layout + limit + fit + sew; }
};

Row run(const QuadControlMesh& mesh) {
  Row row;
  row.faces = mesh.faces.rows();
  ChartLayout layout;
  row.layout = seconds([&] { layout = buildChartLayout(mesh); });
  row.charts = layout.charts.size();
  std::unique_ptr<bvmesh::ControlMesh> controlMesh;
  std::unique_ptr<bvmesh::LimitEvaluator> limit;
  row.limit = seconds([&] {
    controlMesh = std::make_unique<bvmesh::ControlMesh>(toControlMesh(mesh));
    limit = std::make_unique<bvmesh::LimitEvaluator>(*controlMesh, bvmesh::SubdivisionOptions{}, 8);
  });
  const LimitPointsFunction points = limitPoints(*limit, controlMesh->vertices());
  std::vector<bvmesh::SurfaceLocation> samples;
  for (int f = 0; f < mesh.faces.rows(); ++f) {
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) samples.push_back({f, (a + 0.5) / 4, (b + 0.5) / 4});
    }
  }
  bvmesh::RowMatrixX3d evaluated;
  row.baseline = seconds([&] { points(samples, evaluated, nullptr); });
  LimitBSplines result;
  row.fit = seconds([&] { result = fitLimitBSplines(layout, points); });
  for (double d : result.maxDeviation) row.deviation = std::max(row.deviation, d);
  row.sew = seconds([&] { sewBSplineSurfaces(result.surfaces); });
  return row;
}

void family(const char* name, const std::function<QuadControlMesh(int)>& make,
            const std::vector<int>& sizes) {
  std::printf("\n%s\n%8s %7s %9s %9s %9s %9s %9s %10s %9s %10s\n", name, "quads", "charts", "layout s",
              "limit s", "fit s", "sew s", "total s", "fit/eval", "exponent", "max dev");
  Row previous;
  for (int n : sizes) {
    const Row row = run(make(n));
    char exponent[32] = "-";
    if (previous.faces > 0) {
      std::snprintf(exponent, sizeof exponent, "%.2f",
                    std::log(row.total() / previous.total()) /
                        std::log(static_cast<double>(row.faces) / static_cast<double>(previous.faces)));
    }
    std::printf("%8ld %7zu %9.3f %9.3f %9.3f %9.3f %9.3f %10.2f %9s %10.2e\n", row.faces, row.charts,
                row.layout, row.limit, row.fit, row.sew, row.total(), row.fit / row.baseline, exponent,
                row.deviation);
    std::fflush(stdout);
    previous = row;
  }
}

}  // namespace

int main() {
  std::printf("fit/eval: fit time over the time to evaluate the limit surface at 16 samples per quad\n");
  family("sphere (6 charts, 8 extraordinary vertices)", sphere, {13, 41, 129});
  family("creased grid (8 x 8 charts)", creasedGrid, {32, 100, 316});
  return 0;
}
