#include "core/cad/shape_io.h"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <XSControl_WorkSession.hxx>
#include <STEPControl_Reader.hxx>
#include <XSControl_Reader.hxx>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/common/errors.h"
#include "core/common/occt_errors.h"

namespace bvmesh::cad {
namespace {

std::string lowerCaseExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// STEP and IGES share XSControl_Reader's transfer interface.
TopoDS_Shape readWithExchangeReader(XSControl_Reader& reader, const std::string& path,
                                    const char* format) {
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) {
    throw InvalidInputError("cannot read \"" + path + "\" as " + format + ": the file is corrupt or not " + format);
  }
  // Entities that failed to load (a reference to a missing entity, a wrong type): translating
  // them would crash OCCT's transfer, so stop here and say which.
  const Interface_CheckIterator checks = reader.WS()->ModelCheckList();
  std::string failures;
  int failed = 0;
  for (checks.Start(); checks.More(); checks.Next()) {
    const Handle(Interface_Check)& check = checks.Value();
    if (!check->HasFailed()) continue;
    if (++failed <= 3) {
      failures += std::string(failures.empty() ? "" : "; ") + "entity #" + std::to_string(checks.Number()) + ": " +
                  check->CFail(1);
    }
  }
  if (failed > 0) {
    throw InvalidInputError("\"" + path + "\" is a corrupt " + format + " file: " + std::to_string(failed) +
                            " entities failed to load (" + failures + (failed > 3 ? "; ..." : "") + ")");
  }
  if (reader.TransferRoots() == 0) {
    throw InvalidInputError("\"" + path + "\" holds no shape that can be transferred from " + format);
  }
  TopoDS_Shape shape = reader.OneShape();
  if (shape.IsNull()) throw InvalidInputError("\"" + path + "\" holds no shape");
  return shape;
}

}  // namespace

TopoDS_Shape readBrepString(const std::string& brep) {
  if (brep.find_first_not_of(" \t\r\n") == std::string::npos) {
    throw InvalidInputError("BREP text is empty");
  }
  return translateOcctErrors("reading BREP text", [&] {
    std::istringstream stream(brep);
    TopoDS_Shape shape;
    BRep_Builder builder;
    BRepTools::Read(shape, stream, builder);
    if (shape.IsNull()) {
      throw InvalidInputError("BREP text is corrupt or truncated: OpenCASCADE read no shape from it (BREP "
                              "text starts with \"CASCADE Topology\" or \"DBRep_DrawableShape\" and ends with "
                              "the shape's own record)");
    }
    return shape;
  });
}

std::string writeBrepString(const TopoDS_Shape& shape) {
  if (shape.IsNull()) throw InvalidInputError("cannot write a null shape as BREP");
  return translateOcctErrors("writing BREP text", [&] {
    std::ostringstream stream;
    BRepTools::Write(shape, stream);
    return stream.str();
  });
}

TopoDS_Shape readShapeFile(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InvalidInputError("CAD file \"" + path + "\" does not exist or is not a file");
  }
  if (!std::ifstream(path).good()) throw InvalidInputError("CAD file \"" + path + "\" cannot be opened");

  const std::string extension = lowerCaseExtension(path);
  return translateOcctErrors("reading \"" + path + "\"", [&] {
    if (extension == ".step" || extension == ".stp") {
      STEPControl_Reader reader;
      return readWithExchangeReader(reader, path, "STEP");
    }
    if (extension == ".iges" || extension == ".igs") {
      IGESControl_Reader reader;
      return readWithExchangeReader(reader, path, "IGES");
    }
    if (extension == ".brep" || extension == ".brp") {
      std::ifstream file(path);
      std::stringstream text;
      text << file.rdbuf();
      return readBrepString(text.str());
    }
    throw InvalidInputError("CAD file \"" + path + "\" has extension \"" + extension +
                            "\"; expected .step, .stp, .iges, .igs, .brep or .brp");
  });
}

}  // namespace bvmesh::cad
