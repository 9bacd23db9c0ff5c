// Repair on reading: faces written each on its own (IGES in faces mode, STEP without shells) are
// sewn along the edges they share within a tolerance, so that adjacent patches share edges and
// each edge gets its true kind (smooth / sharp / free / seam / non-manifold); a closed shell
// becomes a solid (outward normals). The report says what was repaired and what was left: gaps
// closed, gaps left open (where, how wide), overlapping faces (pairs, area), degenerate edges
// and tiny faces removed, free edges, and whether the result is watertight.
//
// Indices in the report are 0-based in TopExp::MapShapes order (FreeCAD's Face<i+1>, Edge<j+1>):
// of the shape as read for removed faces, of the repaired shape for everything else.
#pragma once

#include <TopoDS_Shape.hxx>

#include <array>
#include <string>
#include <vector>

namespace bvmesh::cad {

struct RepairOptions {
  bool sew = true;
  // Absolute sewing tolerance (model units); 0 = automatic (automaticSewingTolerance).
  double tolerance = 0.0;
};

// A free edge with a free edge of another face close by, farther apart than the sewing
// tolerance: the faces should meet there but do not.
struct OpenGap {
  int edge = -1;
  int otherEdge = -1;
  int face = -1;
  int otherFace = -1;
  double width = 0.0;                  // largest distance from the edge's samples to the other edge
  std::array<double, 3> where{};       // the edge's midpoint
};

// Two faces that cover the same region (within the sewing tolerance of each other there), as a
// face written twice or patches that run on over their neighbours: sewing cannot join them.
struct FaceOverlap {
  int face = -1;
  int otherFace = -1;
  double area = 0.0;             // of the region, measured on the face with more of it
  std::array<double, 3> where{};  // its centroid
};

struct RepairReport {
  bool sewingAttempted = false;  // the shape had free edges and sewing was on
  bool sewingApplied = false;    // the sewn shape replaced the faces as read
  std::string keptReason;        // why the faces were kept as read (sewing attempted, not applied)
  double tolerance = 0.0;        // the sewing tolerance used
  double fileTolerance = 0.0;    // largest vertex tolerance of the shape as read
  double modelSize = 0.0;        // bounding-box diagonal
  int facesRead = 0;
  int faces = 0;
  int freeEdgesRead = 0;         // free edges of the shape as read
  int gapsClosed = 0;            // edges shared by two faces after sewing that were free before
  double largestGapClosed = 0.0; // largest distance between two edges sewn into one
  int degenerateEdgesRemoved = 0;     // edges shorter than the tolerance collapsed to a point
  std::vector<int> facesRemoved;      // faces smaller than the tolerance (indices as read)
  std::vector<OpenGap> openGaps;
  std::vector<FaceOverlap> overlaps;
  int freeEdges = 0;             // free edges of the result (seams and degenerate edges excluded)
  int nonManifoldEdges = 0;
  int closedFreeLoops = 0;       // free boundary as closed loops (e.g. a half model's root)
  int openFreeChains = 0;        // free boundary pieces that do not close
  bool madeSolid = false;        // the sewn faces closed up and became a solid
  std::vector<std::string> notes;  // what the reader did besides (e.g. IGES entities read directly)

  bool watertight() const { return freeEdges == 0 && nonManifoldEdges == 0; }
};

struct RepairedShape {
  TopoDS_Shape shape;
  RepairReport report;
};

// The tolerance sewing uses by default: twice the file's own (largest vertex tolerance), at least
// 2e-4 and at most 1e-3 of the model size (bounding-box diagonal), and below half the shortest
// edge longer than 1e-5 of the model size (so sewing never collapses a real small edge, e.g. the
// 0.5 mm edges of the M6's tip patches), but never below the file's own tolerance.
double automaticSewingTolerance(const TopoDS_Shape& shape);

// Sews `shape` (when options.sew and it has free edges) and reports. Keeps the shape as read when
// nothing gets sewn, and when sewing would change a face beyond the tolerance (its area changes by
// more than the tolerance times its perimeter), saying so in keptReason. Throws InvalidInputError
// for a null shape or a negative or non-finite tolerance.
RepairedShape repairShape(const TopoDS_Shape& shape, const RepairOptions& options = {});

// The report as text lines ("key value ...") and back: how the reader process hands it over.
std::string encodeRepairReport(const RepairReport& report);
RepairReport decodeRepairReport(const std::string& text);

// The report as readable lines, the first saying whether the geometry is watertight.
std::vector<std::string> describeRepair(const RepairReport& report);

}  // namespace bvmesh::cad
