// Point distributions along grid lines against closed forms: Vinokur's and tanh laws, the geometric
// law, the flat-plate first cell, arc length and the turning measure.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

#include "core/common/errors.h"
#include "core/grid/distribution.h"

namespace bvmesh::grid {
namespace {

using Eigen::Vector3d;

TEST(GridDistribution, VinokurEndsAndMonotone) {
  const std::vector<double> x = vinokurFractions(41, 0.002, 0.002);
  ASSERT_EQ(x.size(), 41u);
  EXPECT_EQ(x.front(), 0.0);
  EXPECT_EQ(x.back(), 1.0);
  for (size_t i = 1; i < x.size(); ++i) EXPECT_GT(x[i], x[i - 1]);
  // Symmetric, with the end spacings asked.
  for (size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(x[i] + x[x.size() - 1 - i], 1.0, 1e-12);
  EXPECT_NEAR(x[1] / 0.002, 1.0, 1e-9);
  const std::vector<double> oneSided = vinokurFractions(30, 0.0, 0.01);
  EXPECT_NEAR((1.0 - oneSided[28]) / 0.01, 1.0, 1e-9);
  for (size_t i = 1; i < oneSided.size(); ++i) EXPECT_GT(oneSided[i], oneSided[i - 1]);
  const std::vector<double> uniform = vinokurFractions(5, 0.0, 0.0);
  EXPECT_DOUBLE_EQ(uniform[1], 0.25);
  EXPECT_THROW(vinokurFractions(5, 1.5, 0.0), InvalidInputError);
}

TEST(GridDistribution, TanhWallFirstSpacingIsExact) {
  const std::vector<double> x = tanhWallFractions(60, 1e-7);
  EXPECT_NEAR(x[1] / 1e-7, 1.0, 1e-9);
  for (size_t i = 1; i < x.size(); ++i) EXPECT_GT(x[i], x[i - 1]);
  EXPECT_EQ(x.back(), 1.0);
  EXPECT_THROW(tanhWallFractions(10, 0.5), InvalidInputError);
}

TEST(GridDistribution, GeometricLawClosedForms) {
  // Three points, first spacing 1, length 1 + r: r = length - 1.
  EXPECT_NEAR(geometricGrowth(3, 1.0, 2.44), 1.44, 1e-13);
  const double r = geometricGrowth(50, 1e-6, 1.0);
  const std::vector<double> d = geometricDistances(50, 1e-6, r, 1.0);
  EXPECT_DOUBLE_EQ(d[1], 1e-6);
  for (size_t k = 2; k < d.size(); ++k) EXPECT_NEAR((d[k] - d[k - 1]) / (d[k - 1] - d[k - 2]), r, 1e-9 * r);
  EXPECT_DOUBLE_EQ(d.back(), 1.0);
  // Points needed: 1e-6 (1.2^n - 1) / 0.2 >= 1 first at n = 67 intervals.
  EXPECT_EQ(geometricPointsNeeded(1e-6, 1.2, 1.0), 68);
  EXPECT_THROW(geometricGrowth(11, 0.1, 1.0), InvalidInputError);  // 10 spacings of 0.1 fill it already
}

TEST(GridDistribution, FlatPlateFirstCellHeight) {
  // White: Cf = 0.026 Re^(-1/7); at Re = 1e6, L = 1: Cf = 3.6127e-3, y(y+ = 1) = 2.3529e-5.
  EXPECT_NEAR(flatPlateFirstCellHeight(1.0, 1e6, 1.0), 2.3529e-5, 1e-9);
  EXPECT_NEAR(flatPlateYPlus(flatPlateFirstCellHeight(2.5, 3e6, 0.8), 3e6, 0.8), 2.5, 1e-12);
  EXPECT_THROW(flatPlateFirstCellHeight(1.0, 0.0, 1.0), InvalidInputError);
}

TEST(GridDistribution, ArcLengthOfAnUnevenlyParameterisedLine) {
  // A cubic B-spline with poles bunched on a straight line: arc length is distance along it.
  BsplineCurve line;
  line.degree = 3;
  line.knots = {0, 0, 0, 0, 0.1, 0.5, 1, 1, 1, 1};
  line.poles.resize(6, 3);
  const double at[6] = {0.0, 0.01, 0.05, 0.4, 2.0, 3.0};
  for (int p = 0; p < 6; ++p) line.poles.row(p) = (at[p] * Vector3d(1, 2, 2) / 3.0).transpose();
  const ArcLength arc(line, 8);
  EXPECT_NEAR(arc.length(), 3.0, 1e-12);
  // The Hermite inversion of t(s): to about 1e-5 of s even on this strongly uneven line.
  for (double s : {1e-7, 0.003, 0.5, 1.7, 2.9999})
    EXPECT_NEAR(line.point(arc.parameterAt(s)).norm() / s, 1.0, 1e-5);
  const double t = parameterAtDistance(line, 0.0, 1, 1e-6, 1e-3);
  EXPECT_NEAR(line.point(t).norm(), 1e-6, 1e-18);
}

// A planar cubic B-spline whose control polygon runs straight along x, bends left and leaves
// along y: a convex polygon gives a curve that turns one way only, so its tangent turns by
// exactly the angle between its end legs, 90 degrees, mostly in the bend near x = 3.5 .. 3.9.
BsplineCurve straightThenBent() {
  BsplineCurve curve;
  curve.knots = {0, 0, 0, 0, 0.2, 0.4, 0.6, 0.8, 1, 1, 1, 1};
  curve.poles.resize(8, 3);
  const double xy[8][2] = {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {3.5, 0.1}, {3.8, 0.5}, {3.9, 1.0}, {3.9, 2.0}};
  for (int p = 0; p < 8; ++p) curve.poles.row(p) = Vector3d(xy[p][0], xy[p][1], 0.0).transpose();
  return curve;
}

double tangentAngleDegrees(const BsplineCurve& curve, double t0, double t1) {
  Vector3d a, b;
  curve.point(t0, &a);
  curve.point(t1, &b);
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

TEST(GridDistribution, TurningMeasureGathersPointsInTheBend) {
  const BsplineCurve curve = straightThenBent();
  const ArcLength arc(curve, 8);
  const TurningTable table(curve, arc, 400);
  EXPECT_NEAR(table.turning(), M_PI / 2.0, 1e-12);
  EXPECT_NEAR(table.length(), arc.length(), 1e-15);
  const double limit = 10.0 * M_PI / 180.0;
  // No turning limit: the arc-length fractions exactly (grids refined without it keep their points
  // bit for bit), with or without end spacings.
  SharedMeasure plain(1000, 0.5, 0.0);
  plain.add(table, false);
  plain.add(table, true);
  EXPECT_TRUE(plain.uniformInArcLength());
  EXPECT_EQ(plain.fractions(11, 0.0, 0.0), vinokurFractions(11, 0.0, 0.0));
  EXPECT_EQ(plain.fractions(11, 0.01, 0.01), vinokurFractions(11, 0.01, 0.01));
  // One end clustered (the other's step 0, or no shorter than an equal step): the one-sided law.
  const std::vector<double> oneSided = plain.fractions(11, 0.0, 0.01);
  EXPECT_EQ(oneSided, vinokurFractions(11, 0.0, 0.01));
  EXPECT_EQ(plain.fractions(11, 0.2, 0.01), oneSided);
  EXPECT_NEAR(1.0 - oneSided[9], 0.01, 1e-12);
  EXPECT_GT(oneSided[1], 0.1);
  EXPECT_EQ(plain.at(0.3), 0.3);
  // Spacing 0.5 and 10 degrees: length / 0.5 + 9 cells; none longer than 0.5 in arc length, none
  // whose end tangents differ by more than 10 degrees (measured on the curve, not the table).
  const double cells = table.measure(0.5, limit);
  EXPECT_NEAR(cells, arc.length() / 0.5 + 9.0, 1e-9);
  const int points = static_cast<int>(std::ceil(cells)) + 1;
  SharedMeasure shared(1000, 0.5, limit);
  shared.add(table, false);
  EXPECT_FALSE(shared.uniformInArcLength());
  const std::vector<double> sigma = shared.fractions(points, 0.0, 0.0);
  int inBend = 0;
  for (size_t i = 1; i < sigma.size(); ++i) {
    EXPECT_GT(sigma[i], sigma[i - 1]);
    EXPECT_LE((sigma[i] - sigma[i - 1]) * arc.length(), 0.5 * (1.0 + 1e-6));
    const double t0 = arc.parameterAt(sigma[i - 1] * arc.length()),
                 t1 = arc.parameterAt(sigma[i] * arc.length());
    EXPECT_LE(tangentAngleDegrees(curve, t0, t1), 10.0 * 1.02);
    if (curve.point(t1).x() > 3.4 && curve.point(t1).y() < 1.2) ++inBend;
  }
  // Uniform points at that count put about 3 in the bend (its arc is about a quarter of the
  // curve's 5.3); the turning measure gives the bend its nine 10-degree steps.
  EXPECT_GE(inBend, 8);
  // End spacings of 0.02 asked at both ends, as steps of the measure: met to its tabulation.
  const double end = 0.02 / arc.length();
  const std::vector<double> ends = shared.fractions(points, shared.at(end), 1.0 - shared.at(1.0 - end));
  EXPECT_NEAR(ends[1] / end, 1.0, 1e-2);
  EXPECT_NEAR((1.0 - ends[ends.size() - 2]) / end, 1.0, 1e-2);
  // The same edge added against the shared sense gives the mirrored measure.
  SharedMeasure mirrored(1000, 0.5, limit);
  mirrored.add(table, true);
  for (const double x : {0.1, 0.5, 0.77, 0.95}) EXPECT_NEAR(mirrored.at(x), 1.0 - shared.at(1.0 - x), 1e-12);
}

}  // namespace
}  // namespace bvmesh::grid
