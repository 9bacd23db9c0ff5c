// Reading and writing CAD shapes: BREP text (what FreeCAD's Shape.exportBrepToString() gives
// and importBrepFromString() takes) and STEP / IGES / BREP files.
#pragma once

#include <TopoDS_Shape.hxx>

#include <string>

namespace bvmesh::cad {

// Parses BREP text. Throws InvalidInputError for empty or corrupt text and for a null shape.
TopoDS_Shape readBrepString(const std::string& brep);

// Writes a shape as BREP text. Throws InvalidInputError for a null shape.
std::string writeBrepString(const TopoDS_Shape& shape);

// Reads a STEP (.step/.stp), IGES (.iges/.igs) or BREP (.brep/.brp) file, chosen by its extension
// (case-insensitive). Throws InvalidInputError naming the file when it is missing, unreadable,
// of another format, or holds no shape.
TopoDS_Shape readShapeFile(const std::string& path);

}  // namespace bvmesh::cad
