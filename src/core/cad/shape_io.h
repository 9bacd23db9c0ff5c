// Reading and writing CAD shapes: BREP text (what FreeCAD's Shape.exportBrepToString() gives
// and importBrepFromString() takes) and STEP / IGES / BREP files.
#pragma once

#include <TopoDS_Shape.hxx>

#include <string>
#include <vector>

namespace bvmesh::cad {

// Parses BREP text. Throws InvalidInputError for empty or corrupt text and for a null shape.
TopoDS_Shape readBrepString(const std::string& brep);

// Writes a shape as BREP text. Throws InvalidInputError for a null shape.
std::string writeBrepString(const TopoDS_Shape& shape);

// Reads a STEP (.step/.stp), IGES (.iges/.igs) or BREP (.brep/.brp) file, chosen by its extension
// (case-insensitive). Throws InvalidInputError naming the file when it is missing, unreadable,
// of another format, or holds no shape. `notes` (optional) gets what the reader did besides the
// plain transfer (IGES surfaces read directly when no root entity gives a face).
TopoDS_Shape readShapeFile(const std::string& path, std::vector<std::string>* notes = nullptr);

// The file's extension in lower case, with its dot (".stp"), or "" (readShapeFile's choice of format).
std::string lowerCaseExtension(const std::string& path);

// Writes the faces of `shape` to an IGES file as many design tools do: each face an entity of its
// own (OCCT's faces mode: trimmed surface 144 over its surface), no shared edges or topology.
// Throws InvalidInputError for a shape without faces and SolverError when the file cannot be written.
void writeIgesFaces(const TopoDS_Shape& shape, const std::string& path);

}  // namespace bvmesh::cad
