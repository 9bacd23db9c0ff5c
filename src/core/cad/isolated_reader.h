// CAD files and BREP text from outside are parsed in a child process (the bvmesh-cad-reader
// executable) under a time and memory limit, so a file that crashes OCCT's readers (dangling STEP
// references), makes them loop (truncated BREP text, NaN coordinates) or exhausts memory costs
// the caller an error message, never its process or its unsaved FreeCAD document. The child
// sends the shape back as BREP text written by OCCT itself, which the caller then reads in
// process (trusted). Overhead: one process start (tens of milliseconds, docs/hostile_input.md).
#pragma once

#include <TopoDS_Shape.hxx>

#include <string>

#include "core/cad/shape_repair.h"

namespace bvmesh::cad {

struct ReaderLimits {
  double seconds = 300.0;          // wall-clock time of the child (CPU time is limited likewise)
  double memoryMegabytes = 8192.0; // address space of the child
};

// The reader executable: $BVMESH_CAD_READER if set, else the one the build puts beside the
// Python module (Mod/bvmesh/bvmesh-cad-reader).
std::string cadReaderExecutable();

// Reads a STEP / IGES / BREP file (as readShapeFile) in the child, repairs it there (sews its
// faces, repairShape: sewing is geometry work on input from outside, so it runs under the same
// limits) and returns the shape as BREP text, the repair report in *report when given. Throws
// InvalidInputError naming the file and what went wrong: the reader's own error, a crash (with
// the signal), the time or memory limit.
std::string readShapeFileIsolated(const std::string& path, const ReaderLimits& limits = {},
                                  const RepairOptions& repair = {}, RepairReport* report = nullptr);

// Limits for BREP text of `bytes`: OCCT parses it at tens of MB/s, so 10 s plus 5 s per MB stops a
// looping parse (truncated text) long before the file limit would.
ReaderLimits brepTextLimits(size_t bytes);

// Parses BREP text (as readBrepString) in the child and returns it as the child wrote it back;
// by default unsewn (the caller's face and edge numbering stays valid).
std::string checkBrepStringIsolated(const std::string& brep, const ReaderLimits& limits,
                                    const RepairOptions& repair = RepairOptions{false, 0.0},
                                    RepairReport* report = nullptr);

// The shapes themselves: the child's BREP text read back in process. Files are sewn, BREP text
// is not (see above).
TopoDS_Shape readShapeFileSafely(const std::string& path, const ReaderLimits& limits = {});
TopoDS_Shape readBrepStringSafely(const std::string& brep);
// ... with the repair report.
RepairedShape readShapeFileRepaired(const std::string& path, const RepairOptions& repair = {},
                                    const ReaderLimits& limits = {});
RepairedShape readBrepStringRepaired(const std::string& brep, const RepairOptions& repair = {});

// The child's side: reads `path` ("-": BREP text on stdin) under `limits`, repairs it and writes
// the repair report (between kRepairReportBegin and kRepairReportEnd lines) and then BREP text to
// stdout; returns the process exit code (0, or 1 with the error on stderr).
int runCadReader(const std::string& path, const ReaderLimits& limits, const RepairOptions& repair = {});

inline constexpr const char* kRepairReportBegin = "BVMESH-REPAIR-REPORT";
inline constexpr const char* kRepairReportEnd = "END-BVMESH-REPAIR-REPORT";

}  // namespace bvmesh::cad
