// B-spline basis functions of any degree on a full (clamped) knot vector, Greville abscissae, and
// Boehm knot insertion on poles stored as matrix rows. Shared by the surface charts and the volume
// blocks; the formulas are those of Piegl & Tiller, The NURBS Book (A2.1-A2.3, A5.1).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace bvmesh {

// The knot span s (t_s <= x < t_{s+1}, degree <= s < #poles) that holds x; x at or past the last
// knot falls into the last non-empty span, x before the first into the first.
int findKnotSpan(const std::vector<double>& knots, int degree, double x);

// The degree + 1 basis functions that are non-zero on `span` (those of poles span - degree ...
// span) at x, and, unless `derivatives` is null, their first derivatives. At the clamped ends the
// values are exactly 0 and 1, so a clamped face is reproduced bit for bit.
void basisFunctions(const std::vector<double>& knots, int degree, int span, double x, double* values,
                    double* derivatives = nullptr);

// Full knot vector 0 (degree + 1 times), 1, ..., spans - 1, spans (degree + 1 times).
std::vector<double> uniformClampedKnots(int degree, int spans);

// The Greville abscissae (t_{i+1} + ... + t_{i+degree}) / degree, one per pole.
std::vector<double> grevilleAbscissae(const std::vector<double>& knots, int degree);

// Inserts x once: the curve whose poles are the rows of `poles` (any number of columns, so a
// surface's pole grid can be refined one direction at a time) is unchanged, `knots` and `poles`
// gain one entry.
void insertKnot(std::vector<double>& knots, int degree, Eigen::MatrixXd& poles, double x);

// The piece [a, b] of a clamped curve (knots of `knots` in between kept): knots and pole rows of
// the same curve restricted to [a, b] and clamped there. a and b must be knots of `knots`.
void restrictToInterval(std::vector<double>& knots, int degree, Eigen::MatrixXd& poles, double a, double b);

}  // namespace bvmesh
