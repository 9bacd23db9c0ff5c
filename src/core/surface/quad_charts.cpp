#include "core/surface/quad_charts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>

#include "core/common/errors.h"
#include "core/common/input_checks.h"

namespace bvmesh::surface {
namespace {

std::string edgeName(int a, int b) { return "(" + std::to_string(a) + ", " + std::to_string(b) + ")"; }

std::uint64_t edgeKey(int a, int b) {
  const auto lo = static_cast<std::uint64_t>(std::min(a, b));
  const auto hi = static_cast<std::uint64_t>(std::max(a, b));
  return (lo << 32) | hi;
}

// Edges, their faces and the faces around each vertex of a validated-array quad mesh.
class Connectivity {
 public:
  explicit Connectivity(const QuadControlMesh& mesh) : faces_(mesh.faces) {
    const int faceCount = static_cast<int>(faces_.rows());
    vertexEdges.resize(static_cast<size_t>(mesh.vertices.rows()));
    faceEdges.resize(static_cast<size_t>(faceCount));
    edgeIds_.reserve(static_cast<size_t>(2 * faceCount + 4));
    for (int f = 0; f < faceCount; ++f) {
      for (int k = 0; k < 4; ++k) {
        const int a = faces_(f, k);
        const int b = faces_(f, (k + 1) % 4);
        auto [it, inserted] = edgeIds_.emplace(edgeKey(a, b), static_cast<int>(edgeVertices.size()));
        const int e = it->second;
        if (inserted) {
          edgeVertices.push_back({a, b});
          edgeFaces.push_back({f, -1});
          edgeLocal.push_back({k, -1});
          vertexEdges[static_cast<size_t>(a)].push_back(e);
          vertexEdges[static_cast<size_t>(b)].push_back(e);
        } else {
          auto& ef = edgeFaces[static_cast<size_t>(e)];
          if (ef[1] >= 0) {
            throw TopologyError("edge " + edgeName(a, b) + " has more than two faces (faces " +
                                std::to_string(ef[0]) + ", " + std::to_string(ef[1]) + ", " +
                                std::to_string(f) + ")");
          }
          if (edgeVertices[static_cast<size_t>(e)][0] == a) {
            throw TopologyError("faces " + std::to_string(ef[0]) + " and " + std::to_string(f) +
                                " traverse edge " + edgeName(a, b) +
                                " in the same direction: inconsistent orientation");
          }
          ef[1] = f;
          edgeLocal[static_cast<size_t>(e)][1] = k;
        }
        faceEdges[static_cast<size_t>(f)][static_cast<size_t>(k)] = e;
      }
    }
    crease.assign(edgeVertices.size(), 0);
    for (Eigen::Index c = 0; c < mesh.creases.rows(); ++c) {
      const int e = edge(mesh.creases(c, 0), mesh.creases(c, 1));
      if (e < 0) {
        throw TopologyError("crease " + std::to_string(c) + " " +
                            edgeName(mesh.creases(c, 0), mesh.creases(c, 1)) + " is not an edge of the mesh");
      }
      crease[static_cast<size_t>(e)] = 1;
    }
  }

  int edge(int a, int b) const {
    auto it = edgeIds_.find(edgeKey(a, b));
    return it == edgeIds_.end() ? -1 : it->second;
  }
  int faceVertex(int f, int k) const { return faces_(f, k); }
  int cornerOf(int f, int v) const {
    for (int k = 0; k < 4; ++k) {
      if (faces_(f, k) == v) return k;
    }
    return -1;
  }
  bool boundary(int e) const { return edgeFaces[static_cast<size_t>(e)][1] < 0; }
  bool sharp(int e) const { return crease[static_cast<size_t>(e)] != 0 || boundary(e); }
  // The face across edge e from face f (-1 on a boundary) and the edge's local index there.
  std::pair<int, int> across(int e, int f) const {
    const auto& ef = edgeFaces[static_cast<size_t>(e)];
    const auto& el = edgeLocal[static_cast<size_t>(e)];
    return ef[0] == f ? std::make_pair(ef[1], el[1]) : std::make_pair(ef[0], el[0]);
  }
  // At a vertex b of edge e: the edge that continues e straight through a valence-4 vertex.
  int oppositeEdge(int b, int e) const {
    std::array<int, 3> excluded{e, -1, -1};
    for (int side = 0; side < 2; ++side) {
      const int f = edgeFaces[static_cast<size_t>(e)][static_cast<size_t>(side)];
      if (f < 0) continue;
      const int c = cornerOf(f, b);
      const int in = faceEdges[static_cast<size_t>(f)][static_cast<size_t>((c + 3) % 4)];
      const int out = faceEdges[static_cast<size_t>(f)][static_cast<size_t>(c)];
      excluded[static_cast<size_t>(side + 1)] = (in == e) ? out : in;
    }
    for (int x : vertexEdges[static_cast<size_t>(b)]) {
      if (std::find(excluded.begin(), excluded.end(), x) == excluded.end()) return x;
    }
    return -1;
  }

  std::vector<std::array<int, 2>> edgeVertices;
  std::vector<std::array<int, 2>> edgeFaces;  // second is -1 on a boundary
  std::vector<std::array<int, 2>> edgeLocal;  // local edge index k (vertex k -> k+1) in each face
  std::vector<std::array<int, 4>> faceEdges;
  std::vector<std::vector<int>> vertexEdges;
  std::vector<char> crease;

 private:
  const RowMatrixX4i& faces_;
  std::unordered_map<std::uint64_t, int> edgeIds_;
};

// A face seen as a chart cell: cell corner k is face vertex (k + rotation) % 4.
struct Frame {
  int face = -1;
  int rotation = 0;
};

class LayoutBuilder {
 public:
  LayoutBuilder(const QuadControlMesh& mesh, const Connectivity& topo)
      : mesh_(mesh), topo_(topo), border_(topo.edgeVertices.size(), 0) {
    classifyVertices();
  }

  ChartLayout build() {
    for (size_t e = 0; e < border_.size(); ++e) {
      if (topo_.sharp(static_cast<int>(e))) border_[e] = 1;
    }
    for (int j : layout_.junctions) {
      for (int e : topo_.vertexEdges[static_cast<size_t>(j)]) extendLine(j, e);
    }
    // Every pass either ends with rectangles or adds border edges, so this terminates.
    for (size_t pass = 0; pass <= border_.size() + 1; ++pass) {
      if (!buildCharts()) continue;
      buildSegments();
      if (buildLines()) return std::move(layout_);
    }
    throw TopologyError("the quad mesh could not be split into rectangular charts");
  }

 private:
  int faceCount() const { return static_cast<int>(mesh_.faces.rows()); }
  bool isBorder(int e) const { return border_[static_cast<size_t>(e)] != 0; }
  int cellEdge(const Frame& f, int k) const {
    return topo_.faceEdges[static_cast<size_t>(f.face)][static_cast<size_t>((k + f.rotation) % 4)];
  }
  int cellCorner(const Frame& f, int k) const { return topo_.faceVertex(f.face, (k + f.rotation) % 4); }
  Frame cross(const Frame& f, int k) const {
    auto [g, local] = topo_.across(cellEdge(f, k), f.face);
    return Frame{g, ((local - (k + 2)) % 4 + 4) % 4};
  }

  void classifyVertices() {
    const int vertexCount = static_cast<int>(mesh_.vertices.rows());
    std::vector<std::vector<std::pair<int, int>>> corners(static_cast<size_t>(vertexCount));
    for (int f = 0; f < faceCount(); ++f) {
      for (int k = 0; k < 4; ++k) corners[static_cast<size_t>(mesh_.faces(f, k))].push_back({f, k});
    }
    std::vector<char> tagged(static_cast<size_t>(vertexCount), 0);
    for (int c : mesh_.corners) tagged[static_cast<size_t>(c)] = 1;
    stop_.assign(static_cast<size_t>(vertexCount), 0);
    for (int v = 0; v < vertexCount; ++v) {
      const auto& around = corners[static_cast<size_t>(v)];
      if (around.empty()) continue;
      int sharpCount = 0;
      for (int e : topo_.vertexEdges[static_cast<size_t>(v)]) sharpCount += topo_.sharp(e) ? 1 : 0;
      bool regular = false;
      if (tagged[static_cast<size_t>(v)] == 0) {
        if (sharpCount == 0) {
          regular = around.size() == 4 && topo_.vertexEdges[static_cast<size_t>(v)].size() == 4;
        } else if (sharpCount == 2) {
          regular = sectorsAllOfTwo(v, around);
        }
      }
      if (!regular) layout_.junctions.push_back(v);
      if (tagged[static_cast<size_t>(v)] != 0 || sharpCount >= 3) layout_.corners.push_back(v);
      stop_[static_cast<size_t>(v)] = (!regular || sharpCount > 0) ? 1 : 0;
    }
  }

  // Every fan between consecutive sharp edges around v holds exactly two faces.
  bool sectorsAllOfTwo(int v, const std::vector<std::pair<int, int>>& around) const {
    size_t covered = 0;
    for (auto [f0, k0] : around) {
      if (!topo_.sharp(topo_.faceEdges[static_cast<size_t>(f0)][static_cast<size_t>((k0 + 3) % 4)])) continue;
      int count = 1;
      int f = f0;
      int k = k0;
      while (true) {
        const int out = topo_.faceEdges[static_cast<size_t>(f)][static_cast<size_t>(k)];
        if (topo_.sharp(out) || count > 4) break;
        f = topo_.across(out, f).first;
        k = topo_.cornerOf(f, v);
        ++count;
      }
      if (count != 2) return false;
      covered += 2;
    }
    return covered == around.size();
  }

  // Marks edge e (leaving vertex `from`) and the edge line beyond it as chart border, continuing
  // straight through regular interior vertices.
  void extendLine(int from, int e) {
    int a = from;
    for (size_t steps = 0; steps <= border_.size(); ++steps) {
      if (isBorder(e)) return;
      border_[static_cast<size_t>(e)] = 1;
      const auto& ev = topo_.edgeVertices[static_cast<size_t>(e)];
      const int b = ev[0] == a ? ev[1] : ev[0];
      if (stop_[static_cast<size_t>(b)] != 0) return;
      e = topo_.oppositeEdge(b, e);
      a = b;
    }
  }

  // Cuts along the whole edge line through e (both directions), to open a loop of faces.
  void cutThrough(int e) {
    const auto ev = topo_.edgeVertices[static_cast<size_t>(e)];
    extendLine(ev[0], e);
    if (stop_[static_cast<size_t>(ev[0])] == 0) extendLine(ev[0], topo_.oppositeEdge(ev[0], e));
  }

  std::vector<std::vector<int>> components() const {
    std::vector<int> seen(static_cast<size_t>(faceCount()), 0);
    std::vector<std::vector<int>> result;
    for (int seed = 0; seed < faceCount(); ++seed) {
      if (seen[static_cast<size_t>(seed)] != 0) continue;
      std::vector<int> comp{seed};
      seen[static_cast<size_t>(seed)] = 1;
      for (size_t q = 0; q < comp.size(); ++q) {
        for (int e : topo_.faceEdges[static_cast<size_t>(comp[q])]) {
          if (isBorder(e)) continue;
          const int g = topo_.across(e, comp[q]).first;
          if (seen[static_cast<size_t>(g)] == 0) {
            seen[static_cast<size_t>(g)] = 1;
            comp.push_back(g);
          }
        }
      }
      result.push_back(std::move(comp));
    }
    return result;
  }

  // Walks from `start` across cell edge k until a border edge; cuts and returns false on a loop.
  bool walk(Frame& f, int k, std::vector<Frame>* cells) {
    // A walk that meets a face again (back at its start, or crossing itself) runs round a loop.
    const int stamp = nextStamp();
    const Frame start = f;
    visited_[static_cast<size_t>(f.face)] = stamp;
    if (cells != nullptr) cells->push_back(f);
    while (!isBorder(cellEdge(f, k))) {
      f = cross(f, k);
      if (visited_[static_cast<size_t>(f.face)] == stamp) {
        cutThrough(cellEdge(start, k));
        return false;
      }
      visited_[static_cast<size_t>(f.face)] = stamp;
      if (cells != nullptr) cells->push_back(f);
    }
    return true;
  }

  int nextStamp() {
    if (visited_.empty()) visited_.assign(static_cast<size_t>(faceCount()), 0);
    return ++stamp_;
  }

  // Rectangle from a component, or false after adding border edges that make progress.
  bool extractRectangle(const std::vector<int>& comp, QuadChart& chart) {
    Frame corner{comp.front(), 0};
    if (!walk(corner, 3, nullptr) || !walk(corner, 0, nullptr)) return false;
    std::vector<Frame> bottom;
    Frame f = corner;
    if (!walk(f, 1, &bottom)) return false;
    const int m = static_cast<int>(bottom.size());
    std::vector<std::vector<Frame>> columns;
    for (const Frame& cell : bottom) {
      Frame g = cell;
      std::vector<Frame> column;
      if (!walk(g, 2, &column)) return false;
      columns.push_back(std::move(column));
    }
    int n = 0;
    for (const auto& column : columns) n = std::max(n, static_cast<int>(column.size()));
    bool rectangular = static_cast<size_t>(m) * static_cast<size_t>(n) == comp.size();
    const int distinct = nextStamp();
    for (int i = 0; rectangular && i < m; ++i) {
      rectangular = static_cast<int>(columns[static_cast<size_t>(i)].size()) == n;
      for (const Frame& cell : columns[static_cast<size_t>(i)]) {
        rectangular = rectangular && visited_[static_cast<size_t>(cell.face)] != distinct;
        visited_[static_cast<size_t>(cell.face)] = distinct;
      }
    }
    for (int i = 0; rectangular && i < m; ++i) {
      const auto& col = columns[static_cast<size_t>(i)];
      rectangular = isBorder(cellEdge(col[0], 0));
      for (int j = 0; rectangular && j < n; ++j) {
        const Frame& c = col[static_cast<size_t>(j)];
        if (i == 0) rectangular = isBorder(cellEdge(c, 3));
        if (i + 1 == m) {
          rectangular = rectangular && isBorder(cellEdge(c, 1));
        } else {
          const Frame& right = columns[static_cast<size_t>(i + 1)][static_cast<size_t>(j)];
          const Frame next = cross(c, 1);
          rectangular = rectangular && !isBorder(cellEdge(c, 1)) && next.face == right.face &&
                        next.rotation == right.rotation;
        }
      }
    }
    if (!rectangular) {
      if (!splitReflexSector(comp)) {
        throw TopologyError("the faces connected to face " + std::to_string(comp.front()) +
                            " form a region that cannot be split into rectangular charts");
      }
      return false;
    }
    chart.uCells = m;
    chart.vCells = n;
    chart.faces.resize(static_cast<size_t>(m * n));
    chart.rotations.resize(static_cast<size_t>(m * n));
    chart.vertices.resize(static_cast<size_t>((m + 1) * (n + 1)));
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < n; ++j) {
        const Frame& c = columns[static_cast<size_t>(i)][static_cast<size_t>(j)];
        chart.faces[static_cast<size_t>(i * n + j)] = c.face;
        chart.rotations[static_cast<size_t>(i * n + j)] = c.rotation;
        const int di[4] = {0, 1, 1, 0};
        const int dj[4] = {0, 0, 1, 1};
        for (int k = 0; k < 4; ++k) {
          chart.vertices[static_cast<size_t>((i + di[k]) * (n + 1) + j + dj[k])] = cellCorner(c, k);
        }
      }
    }
    return true;
  }

  // A vertex where a component wraps three or more faces between border edges is a concave
  // corner: the component is cut along the edges inside that fan.
  bool splitReflexSector(const std::vector<int>& comp) {
    for (int f0 : comp) {
      for (int k0 = 0; k0 < 4; ++k0) {
        const int v = topo_.faceVertex(f0, k0);
        // Rewind clockwise to the fan's first face, then count counter-clockwise.
        int f = f0;
        int k = k0;
        bool closed = false;
        for (int steps = 0;; ++steps) {
          const int in = topo_.faceEdges[static_cast<size_t>(f)][static_cast<size_t>((k + 3) % 4)];
          if (isBorder(in)) break;
          if (steps > faceCount()) {
            closed = true;
            break;
          }
          f = topo_.across(in, f).first;
          k = topo_.cornerOf(f, v);
          if (f == f0) {
            closed = true;
            break;
          }
        }
        if (closed) continue;
        std::vector<int> inner;
        while (true) {
          const int out = topo_.faceEdges[static_cast<size_t>(f)][static_cast<size_t>(k)];
          if (isBorder(out)) break;
          inner.push_back(out);
          f = topo_.across(out, f).first;
          k = topo_.cornerOf(f, v);
        }
        if (inner.size() >= 2) {
          for (int e : inner) extendLine(v, e);
          return true;
        }
      }
    }
    return false;
  }

  bool buildCharts() {
    layout_.charts.clear();
    layout_.faceChart.assign(static_cast<size_t>(faceCount()), -1);
    bool complete = true;
    for (const auto& comp : components()) {
      QuadChart chart;
      if (!extractRectangle(comp, chart)) {
        complete = false;
        continue;
      }
      if (!complete) continue;
      for (int face : chart.faces)
        layout_.faceChart[static_cast<size_t>(face)] = static_cast<int>(layout_.charts.size());
      layout_.charts.push_back(std::move(chart));
    }
    return complete;
  }

  void buildSegments() {
    layout_.segments.clear();
    segmentEdges_.clear();
    std::vector<char> isNode(static_cast<size_t>(mesh_.vertices.rows()), 0);
    for (const QuadChart& chart : layout_.charts) {
      for (int v : {chart.vertex(0, 0), chart.vertex(chart.uCells, 0),
                    chart.vertex(chart.uCells, chart.vCells), chart.vertex(0, chart.vCells)}) {
        isNode[static_cast<size_t>(v)] = 1;
      }
    }
    layout_.nodes.clear();
    for (size_t v = 0; v < isNode.size(); ++v) {
      if (isNode[v] != 0) layout_.nodes.push_back(static_cast<int>(v));
    }
    std::vector<int> edgeSegment(border_.size(), -1);
    for (size_t c = 0; c < layout_.charts.size(); ++c) {
      QuadChart& chart = layout_.charts[c];
      for (int s = 0; s < 4; ++s) {
        const auto side = static_cast<ChartSide>(s);
        const int length = chart.sideLength(side);
        chart.sideSegments[static_cast<size_t>(s)].clear();
        int p0 = 0;
        for (int p = 1; p <= length; ++p) {
          if (p < length && isNode[static_cast<size_t>(chart.sideVertex(side, p))] == 0) continue;
          const int first = topo_.edge(chart.sideVertex(side, p0), chart.sideVertex(side, p0 + 1));
          int segment = edgeSegment[static_cast<size_t>(first)];
          SegmentUse use{static_cast<int>(c), side, p0, false};
          if (segment < 0) {
            segment = static_cast<int>(layout_.segments.size());
            BorderSegment seg;
            std::vector<int> edges;
            for (int q = p0; q <= p; ++q) seg.vertices.push_back(chart.sideVertex(side, q));
            for (int q = p0; q < p; ++q) {
              const int e = topo_.edge(chart.sideVertex(side, q), chart.sideVertex(side, q + 1));
              edges.push_back(e);
              edgeSegment[static_cast<size_t>(e)] = segment;
            }
            seg.kind = topo_.boundary(first)                           ? BorderKind::Boundary
                       : topo_.crease[static_cast<size_t>(first)] != 0 ? BorderKind::Crease
                                                                       : BorderKind::Separatrix;
            layout_.segments.push_back(std::move(seg));
            segmentEdges_.push_back(std::move(edges));
          } else {
            const auto& edges = segmentEdges_[static_cast<size_t>(segment)];
            const auto& verts = layout_.segments[static_cast<size_t>(segment)].vertices;
            if (static_cast<int>(edges.size()) != p - p0) {
              throw SolverError("chart layout: border segment " + std::to_string(segment) +
                                " is seen with different lengths from its two sides");
            }
            const bool forward = edges.front() == first && verts.front() == chart.sideVertex(side, p0);
            if (!forward) use = SegmentUse{static_cast<int>(c), side, p, true};
          }
          layout_.segments[static_cast<size_t>(segment)].uses.push_back(use);
          chart.sideSegments[static_cast<size_t>(s)].push_back(segment);
          p0 = p;
        }
      }
    }
  }

  // Chains of segments joined where a chart side passes a node. A closed chain has no place for
  // clamped curve ends, so it is broken by cutting the passing chart there.
  bool buildLines() {
    const size_t segmentCount = layout_.segments.size();
    std::vector<int> link(2 * segmentCount, -1);
    struct Pass {
      int chart;
      ChartSide side;
      int position;
    };
    std::vector<Pass> passAt(2 * segmentCount, Pass{-1, ChartSide::VMin, 0});
    auto endAt = [&](int segment, int chart, ChartSide side, int position) {
      for (const SegmentUse& use : layout_.segments[static_cast<size_t>(segment)].uses) {
        if (use.chart != chart || use.side != side) continue;
        if (use.first == position) return 2 * segment;
        const int length =
            static_cast<int>(layout_.segments[static_cast<size_t>(segment)].vertices.size()) - 1;
        if (use.first + (use.reversed ? -length : length) == position) return 2 * segment + 1;
      }
      throw SolverError("chart layout: segment " + std::to_string(segment) + " is not where its chart says");
    };
    for (size_t c = 0; c < layout_.charts.size(); ++c) {
      const QuadChart& chart = layout_.charts[c];
      for (int s = 0; s < 4; ++s) {
        const auto side = static_cast<ChartSide>(s);
        const auto& list = chart.sideSegments[static_cast<size_t>(s)];
        int position = 0;
        for (size_t k = 0; k + 1 < list.size(); ++k) {
          position += static_cast<int>(layout_.segments[static_cast<size_t>(list[k])].vertices.size()) - 1;
          const int a = endAt(list[k], static_cast<int>(c), side, position);
          const int b = endAt(list[k + 1], static_cast<int>(c), side, position);
          if ((link[static_cast<size_t>(a)] >= 0 && link[static_cast<size_t>(a)] != b) ||
              (link[static_cast<size_t>(b)] >= 0 && link[static_cast<size_t>(b)] != a)) {
            throw SolverError("chart layout: border segments continue ambiguously at vertex " +
                              std::to_string(chart.sideVertex(side, position)));
          }
          link[static_cast<size_t>(a)] = b;
          link[static_cast<size_t>(b)] = a;
          passAt[static_cast<size_t>(a)] = Pass{static_cast<int>(c), side, position};
          passAt[static_cast<size_t>(b)] = passAt[static_cast<size_t>(a)];
        }
      }
    }
    layout_.lines.clear();
    std::vector<char> used(segmentCount, 0);
    auto chainFrom = [&](int startEnd) {
      BorderLine line;
      int end = startEnd;
      while (end >= 0 && used[static_cast<size_t>(end / 2)] == 0) {
        used[static_cast<size_t>(end / 2)] = 1;
        line.segments.push_back(end / 2);
        line.reversed.push_back(end % 2 == 1);
        end = link[static_cast<size_t>(end ^ 1)];
      }
      layout_.lines.push_back(std::move(line));
    };
    for (size_t end = 0; end < 2 * segmentCount; ++end) {
      if (link[end] < 0 && used[end / 2] == 0) chainFrom(static_cast<int>(end));
    }
    for (size_t s = 0; s < segmentCount; ++s) {
      if (used[s] != 0) continue;
      // A closed chain: cut the chart that passes the first segment's start into two.
      const Pass pass = passAt[2 * s];
      const QuadChart& chart = layout_.charts[static_cast<size_t>(pass.chart)];
      const int p = pass.position;
      int from = -1;
      int to = -1;
      switch (pass.side) {
        case ChartSide::VMin:
          from = chart.vertex(p, 0);
          to = chart.vertex(p, 1);
          break;
        case ChartSide::UMax:
          from = chart.vertex(chart.uCells, p);
          to = chart.vertex(chart.uCells - 1, p);
          break;
        case ChartSide::VMax:
          from = chart.vertex(p, chart.vCells);
          to = chart.vertex(p, chart.vCells - 1);
          break;
        case ChartSide::UMin:
          from = chart.vertex(0, p);
          to = chart.vertex(1, p);
          break;
      }
      extendLine(from, topo_.edge(from, to));
      return false;
    }
    return true;
  }

  const QuadControlMesh& mesh_;
  const Connectivity& topo_;
  std::vector<char> border_;
  std::vector<char> stop_;  // junctions and vertices on sharp edges end separatrices
  std::vector<std::vector<int>> segmentEdges_;
  std::vector<int> visited_;  // per face: stamp of the last walk (or check) that saw it
  int stamp_ = 0;
  ChartLayout layout_;
};

}  // namespace

int QuadChart::sideLength(ChartSide side) const {
  return (side == ChartSide::VMin || side == ChartSide::VMax) ? uCells : vCells;
}

int QuadChart::sideVertex(ChartSide side, int position) const {
  switch (side) {
    case ChartSide::VMin:
      return vertex(position, 0);
    case ChartSide::UMax:
      return vertex(uCells, position);
    case ChartSide::VMax:
      return vertex(position, vCells);
    case ChartSide::UMin:
      return vertex(0, position);
  }
  return -1;
}

QuadControlMesh makeQuadControlMesh(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<std::array<int, 4>>& quads,
                                    const std::vector<std::array<int, 2>>& creases) {
  QuadControlMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t v = 0; v < points.size(); ++v) mesh.vertices.row(static_cast<Eigen::Index>(v)) = points[v].transpose();
  mesh.faces.resize(static_cast<Eigen::Index>(quads.size()), 4);
  for (size_t f = 0; f < quads.size(); ++f) {
    for (int k = 0; k < 4; ++k) mesh.faces(static_cast<Eigen::Index>(f), k) = quads[f][static_cast<size_t>(k)];
  }
  mesh.creases.resize(static_cast<Eigen::Index>(creases.size()), 2);
  for (size_t c = 0; c < creases.size(); ++c) {
    mesh.creases(static_cast<Eigen::Index>(c), 0) = creases[c][0];
    mesh.creases(static_cast<Eigen::Index>(c), 1) = creases[c][1];
  }
  return mesh;
}

void validateQuadControlMesh(const QuadControlMesh& mesh) {
  const Eigen::Index vertexCount = mesh.vertices.rows();
  checkFinitePoints(mesh.vertices);
  if (mesh.faces.rows() == 0) throw InvalidInputError("the quad mesh has no faces");
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const int v = mesh.faces(f, k);
      if (v < 0 || v >= vertexCount) {
        throw InvalidInputError("face " + std::to_string(f) + " refers to vertex " + std::to_string(v) +
                                ", outside 0.." + std::to_string(vertexCount - 1));
      }
      for (int l = 0; l < k; ++l) {
        if (mesh.faces(f, l) == v) {
          throw TopologyError("face " + std::to_string(f) + " repeats vertex " + std::to_string(v));
        }
      }
    }
  }
  for (Eigen::Index c = 0; c < mesh.creases.rows(); ++c) {
    for (int k = 0; k < 2; ++k) {
      const int v = mesh.creases(c, k);
      if (v < 0 || v >= vertexCount) {
        throw InvalidInputError("crease " + std::to_string(c) + " refers to vertex " + std::to_string(v) +
                                ", outside 0.." + std::to_string(vertexCount - 1));
      }
    }
  }
  for (size_t c = 0; c < mesh.corners.size(); ++c) {
    if (mesh.corners[c] < 0 || mesh.corners[c] >= vertexCount) {
      throw InvalidInputError("corner " + std::to_string(c) + " refers to vertex " +
                              std::to_string(mesh.corners[c]) + ", outside 0.." +
                              std::to_string(vertexCount - 1));
    }
  }
  Connectivity topology(mesh);
}

ChartLayout buildChartLayout(const QuadControlMesh& mesh) {
  validateQuadControlMesh(mesh);
  Connectivity topology(mesh);
  LayoutBuilder builder(mesh, topology);
  return builder.build();
}

}  // namespace bvmesh::surface
