#include "core/cad/shape_io.h"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESControl_Writer.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IGESData_IGESModel.hxx>
#include <IGESToBRep.hxx>
#include <Interface_EntityIterator.hxx>
#include <Interface_Graph.hxx>
#include <TopExp_Explorer.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <XSControl_WorkSession.hxx>
#include <STEPControl_Reader.hxx>
#include <XSControl_Reader.hxx>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/cad/step_scan.h"
#include "core/common/errors.h"
#include "core/common/occt_errors.h"

namespace bvmesh::cad {

std::string lowerCaseExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

namespace {

bool hasFace(const TopoDS_Shape& shape) {
  return !shape.IsNull() && TopExp_Explorer(shape, TopAbs_FACE).More();
}

// OCCT takes as IGES roots only entities that no other entity references (and that its actor
// recognizes). Surfaces that are members of an associativity OCCT does not transfer (402 form 9,
// single parent, as some writers group untrimmed 128 patches) are no roots then, and the file
// reads as empty (FreeCAD's Part.read gives a null shape). Transfers every surface entity that
// no transferable curve, surface or B-rep entity uses (those come with their user) and says so
// in `note`; returns how many were transferred.
int transferUnrootedIgesSurfaces(IGESControl_Reader& reader, std::string& note) {
  const Handle(IGESData_IGESModel) model = reader.IGESModel();
  if (model.IsNull()) return 0;
  const Interface_Graph& graph = reader.WS()->Graph();
  std::map<std::string, int> users;  // "402 form 9" -> surfaces it held
  int transferred = 0;
  int candidates = 0;
  for (int i = 1; i <= model->NbEntities(); ++i) {
    const Handle(IGESData_IGESEntity) entity = model->Entity(i);
    if (entity.IsNull() || !(IGESToBRep::IsBasicSurface(entity) || IGESToBRep::IsTopoSurface(entity))) continue;
    bool usedByTransferable = false;
    std::string user;
    for (Interface_EntityIterator it = graph.Sharings(entity); it.More(); it.Next()) {
      const Handle(IGESData_IGESEntity) other = Handle(IGESData_IGESEntity)::DownCast(it.Value());
      if (other.IsNull()) continue;
      if (IGESToBRep::IsCurveAndSurface(other) || IGESToBRep::IsBRepEntity(other)) usedByTransferable = true;
      user = std::to_string(other->TypeNumber()) + " form " + std::to_string(other->FormNumber());
    }
    if (usedByTransferable) continue;
    ++candidates;
    if (!user.empty()) ++users[user];
    if (reader.TransferEntity(entity)) ++transferred;
  }
  if (transferred > 0) {
    std::string held;
    for (const auto& [name, count] : users) held += std::string(held.empty() ? "" : ", ") + name + " (" + std::to_string(count) + ")";
    note = "IGES: no root entity gave a face (OpenCASCADE transfers only entities no other entity references" +
           (held.empty() ? std::string() : "; the surfaces are members of entity " + held) + "): " +
           std::to_string(transferred) + " of " + std::to_string(candidates) + " surface entities read directly";
  }
  return transferred;
}

// STEP and IGES share XSControl_Reader's transfer interface; `iges` is the same reader when the
// file is IGES.
TopoDS_Shape readWithExchangeReader(XSControl_Reader& reader, const std::string& path, const char* format,
                                    IGESControl_Reader* iges, std::vector<std::string>* notes) {
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
  const int roots = reader.TransferRoots();
  if (iges != nullptr && (roots == 0 || !hasFace(reader.OneShape()))) {
    std::string note;
    if (transferUnrootedIgesSurfaces(*iges, note) > 0 && notes != nullptr) notes->push_back(note);
  }
  if (reader.NbShapes() == 0) {
    throw InvalidInputError("\"" + path + "\" holds no shape that can be transferred from " + format +
                            (iges != nullptr ? " (no root entity, and no surface entity that could be read directly)" : ""));
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

TopoDS_Shape readShapeFile(const std::string& path, std::vector<std::string>* notes) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InvalidInputError("CAD file \"" + path + "\" does not exist or is not a file");
  }
  if (!std::ifstream(path).good()) throw InvalidInputError("CAD file \"" + path + "\" cannot be opened");

  const std::string extension = lowerCaseExtension(path);
  return translateOcctErrors("reading \"" + path + "\"", [&] {
    if (extension == ".step" || extension == ".stp") {
      checkStepLists(path);  // OCCT's parser is quadratic in a list's length
      STEPControl_Reader reader;
      return readWithExchangeReader(reader, path, "STEP", nullptr, notes);
    }
    if (extension == ".iges" || extension == ".igs") {
      IGESControl_Reader reader;
      return readWithExchangeReader(reader, path, "IGES", &reader, notes);
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

void writeIgesFaces(const TopoDS_Shape& shape, const std::string& path) {
  if (shape.IsNull() || !hasFace(shape)) throw InvalidInputError("cannot write \"" + path + "\": the shape has no face");
  translateOcctErrors("writing \"" + path + "\"", [&] {
    IGESControl_Writer writer("MM", 0);  // mode 0: faces, no B-rep topology
    for (TopExp_Explorer face(shape, TopAbs_FACE); face.More(); face.Next()) writer.AddShape(face.Current());
    writer.ComputeModel();
    if (!writer.Write(path.c_str())) throw SolverError("cannot write the IGES file \"" + path + "\"");
  });
}

}  // namespace bvmesh::cad
