#include "core/cad/isolated_reader.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <iterator>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include "core/cad/shape_io.h"
#include "core/common/errors.h"
#include "core/common/number_text.h"

extern char** environ;

namespace bvmesh::cad {
namespace {

void checkLimits(const ReaderLimits& limits) {
  if (!(limits.seconds > 0.0 && std::isfinite(limits.seconds)) ||
      !(limits.memoryMegabytes >= 64.0 && std::isfinite(limits.memoryMegabytes))) {
    throw InvalidInputError("CAD reader limits must be a positive time and at least 64 MB of memory (got " +
                            numberText(limits.seconds) + " s, " + std::to_string(limits.memoryMegabytes) +
                            " MB)");
  }
}

// Closes a file descriptor once.
struct Descriptor {
  int fd = -1;
  ~Descriptor() { close(); }
  void close() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
};

// The child's line on stderr once the file is read (before sewing).
constexpr const char* kReadDoneMarker = "bvmesh-cad-reader: read";

struct ChildResult {
  int status = 0;
  bool timedOut = false;
  bool readDone = false;  // the child got past reading (kReadDoneMarker), so any failure was in sewing
  std::string out, err;
};

// Takes the marker out of the child's stderr (what is left is its error message).
void takeMarker(ChildResult& result) {
  const std::string marker = std::string(kReadDoneMarker) + "\n";
  const size_t at = result.err.find(marker);
  if (at == std::string::npos) return;
  result.readDone = true;
  result.err.erase(at, marker.size());
}

bool succeeded(const ChildResult& result) {
  return !result.timedOut && WIFEXITED(result.status) && WEXITSTATUS(result.status) == 0 && !result.out.empty();
}



// Runs the reader on `argument` with `input` on its stdin; collects stdout and stderr until it
// exits or the wall-clock limit passes (then it is killed).
ChildResult runChild(const std::string& argument, const std::string& input, const ReaderLimits& limits,
                     const RepairOptions& repair) {
  const std::string executable = cadReaderExecutable();
  if (access(executable.c_str(), X_OK) != 0) {
    throw SolverError("the CAD reader \"" + executable + "\" is missing or not executable (build the project, or set "
                      "BVMESH_CAD_READER)");
  }
  int in[2], out[2], err[2];
  if (pipe2(in, O_CLOEXEC) != 0 || pipe2(out, O_CLOEXEC) != 0 || pipe2(err, O_CLOEXEC) != 0) {
    throw SolverError(std::string("cannot start the CAD reader: ") + std::strerror(errno));
  }
  Descriptor toChild{in[1]}, fromChild{out[0]}, errorsFromChild{err[0]};
  Descriptor childIn{in[0]}, childOut{out[1]}, childErr{err[1]};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in[0], 0);
  posix_spawn_file_actions_adddup2(&actions, out[1], 1);
  posix_spawn_file_actions_adddup2(&actions, err[1], 2);
  const std::string seconds = std::to_string(limits.seconds);
  const std::string megabytes = std::to_string(limits.memoryMegabytes);
  std::ostringstream sew;
  sew.precision(17);
  if (repair.sew) sew << repair.tolerance;
  else sew << "off";
  std::vector<std::string> words{executable, "--seconds", seconds, "--megabytes", megabytes, "--sew", sew.str(), "--",
                                 argument};
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, executable.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw SolverError("cannot start the CAD reader \"" + executable + "\": " + std::strerror(spawned));
  childIn.close();
  childOut.close();
  childErr.close();
  fcntl(toChild.fd, F_SETFL, O_NONBLOCK);
  if (input.empty()) toChild.close();

  ChildResult result;
  size_t written = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(limits.seconds + 5.0);
  char buffer[65536];
  while (fromChild.fd >= 0 || errorsFromChild.fd >= 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      result.timedOut = true;
      kill(pid, SIGKILL);
      break;
    }
    pollfd fds[3];
    nfds_t count = 0;
    for (Descriptor* d : {&fromChild, &errorsFromChild}) {
      if (d->fd >= 0) fds[count++] = {d->fd, POLLIN, 0};
    }
    if (toChild.fd >= 0) fds[count++] = {toChild.fd, POLLOUT, 0};
    if (poll(fds, count, static_cast<int>(std::min<long long>(left.count(), 1000))) < 0 && errno != EINTR) break;
    for (nfds_t f = 0; f < count; ++f) {
      if (fds[f].revents == 0) continue;
      if (fds[f].fd == toChild.fd) {
        const ssize_t n = write(toChild.fd, input.data() + written, input.size() - written);
        if (n > 0) written += static_cast<size_t>(n);
        if (n < 0 && errno != EAGAIN) toChild.close();  // the child stopped reading
        if (written == input.size()) toChild.close();
        continue;
      }
      Descriptor& source = fds[f].fd == fromChild.fd ? fromChild : errorsFromChild;
      const ssize_t n = read(source.fd, buffer, sizeof(buffer));
      if (n > 0) (&source == &fromChild ? result.out : result.err).append(buffer, static_cast<size_t>(n));
      else if (n == 0 || errno != EINTR) source.close();
    }
  }
  toChild.close();
  while (waitpid(pid, &result.status, 0) < 0 && errno == EINTR) {
  }
  takeMarker(result);
  return result;
}

// What a crash of OCCT's reader says about the input: the likely cause where one is known.
std::string crashCause(const std::string& path) {
  if (path == "-") return "the BREP text is corrupt (cut short or edited)";
  const std::string extension = lowerCaseExtension(path);
  if (extension == ".stp" || extension == ".step")
    return "the file is corrupt (for STEP: a reference to a missing or wrong entity)";
  return "the file is corrupt";
}

// path: the child's argument, "-" for BREP text on stdin; what: the input as messages name it.
std::string outcome(const ChildResult& result, const std::string& path, const std::string& what,
                    const ReaderLimits& limits) {
  if (result.timedOut) {
    throw InvalidInputError(
        "reading " + what + " took longer than the limit of " + numberText(limits.seconds) +
        " s and was stopped (the file may be corrupt; OCCT's readers loop on some broken input)");
  }
  if (WIFSIGNALED(result.status)) {
    const int signal = WTERMSIG(result.status);
    if (signal == SIGXCPU || signal == SIGKILL) {
      throw InvalidInputError("reading " + what + " used up the CPU-time limit of " +
                              numberText(limits.seconds) + " s and was stopped (the file may be corrupt)");
    }
    throw InvalidInputError("reading " + what + " crashed OpenCASCADE's reader (" + strsignal(signal) + "); " +
                            crashCause(path) +
                            (result.err.empty() ? "" : ": " + result.err));
  }
  const int code = WIFEXITED(result.status) ? WEXITSTATUS(result.status) : -1;
  std::string message = result.err;
  while (!message.empty() && (message.back() == '\n' || message.back() == '\r')) message.pop_back();
  if (code != 0) {
    if (message.find("bad_alloc") != std::string::npos || message.find("memory") != std::string::npos) {
      throw InvalidInputError("reading " + what + " needed more than the memory limit of " +
                              std::to_string(limits.memoryMegabytes) + " MB");
    }
    throw InvalidInputError(message.empty() ? "reading " + what + " failed (CAD reader exit code " + std::to_string(code) + ")"
                                            : message);
  }
  if (result.out.empty()) throw InvalidInputError("reading " + what + " gave no shape");
  return result.out;
}

// The child's stdout: the repair report, then the BREP text.
std::string splitReport(const std::string& out, RepairReport* report) {
  const std::string begin = std::string(kRepairReportBegin) + "\n";
  const std::string end = std::string(kRepairReportEnd) + "\n";
  // OCCT's readers print progress to stdout before it (IGES: "Total number of loaded entities").
  size_t start = out.compare(0, begin.size(), begin) == 0 ? 0 : out.find("\n" + begin);
  if (start == std::string::npos) throw SolverError("the CAD reader sent no repair report");
  if (out[start] == '\n') ++start;
  const size_t stop = out.find(end, start + begin.size());
  if (stop == std::string::npos) throw SolverError("the CAD reader's repair report is cut short");
  if (report != nullptr) *report = decodeRepairReport(out.substr(start + begin.size(), stop - start - begin.size()));
  return out.substr(stop + end.size());
}

void applyLimits(const ReaderLimits& limits) {
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  // (Address- and ThreadSanitizer builds reserve terabytes of shadow address space: no
  // address-space limit.)
  const auto bytes = static_cast<rlim_t>(limits.memoryMegabytes * 1048576.0);
  const rlimit memory{bytes, bytes};
  setrlimit(RLIMIT_AS, &memory);
#endif
  const auto cpu = static_cast<rlim_t>(std::ceil(limits.seconds));
  const rlimit time{cpu, cpu + 1};
  setrlimit(RLIMIT_CPU, &time);
}

}  // namespace

std::string cadReaderExecutable() {
  const char* chosen = std::getenv("BVMESH_CAD_READER");
  if (chosen != nullptr && *chosen != '\0') return chosen;
  return BVMESH_CAD_READER_DEFAULT;
}

namespace {

// Runs the child; when it read the input but failed while sewing (a crash, the time or memory
// limit), runs it again without sewing so the faces as read still arrive, with a note saying why.
std::string runRepairing(const std::string& argument, const std::string& input, const ReaderLimits& limits,
                         const RepairOptions& repair, const std::string& what, RepairReport* report) {
  ChildResult result = runChild(argument, input, limits, repair);
  if (repair.sew && result.readDone && !succeeded(result)) {
    std::string why;
    try {
      outcome(result, argument, what, limits);
      why = "it gave no shape";
    } catch (const std::exception& error) {
      why = error.what();
    }
    std::string brep =
        splitReport(outcome(runChild(argument, input, limits, RepairOptions{false, 0.0}), argument, what, limits), report);
    if (report != nullptr) report->notes.push_back("sewing failed in the reader process, the faces are kept as read: " + why);
    return brep;
  }
  return splitReport(outcome(result, argument, what, limits), report);
}

void checkRepair(const RepairOptions& repair) {
  if (!(repair.tolerance >= 0.0) || !std::isfinite(repair.tolerance))
    throw InvalidInputError("the sewing tolerance must be 0 (automatic) or positive, got " +
                            numberText(repair.tolerance));
}

}  // namespace

std::string readShapeFileIsolated(const std::string& path, const ReaderLimits& limits, const RepairOptions& repair,
                                  RepairReport* report) {
  checkLimits(limits);
  checkRepair(repair);
  if (path.empty() || path[0] == '-') {
    // Never let a path be taken for an option of the reader.
    return readShapeFileIsolated("./" + path, limits, repair, report);
  }
  return runRepairing(path, "", limits, repair, "\"" + path + "\"", report);
}

std::string checkBrepStringIsolated(const std::string& brep, const ReaderLimits& limits, const RepairOptions& repair,
                                    RepairReport* report) {
  checkLimits(limits);
  checkRepair(repair);
  if (brep.find_first_not_of(" \t\r\n") == std::string::npos) throw InvalidInputError("BREP text is empty");
  return runRepairing("-", brep, limits, repair, "BREP text", report);
}

TopoDS_Shape readShapeFileSafely(const std::string& path, const ReaderLimits& limits) {
  return readBrepString(readShapeFileIsolated(path, limits));
}

RepairedShape readShapeFileRepaired(const std::string& path, const RepairOptions& repair, const ReaderLimits& limits) {
  RepairedShape result;
  result.shape = readBrepString(readShapeFileIsolated(path, limits, repair, &result.report));
  return result;
}

RepairedShape readBrepStringRepaired(const std::string& brep, const RepairOptions& repair) {
  RepairedShape result;
  result.shape = readBrepString(checkBrepStringIsolated(brep, brepTextLimits(brep.size()), repair, &result.report));
  return result;
}

ReaderLimits brepTextLimits(size_t bytes) {
  ReaderLimits limits;
  limits.seconds = 10.0 + 5.0 * static_cast<double>(bytes) / 1048576.0;
  return limits;
}

TopoDS_Shape readBrepStringSafely(const std::string& brep) {
  return readBrepString(checkBrepStringIsolated(brep, brepTextLimits(brep.size())));
}

int runCadReader(const std::string& path, const ReaderLimits& limits, const RepairOptions& repair) {
  applyLimits(limits);
  try {
    TopoDS_Shape shape;
    std::vector<std::string> notes;
    if (path == "-") {
      std::string text((std::istreambuf_iterator<char>(std::cin)), std::istreambuf_iterator<char>());
      shape = readBrepString(text);
    } else {
      shape = readShapeFile(path, &notes);
    }
    // From here on the file is read: the parent retries without sewing if sewing crashes or hangs.
    std::cerr << kReadDoneMarker << std::endl;
    RepairedShape repaired;
    try {
      repaired = repairShape(shape, repair);
    } catch (const std::exception& error) {
      // Faces that cannot be sewn still make a target: the shape as read, with the reason.
      repaired = repairShape(shape, RepairOptions{false, repair.tolerance});
      notes.push_back(std::string("sewing failed, the faces are kept as read: ") + error.what());
    }
    repaired.report.notes.insert(repaired.report.notes.begin(), notes.begin(), notes.end());
    const std::string brep = writeBrepString(repaired.shape);
    std::cout << "\n" << kRepairReportBegin << "\n" << encodeRepairReport(repaired.report) << kRepairReportEnd << "\n" << brep;
    std::cout.flush();
    return std::cout ? 0 : 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "std::bad_alloc: out of memory\n";
  } catch (const std::exception& error) {
    std::cerr << error.what() << "\n";
  }
  return 1;
}

}  // namespace bvmesh::cad
