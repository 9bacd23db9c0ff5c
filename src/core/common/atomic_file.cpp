#include "core/common/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>

#include "core/common/errors.h"

namespace bvmesh {
namespace {

void moveIntoPlace(const std::string& temporary, const std::string& path, const std::string& what) {
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::remove(temporary.c_str());
    throw InvalidInputError("cannot move " + what + " into place at \"" + path + "\"");
  }
}

// The temporary is made afresh and exclusively under its predictable name: a stale one (from a
// write that crashed) or a link planted there is removed, never followed (the link's target would
// be overwritten); a folder in the way stays, and the write fails.
void createTemporary(const std::string& temporary, const std::string& path, const std::string& what) {
  struct stat status {};
  if (::lstat(temporary.c_str(), &status) == 0 && !S_ISDIR(status.st_mode)) ::unlink(temporary.c_str());
  const int descriptor =
      ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (descriptor < 0) {
    throw InvalidInputError("cannot write " + what + " \"" + path +
                            "\" (its folder is missing or not writable, or \"" + temporary +
                            "\" is in the way)");
  }
  ::close(descriptor);
}

}  // namespace

void writeFileAtomicallyByPath(const std::string& path, const std::string& what,
                               const std::function<void(const std::string&)>& write) {
  if (path.empty()) throw InvalidInputError("no file name given for " + what);
  const std::string temporary = path + ".partial";
  createTemporary(temporary, path, what);
  try {
    write(temporary);
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
  moveIntoPlace(temporary, path, what);
}

void writeFileAtomically(const std::string& path, const std::string& what,
                         const std::function<void(std::ostream&)>& write,
                         const std::function<void()>& complete) {
  writeFileAtomicallyByPath(path, what, [&](const std::string& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    if (!out) throw InvalidInputError("cannot write " + what + " \"" + path + "\" (its folder is missing or not writable)");
    write(out);
    out.flush();
    if (!out) throw InvalidInputError("writing " + what + " \"" + path + "\" failed (disk full?)");
    if (complete) complete();
  });
}

}  // namespace bvmesh
