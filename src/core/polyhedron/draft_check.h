// The check a template's placed polyhedron passes before it becomes a ControlMesh: a template
// never hands on an invalid mesh. When vertices of a face coincide or a face has no area, the
// placement stops with an error that names the template, the face, its vertices and what about
// the target likely caused it (the capsule on a hemisphere-cylinder read unsewn took its plane
// faces' outlines for a symmetry plane, and snapping onto it collapsed face 8). Before that, a
// target without volume (flat, or a line) stops the placement with that reason.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

#include "core/polyhedron/target_analysis.h"
#include "core/target/target.h"

namespace bvmesh::polyhedron {

// "template '<name>' cannot be placed on this target: <what>; <what about the target likely
// caused it>" (its free edges, unsewn faces, gaps left open).
std::string placementFailure(const std::string& templateName, const std::string& what, const target::Target& target);

// Throws InvalidInputError "template '<name>' cannot be placed on this target: the target is flat
// ..." (or "... is a line ...") when the target's extent across its principal axes is within its
// gap tolerance: every template encloses a body, and laid on a plate its faces would collapse.
// frame: principalFrame(target).
void checkTargetHasVolume(const std::string& templateName, const PrincipalFrame& frame, const target::Target& target);

// Throws InvalidInputError "template '<name>' cannot be placed on this target: it is 2 separate
// bodies ..." when a watertight target's faces fall apart into groups that share no edge (two
// spheres in one file): a template encloses one body, and stretched over two it fits neither. A
// target with free edges is not judged (faces read unsewn share no edges either).
void checkTargetIsOneBody(const std::string& templateName, const target::Target& target);

// Throws InvalidInputError "template '<name>' cannot be placed on this target: it has 1 hole
// through it (genus 1 ...)" when a watertight, manifold target's genus (holes through the body,
// from its faces' Euler characteristic) differs from the template's (templateGenus: 1 for a
// ring, 0 for the others): a cylinder wrapped round a tube stagnated 9 % of its length from it,
// and the volume then folded. Other targets are not judged.
void checkTargetGenus(const std::string& templateName, int templateGenus, const target::Target& target);

// Throws InvalidInputError "template '<name>' cannot be placed on this target: it is open on a
// plane ..." when the target is a half model (detectSymmetryPlane finds its plane) and the
// template wraps a closed body only (box, sphere): a cube-sphere fitted over a dome open at its
// equator folded its lower half onto the rim and the volume stage refused the closed wall.
void checkNotAHalfModel(const std::string& templateName, const target::Target& target,
                        const std::vector<FeatureCurve>& curves);

// Throws InvalidInputError when two corners map to the same target vertex (vertexCadVertex: per
// mesh vertex, -1 for none): improving moves both onto it, and the faces or crease chain between
// them collapse. Named in terms of the target: "it has 2 vertices for the template's 8 corners:
// corners 0 and 5 would both sit on its vertex 1 at (0.1, 0, 0)".
void checkCornersOnDistinctVertices(const std::string& templateName, const std::vector<int>& vertexCadVertex,
                                    const target::Target& target);

// vertices: the draft's points; faces: vertex indices per face. Throws InvalidInputError.
void checkPlacedFaces(const std::string& templateName, const std::vector<Eigen::Vector3d>& vertices,
                      const std::vector<std::vector<int>>& faces, const target::Target& target);

}  // namespace bvmesh::polyhedron
