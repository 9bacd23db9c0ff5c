// Chan & Steger's hyperbolic marching of a quad surface grid, on an unstructured front: each step
// solves, at every point, the orthogonality of the marching direction to the front
// (r_xi . r_zeta = r_eta . r_zeta = 0) and a prescribed cell volume ((r_xi x r_eta) . r_zeta = V),
// linearised about the current front and coupled through the front's central differences, with
// implicit and explicit second-difference smoothing: one sparse linear solve per step. The volume
// term is what opens concave corners: the volumes are smoothed over the front, so a point whose
// surrounding area is small (the inside of a corner) takes a longer step than its neighbours.
// Derivatives at a point of any valence come from its ring of neighbours in counter-clockwise
// order (Fourier weights: r_xi = 2/M sum cos(2 pi m / M) (x_m - x), r_eta with sin), which at
// valence 4 are the central differences; a point on a boundary plane (the symmetry plane, an
// outflow plane) closes its ring with its neighbours mirrored (ghost points).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <array>
#include <memory>
#include <vector>

#include "core/common/types.h"
#include "core/volume/boundary_planes.h"

namespace bvmesh::volume {

struct HyperbolicOptions {
  double explicitSmoothing = 1.0;  // epsilon_E: second-difference dissipation of the current front
  double implicitSmoothing = 2.0;  // epsilon_I: second-difference smoothing of the step itself
  double implicitCoupling = 3.0;   // theta: extra weight of the implicit cross terms (Barth)
  double volumeSmoothing = 0.25;   // weight of the neighbours' volumes in each Jacobi pass
  int volumeSmoothingPasses = 20;
  double maxStepToEdge = 1.0;  // a pseudo-step is at most this times a short edge of the front
  int maxPseudoSteps = 64;     // per layer; beyond it the pseudo-steps are longer than asked
  // Relative residual to which each step's linear system is solved. Against 1e-6 the M6's far field
  // moves by at most 2.3e-4 of its distance from the centre; at 1e-3 (1.2e-3, a third less time)
  // a symmetric layout (the sphere's cube charts) is no longer symmetric to the 1e-6 at which a box
  // domain puts points on its edges.
  double solverTolerance = 1e-4;
};

class HyperbolicStepper {
 public:
  // quads: counter-clockwise seen from the side marched to. onPlanes (per point, may be empty):
  // the `planes` a point is kept on (bits). Throws InvalidInputError when a point's cells do not
  // form one fan around it (a non-manifold front), or its fan is open off the planes.
  HyperbolicStepper(Eigen::Index pointCount, const std::vector<std::array<int, 4>>& quads,
                    const std::vector<unsigned char>& onPlanes, const BoundaryPlanes& planes,
                    const HyperbolicOptions& options);
  ~HyperbolicStepper();

  // The front `points` advanced by `thickness` (the area-weighted mean of the points' steps), in
  // pseudo-steps no longer than maxStepToEdge times a short edge of the front (its 10th
  // percentile). `below`: the front one layer earlier (the grid-convergence sensor compares edge
  // lengths with it); `progress` in [0, 1]: the share of the far field marched, which raises the
  // explicit smoothing towards the outside. Throws SolverError for a degenerate front. Each solve
  // starts from the previous one's solution scaled to its step (successive steps differ little:
  // about half the iterations).
  RowMatrixX3d advance(const RowMatrixX3d& below, const RowMatrixX3d& points, double thickness,
                       double progress);

 private:
  struct RingEntry {
    int point;
    unsigned char mirror;    // a ghost: the point's mirror image in these planes (bits; 0: the point itself)
    double xiWeight = 0.0;   // 2/M cos(2 pi m / M): r_xi's weight of this neighbour
    double etaWeight = 0.0;  // 2/M sin(2 pi m / M)
  };

  RowMatrixX3d pseudoStep(const RowMatrixX3d& before, const RowMatrixX3d& points, double step,
                          double progress);
  Eigen::Vector3d ringPoint(const RowMatrixX3d& points, const RingEntry& entry) const;
  Eigen::VectorXd nodeAreas(const RowMatrixX3d& points) const;
  double shortEdge(const RowMatrixX3d& points) const;

  std::vector<std::array<int, 4>> quads_;
  std::vector<unsigned char> onPlanes_;
  BoundaryPlanes planes_;
  HyperbolicOptions options_;
  std::vector<std::vector<RingEntry>> rings_;
  // GMRES on the step's system from the last solution scaled to this step; false where it stalls.
  template <typename Preconditioner>
  bool solveIteratively(const Eigen::SparseMatrix<double>& matrix, const Eigen::VectorXd& rhs, double step,
                        Eigen::VectorXd& delta) const;

  // The step's smoothing operator, factored once (the preconditioner of the steps it suits).
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> smoothingFactor_;
  Eigen::VectorXd smoothingRowScale_;
  // The direct factor of the layer's last pseudo-step solved directly: the preconditioner of its
  // next pseudo-steps, until it no longer suits them.
  struct StepFactor;
  std::unique_ptr<StepFactor> stepFactor_;
  // The last solve's solution and its pseudo-step: the next solve's first guess.
  Eigen::VectorXd lastSolution_;
  double lastStep_ = 0.0;
};

}  // namespace bvmesh::volume
