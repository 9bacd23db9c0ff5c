#include "core/volume/edge_fans.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/math_constants.h"

namespace bvmesh::volume {
namespace {

// A patch's quads run along its side in increasing entry order on VMin and UMax, decreasing on
// VMax and UMin (counter-clockwise round each quad).
bool runsForward(ChartSide side) { return side == ChartSide::VMin || side == ChartSide::UMax; }

Eigen::Vector3d sideNormal(const WallPatch& patch, ChartSide side, int t) {
  const auto [i, j] = sidePolePosition(patch, side, t);
  Eigen::Vector3d normal;
  polePoint(patch, i, j, &normal);
  return normal.normalized();
}

// A knife edge between patch `a` side `aSide` and patch `b` side `bSide`, from vertex `from` to
// vertex `to` along its chain; `a` is the face whose quads run along it from `from` to `to`.
struct Knife {
  int a = -1, b = -1;
  ChartSide aSide = ChartSide::VMin, bSide = ChartSide::VMin;
  bool reversed = false;  // b's entries run against a's
  int from = -1, to = -1;
};

// How far a cusp's faces may lie on the wrong side of each other's tangent planes by rounding.
constexpr double kCuspTolerance = 1e-9;

bool isKnife(const std::vector<WallPatch>& patches, int p, ChartSide side) {
  const WallPatch& patch = patches[static_cast<size_t>(p)];
  const PatchSideLink& link = patch.sides[static_cast<size_t>(side)];
  if (link.patch < 0 || !patch.creaseSide[static_cast<size_t>(side)]) return false;
  const WallPatch& other = patches[static_cast<size_t>(link.patch)];
  const int length = sidePoleCount(patch, side);
  const double knife = std::cos(kKnifeEdgeDegrees * kPi / 180.0);
  for (int t = 1; t + 1 < length; ++t) {
    const int theirs = link.reversed ? length - 1 - t : t;
    const Eigen::Vector3d mine = sideNormal(patch, side, t), its = sideNormal(other, link.side, theirs);
    if (mine.dot(its) > knife) return false;
    // Convex: each face lies behind the other's tangent plane (a narrow groove, its faces'
    // normals as far apart, is concave; a cusp, with opposite normals, is both).
    const double behind =
        mine.dot(sideOutward(other, link.side, theirs)) + its.dot(sideOutward(patch, side, t));
    if (behind < -kCuspTolerance) return false;
  }
  return length > 2;
}

// Every knife edge once, oriented along its chain: chains of knife edges through vertices where
// exactly two of them meet run one way, so that one face of a trailing edge is `a` all along it.
std::vector<Knife> orientedKnives(const std::vector<WallPatch>& patches) {
  std::vector<Knife> knives;
  for (size_t p = 0; p < patches.size(); ++p) {
    for (int s = 0; s < 4; ++s) {
      const ChartSide side = static_cast<ChartSide>(s);
      const PatchSideLink& link = patches[p].sides[static_cast<size_t>(s)];
      if (link.patch < static_cast<int>(p) || (link.patch == static_cast<int>(p) && link.side <= side))
        continue;
      if (!isKnife(patches, static_cast<int>(p), side)) continue;
      Knife knife;
      knife.a = static_cast<int>(p);
      knife.aSide = side;
      knife.b = link.patch;
      knife.bSide = link.side;
      knife.reversed = link.reversed;
      const std::vector<int>& chain = patches[p].sideVertices[static_cast<size_t>(s)];
      knife.from = runsForward(side) ? chain.front() : chain.back();
      knife.to = runsForward(side) ? chain.back() : chain.front();
      knives.push_back(knife);
    }
  }
  std::map<int, std::vector<size_t>> at;
  for (size_t k = 0; k < knives.size(); ++k) {
    at[knives[k].from].push_back(k);
    at[knives[k].to].push_back(k);
  }
  // Walk each chain from one of its ends (or anywhere on a loop), turning every knife to run on.
  std::vector<char> done(knives.size(), 0);
  auto flip = [&](Knife& knife) {
    std::swap(knife.a, knife.b);
    std::swap(knife.aSide, knife.bSide);
    std::swap(knife.from, knife.to);
  };
  for (size_t seed = 0; seed < knives.size(); ++seed) {
    if (done[seed] != 0) continue;
    size_t start = seed;
    int vertex = knives[seed].from;
    for (size_t steps = 0; steps < knives.size() && at[vertex].size() == 2; ++steps) {
      const size_t previous = at[vertex][0] == start ? at[vertex][1] : at[vertex][0];
      if (previous == seed) break;  // a loop
      start = previous;
      vertex = knives[start].from == vertex ? knives[start].to : knives[start].from;
    }
    if (knives[start].from != vertex) flip(knives[start]);
    for (size_t k = start;;) {
      done[k] = 1;
      const int next = knives[k].to;
      if (at[next].size() != 2) break;
      const size_t following = at[next][0] == k ? at[next][1] : at[next][0];
      if (done[following] != 0) break;
      if (knives[following].from != next) flip(knives[following]);
      k = following;
    }
  }
  return knives;
}

// Whether `vertex` ends an open side of the patch (the wall's boundary: a symmetry plane).
bool openAt(const WallPatch& patch, int vertex) {
  for (int s = 0; s < 4; ++s) {
    const std::vector<int>& chain = patch.sideVertices[static_cast<size_t>(s)];
    if (patch.sides[static_cast<size_t>(s)].patch < 0 && !patch.collapsedSide[static_cast<size_t>(s)] &&
        (chain.front() == vertex || chain.back() == vertex)) {
      return true;
    }
  }
  return false;
}

// Copies (1, 2) of a cut-open chain vertex for the patches that touch it at a corner alone (more
// than four patches there, or the chain turning at it): each takes the copy of the patches it
// meets across its uncut sides round the vertex, the side of the knife edges it lies on. Skips
// the vertices where the chains close (copy 0 for every patch there).
void spreadCornerCopies(std::vector<WallPatch>& patches, const std::set<int>& closing) {
  // The two sides meeting at each corner, with the corner's end along each.
  constexpr std::array<std::array<std::pair<ChartSide, int>, 2>, 4> kCornerSides{{
      {{{ChartSide::VMin, 0}, {ChartSide::UMin, 0}}},
      {{{ChartSide::VMin, 1}, {ChartSide::UMax, 0}}},
      {{{ChartSide::VMax, 0}, {ChartSide::UMin, 1}}},
      {{{ChartSide::VMax, 1}, {ChartSide::UMax, 1}}},
  }};
  for (bool changed = true; changed;) {
    changed = false;
    for (WallPatch& patch : patches) {
      if (patch.fan) continue;
      for (int corner = 0; corner < 4; ++corner) {
        const int copy = patch.cornerCopy[static_cast<size_t>(corner)];
        const int vertex = cornerVertex(patch, corner);
        if (copy == 0 || closing.count(vertex) != 0) continue;
        for (const auto& [side, end] : kCornerSides[static_cast<size_t>(corner)]) {
          const PatchSideLink& link = patch.sides[static_cast<size_t>(side)];
          if (link.patch < 0 || patches[static_cast<size_t>(link.patch)].fan) continue;  // open, or cut
          WallPatch& other = patches[static_cast<size_t>(link.patch)];
          const std::vector<int>& chain = other.sideVertices[static_cast<size_t>(link.side)];
          const int theirs = sideEndCorner(link.side, chain.front() == vertex ? 0 : 1);
          int& otherCopy = other.cornerCopy[static_cast<size_t>(theirs)];
          if (otherCopy == copy) continue;
          if (otherCopy != 0) {
            throw InvalidInputError("the knife edges through control vertex " + std::to_string(vertex) +
                                    " do not part the wall round it in two: march this wall without "
                                    "knife_edge_fans");
          }
          otherCopy = copy;
          changed = true;
        }
      }
    }
  }
}

}  // namespace

int insertEdgeFans(std::vector<WallPatch>& patches) {
  const std::vector<Knife> knives = orientedKnives(patches);
  if (knives.empty()) return 0;
  std::map<int, int> ends;  // vertex -> knife ends there
  for (const Knife& knife : knives) {
    ++ends[knife.from];
    ++ends[knife.to];
  }
  for (const auto& [vertex, count] : ends) {
    const Knife& knife = *std::find_if(knives.begin(), knives.end(),
                                       [&](const Knife& k) { return k.from == vertex || k.to == vertex; });
    if (count > 2 && (openAt(patches[static_cast<size_t>(knife.a)], vertex) ||
                      openAt(patches[static_cast<size_t>(knife.b)], vertex))) {
      throw InvalidInputError(std::to_string(count) + " knife edges meet at control vertex " +
                              std::to_string(vertex) +
                              " on the symmetry plane: fans end there one per knife edge, so march this wall "
                              "without knife_edge_fans");
    }
  }
  // Where a chain ends inside the wall its copies join again (copy 0) and the fans close.
  auto closes = [&](const Knife& knife, int vertex) {
    return ends[vertex] != 2 && !openAt(patches[static_cast<size_t>(knife.a)], vertex) &&
           !openAt(patches[static_cast<size_t>(knife.b)], vertex);
  };
  const size_t firstFan = patches.size();
  std::map<int, std::vector<std::pair<size_t, ChartSide>>> fanEnds;  // chain vertex -> (fan, its end side)
  for (const Knife& knife : knives) {
    WallPatch& a = patches[static_cast<size_t>(knife.a)];
    WallPatch& b = patches[static_cast<size_t>(knife.b)];
    const int length = sidePoleCount(a, knife.aSide);
    // The fan's u runs against a's quads along the edge (from `to` to `from`), so that its own
    // quads, counter-clockwise like the wall's, meet a's the other way round.
    const bool againstA = runsForward(knife.aSide);
    const std::vector<double>& edgeKnots = knife.aSide == ChartSide::VMin || knife.aSide == ChartSide::VMax
                                               ? a.surface.uKnots
                                               : a.surface.vKnots;
    WallPatch fan;
    fan.fan = true;
    fan.surface.uKnots = edgeKnots;
    if (againstA) {
      std::reverse(fan.surface.uKnots.begin(), fan.surface.uKnots.end());
      for (double& k : fan.surface.uKnots) k = edgeKnots.front() + edgeKnots.back() - k;
    }
    fan.surface.vKnots = uniformClampedKnots(3, kFanSpans);
    fan.surface.uPoles = length;
    fan.surface.vPoles = kFanSpans + 3;
    for (int i = 0; i < length; ++i) {
      const auto [ia, ja] = sidePolePosition(a, knife.aSide, againstA ? length - 1 - i : i);
      fan.surface.poles.insert(fan.surface.poles.end(), static_cast<size_t>(fan.surface.vPoles),
                               a.surface.pole(ia, ja));
    }
    std::vector<int> chain = a.sideVertices[static_cast<size_t>(knife.aSide)];
    if (againstA) std::reverse(chain.begin(), chain.end());
    fan.sideVertices[static_cast<size_t>(ChartSide::VMin)] = chain;
    fan.sideVertices[static_cast<size_t>(ChartSide::VMax)] = chain;
    fan.sideVertices[static_cast<size_t>(ChartSide::UMin)].assign(static_cast<size_t>(kFanSpans + 1),
                                                                  chain.front());
    fan.sideVertices[static_cast<size_t>(ChartSide::UMax)].assign(static_cast<size_t>(kFanSpans + 1),
                                                                  chain.back());
    const size_t id = patches.size();
    fan.sides[static_cast<size_t>(ChartSide::VMin)] = {knife.a, knife.aSide, againstA};
    fan.sides[static_cast<size_t>(ChartSide::VMax)] = {knife.b, knife.bSide, againstA != knife.reversed};
    fan.sideCopy = {1, 3, 2, 3};  // VMin, UMax, VMax, UMin
    fan.cornerCopy = {1, 1, 2, 2};
    a.sides[static_cast<size_t>(knife.aSide)] = {static_cast<int>(id), ChartSide::VMin, againstA};
    b.sides[static_cast<size_t>(knife.bSide)] = {static_cast<int>(id), ChartSide::VMax,
                                                 againstA != knife.reversed};
    a.sideCopy[static_cast<size_t>(knife.aSide)] = 1;
    b.sideCopy[static_cast<size_t>(knife.bSide)] = 2;
    // The copies of the chain's vertices at a's and b's corners there.
    for (int end = 0; end < 2; ++end) {
      a.cornerCopy[static_cast<size_t>(sideEndCorner(knife.aSide, end))] = 1;
      b.cornerCopy[static_cast<size_t>(sideEndCorner(knife.bSide, end))] = 2;
    }
    for (const auto& [side, vertex] :
         {std::pair{ChartSide::UMin, chain.front()}, std::pair{ChartSide::UMax, chain.back()}}) {
      if (closes(knife, vertex)) {
        fan.collapsedSide[static_cast<size_t>(side)] = true;
      } else if (ends[vertex] == 2) {
        fanEnds[vertex].emplace_back(id, side);
      }  // else open: on the symmetry plane
    }
    patches.push_back(std::move(fan));
  }
  // Consecutive fans along a chain meet end to end; every fan runs from copy 1 to copy 2.
  for (const auto& [vertex, fans] : fanEnds) {
    if (fans.size() != 2) continue;
    for (int k = 0; k < 2; ++k) {
      const auto [fan, side] = fans[static_cast<size_t>(k)];
      const auto [other, otherSide] = fans[static_cast<size_t>(1 - k)];
      patches[fan].sides[static_cast<size_t>(side)] = {static_cast<int>(other), otherSide, false};
    }
  }
  std::set<int> closing;
  for (const Knife& knife : knives) {
    for (int vertex : {knife.from, knife.to}) {
      if (closes(knife, vertex)) closing.insert(vertex);
    }
  }
  spreadCornerCopies(patches, closing);
  // Corners where a chain closes are the vertex itself for every patch there.
  for (WallPatch& patch : patches) {
    for (int corner = 0; corner < 4; ++corner) {
      if (closing.count(cornerVertex(patch, corner)) != 0) patch.cornerCopy[static_cast<size_t>(corner)] = 0;
    }
  }
  return static_cast<int>(patches.size() - firstFan);
}

}  // namespace bvmesh::volume
