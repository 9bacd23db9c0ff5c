// Internal: the bridge between ControlMesh and OpenSubdiv's Far layer (not part of the public
// API; OpenSubdiv types stay inside src/core/subdiv).
#pragma once

#include <opensubdiv/far/topologyRefiner.h>

#include <memory>
#include <vector>

#include "core/mesh/control_mesh.h"
#include "core/subdiv/subdivision.h"

namespace bvmesh::osd {

namespace Far = OpenSubdiv::Far;

// Makes OpenSubdiv report errors as TopologyError instead of printing them (installed once).
void installErrorHandler();

// A Catmark refiner for the mesh's topology, creases and corners (level 0 only).
std::unique_ptr<Far::TopologyRefiner> createRefiner(const ControlMesh& mesh,
                                                    const SubdivisionOptions& options);

// A refiner refined uniformly by one level, with full topology in that level (needed for limit
// masks).
std::unique_ptr<Far::TopologyRefiner> createRefinedOnce(const ControlMesh& mesh,
                                                        const SubdivisionOptions& options);

// For every level-1 vertex of OpenSubdiv, its index in our child order (old vertices, then edge
// points in ControlMesh edge order, then face points).
std::vector<int> childVertexOrder(const Far::TopologyRefiner& refiner, const ControlMesh& mesh);

// Sparse rows built one at a time from OpenSubdiv's masks (PrimvarRefiner calls Clear() once per
// destination row, then AddWithWeight for each contribution). Duplicate columns are summed with
// a dense scatter array, so a row costs O(its entries).
class RowBuilder {
public:
  // expectedRowSize: entries per row to reserve room for (a hint).
  RowBuilder(int numRows, int numColumns, int expectedRowSize);
  void begin(int row);  // finishes the previous row; beginning a finished row again replaces it
  void add(int column, double weight) {
    if (!marked_[static_cast<size_t>(column)]) {
      marked_[static_cast<size_t>(column)] = true;
      touched_.push_back(column);
    }
    dense_[static_cast<size_t>(column)] += weight;
  }
  // Adds weight * (finished row `row` of `source`).
  void addRow(const RowBuilder& source, int row, double weight);
  void finish();
  // The matrix with row r of this builder at row rowOrder[r]; the builder is emptied (its memory
  // released) so that large operators are not held twice.
  RowSparseMatrix takeMatrix(const std::vector<int>& rowOrder);

private:
  std::vector<int> start_;
  std::vector<int> count_;
  std::vector<int> columns_;
  std::vector<double> weights_;
  std::vector<double> dense_;
  std::vector<char> marked_;
  std::vector<int> touched_;
  int current_ = -1;
};

// Primvar "arrays" for PrimvarRefiner that record masks into RowBuilders instead of combining
// values. Element i of VertexRefs is source vertex i; element i of BuilderRows is destination
// row i, and can itself be a source (refined points made from other refined points); element i
// of ComposedRows is row i of a builder that, for each source vertex j, adds row j of an inner
// builder (the composition of two operators). Elements are made on the fly, so no per-vertex
// storage is needed.
struct VertexRef {
  int index;
};

struct VertexRefs {
  VertexRef operator[](int index) const { return {index}; }
};

class BuilderRow {
public:
  BuilderRow(RowBuilder* builder, int row) : builder_(builder), row_(row) {}
  void Clear() const { builder_->begin(row_); }
  void AddWithWeight(const VertexRef& source, double weight) const {
    builder_->add(source.index, weight);
  }
  void AddWithWeight(const BuilderRow& source, double weight) const {
    builder_->addRow(*source.builder_, source.row_, weight);
  }

private:
  RowBuilder* builder_;
  int row_;
};

struct BuilderRows {
  RowBuilder* builder;
  BuilderRow operator[](int row) const { return {builder, row}; }
};

class ComposedRow {
public:
  ComposedRow(RowBuilder* builder, const RowBuilder* inner, int row)
      : builder_(builder), inner_(inner), row_(row) {}
  void Clear() const { builder_->begin(row_); }
  void AddWithWeight(const VertexRef& source, double weight) const {
    builder_->addRow(*inner_, source.index, weight);
  }

private:
  RowBuilder* builder_;
  const RowBuilder* inner_;
  int row_;
};

struct ComposedRows {
  RowBuilder* builder;
  const RowBuilder* inner;
  ComposedRow operator[](int row) const { return {builder, inner, row}; }
};

// The rows of the first refinement's operator, in OpenSubdiv's level-1 vertex order (finished).
RowBuilder firstRefinementRows(const Far::TopologyRefiner& refiner);

// #V' x #V operator of the first refinement, rows in our child order.
RowSparseMatrix subdivisionOperator(const Far::TopologyRefiner& refiner,
                                    const std::vector<int>& childOrder);

// OpenSubdiv encodes infinite sharpness as 10.
float toOsdSharpness(double sharpness);
double fromOsdSharpness(float sharpness);

}  // namespace bvmesh::osd
