// Opening a file the user named for reading. Only a regular file is read: a folder opens as a
// stream that reads nothing (reported as a file that "ends early"), and a device or a pipe
// (/dev/zero, a FIFO) may never end, so a reader would hang or fill the memory.
#pragma once

#include <fstream>
#include <string>

namespace bvmesh {

// The file at `path` opened for reading; `what` names it in errors ("the block mesh file").
// Throws InvalidInputError when it does not exist, is a folder or not a regular file, or cannot
// be opened.
std::ifstream openInputFile(const std::string& path, const std::string& what,
                            std::ios::openmode mode = std::ios::in);

}  // namespace bvmesh
