#include "core/common/input_file.h"

#include <filesystem>

#include "core/common/errors.h"

namespace bvmesh {

std::ifstream openInputFile(const std::string& path, const std::string& what, std::ios::openmode mode) {
  const std::string named = what + " \"" + path + "\"";
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) {
    throw InvalidInputError("cannot open " + named + ": it does not exist");
  }
  if (error) throw InvalidInputError("cannot open " + named + ": " + error.message());  // a folder on the way not readable
  if (std::filesystem::is_directory(status)) {
    throw InvalidInputError("cannot open " + named + ": it is a folder, not a file");
  }
  if (!std::filesystem::is_regular_file(status)) {
    throw InvalidInputError("cannot open " + named + ": it is not a regular file (a device, a pipe or a socket)");
  }
  std::ifstream in(path, mode);
  if (!in) throw InvalidInputError("cannot open " + named + " (no permission to read it)");
  return in;
}

}  // namespace bvmesh
