#include "core/volume/edge_fans.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>

#include "core/common/bspline_basis.h"
#include "core/common/math_constants.h"

namespace bvmesh::volume {
namespace {

// Corner index (0, 0) = 0, (U, 0) = 1, (0, V) = 2, (U, V) = 3 of entry `end` (0: first, 1: last)
// along a side.
int cornerOf(ChartSide side, int end) {
  switch (side) {
    case ChartSide::VMin:
      return end;
    case ChartSide::UMax:
      return 1 + 2 * end;
    case ChartSide::VMax:
      return 2 + end;
    case ChartSide::UMin:
      return 2 * end;
  }
  return 0;
}

// A patch's quads run along its side in increasing entry order on VMin and UMax, decreasing on
// VMax and UMin (counter-clockwise round each quad).
bool runsForward(ChartSide side) { return side == ChartSide::VMin || side == ChartSide::UMax; }

Eigen::Vector3d sideNormal(const WallPatch& patch, ChartSide side, int t) {
  const auto [i, j] = sidePolePosition(patch, side, t);
  const std::vector<double> gu = grevilleAbscissae(patch.surface.uKnots, 3);
  const std::vector<double> gv = grevilleAbscissae(patch.surface.vKnots, 3);
  Eigen::Vector3d normal;
  patch.surface.point(gu[static_cast<size_t>(i)], gv[static_cast<size_t>(j)], &normal);
  return normal;
}

// A knife edge between patch `a` side `aSide` and patch `b` side `bSide`, from vertex `from` to
// vertex `to` along its chain; `a` is the face whose quads run along it from `from` to `to`.
struct Knife {
  int a = -1, b = -1;
  ChartSide aSide = ChartSide::VMin, bSide = ChartSide::VMin;
  bool reversed = false;  // b's entries run against a's
  int from = -1, to = -1;
};

bool isKnife(const std::vector<WallPatch>& patches, int p, ChartSide side) {
  const WallPatch& patch = patches[static_cast<size_t>(p)];
  const PatchSideLink& link = patch.sides[static_cast<size_t>(side)];
  if (link.patch < 0 || !patch.creaseSide[static_cast<size_t>(side)]) return false;
  const WallPatch& other = patches[static_cast<size_t>(link.patch)];
  const int length = sidePoleCount(patch, side);
  const double knife = std::cos(kKnifeEdgeDegrees * kPi / 180.0);
  for (int t = 1; t + 1 < length; ++t) {
    const int theirs = link.reversed ? length - 1 - t : t;
    if (sideNormal(patch, side, t).dot(sideNormal(other, link.side, theirs)) > knife) return false;
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

}  // namespace

int insertEdgeFans(std::vector<WallPatch>& patches, int fanSpans) {
  const std::vector<Knife> knives = orientedKnives(patches);
  if (knives.empty()) return 0;
  std::map<int, int> ends;  // vertex -> knife ends there
  for (const Knife& knife : knives) {
    ++ends[knife.from];
    ++ends[knife.to];
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
    fan.surface.vKnots = uniformClampedKnots(3, fanSpans);
    fan.surface.uPoles = length;
    fan.surface.vPoles = fanSpans + 3;
    for (int i = 0; i < length; ++i) {
      const auto [ia, ja] = sidePolePosition(a, knife.aSide, againstA ? length - 1 - i : i);
      fan.surface.poles.insert(fan.surface.poles.end(), static_cast<size_t>(fan.surface.vPoles),
                               a.surface.pole(ia, ja));
    }
    std::vector<int> chain = a.sideVertices[static_cast<size_t>(knife.aSide)];
    if (againstA) std::reverse(chain.begin(), chain.end());
    fan.sideVertices[static_cast<size_t>(ChartSide::VMin)] = chain;
    fan.sideVertices[static_cast<size_t>(ChartSide::VMax)] = chain;
    fan.sideVertices[static_cast<size_t>(ChartSide::UMin)].assign(static_cast<size_t>(fanSpans + 1),
                                                                  chain.front());
    fan.sideVertices[static_cast<size_t>(ChartSide::UMax)].assign(static_cast<size_t>(fanSpans + 1),
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
      a.cornerCopy[static_cast<size_t>(cornerOf(knife.aSide, end))] = 1;
      b.cornerCopy[static_cast<size_t>(cornerOf(knife.bSide, end))] = 2;
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
  // Corners where a chain closes are the vertex itself for every patch there.
  for (const Knife& knife : knives) {
    for (int vertex : {knife.from, knife.to}) {
      if (!closes(knife, vertex)) continue;
      for (WallPatch& patch : patches) {
        for (int corner = 0; corner < 4; ++corner) {
          const ChartSide side = corner < 2 ? ChartSide::VMin : ChartSide::VMax;
          const std::vector<int>& chain = patch.sideVertices[static_cast<size_t>(side)];
          if ((corner % 2 == 0 ? chain.front() : chain.back()) == vertex)
            patch.cornerCopy[static_cast<size_t>(corner)] = 0;
        }
      }
    }
  }
  return static_cast<int>(patches.size() - firstFan);
}

}  // namespace bvmesh::volume
