#include "core/common/atomic_file.h"

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

}  // namespace

void writeFileAtomicallyByPath(const std::string& path, const std::string& what,
                               const std::function<void(const std::string&)>& write) {
  if (path.empty()) throw InvalidInputError("no file name given for " + what);
  const std::string temporary = path + ".partial";
  try {
    write(temporary);
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
  moveIntoPlace(temporary, path, what);
}

void writeFileAtomically(const std::string& path, const std::string& what,
                         const std::function<void(std::ostream&)>& write) {
  writeFileAtomicallyByPath(path, what, [&](const std::string& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    if (!out) throw InvalidInputError("cannot write " + what + " \"" + path + "\" (its folder is missing or not writable)");
    write(out);
    out.flush();
    if (!out) throw InvalidInputError("writing " + what + " \"" + path + "\" failed (disk full?)");
  });
}

}  // namespace bvmesh
