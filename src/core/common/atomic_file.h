// Files written so that a failure never leaves a partial file under the final name: the content
// goes to "<path>.partial", which is renamed onto the path only once it is complete.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace bvmesh {

// Calls write(stream) on a binary stream to the temporary file, then renames it into place.
// `what` names the file in errors ("the CGNS file"): InvalidInputError on an unwritable path or
// a failed write (the temporary is removed); exceptions from `write` propagate, also removing it.
// `complete`, when given, runs once the temporary is written and before the rename (files that
// belong with this one are moved into place with it).
void writeFileAtomically(const std::string& path, const std::string& what,
                         const std::function<void(std::ostream&)>& write,
                         const std::function<void()>& complete = nullptr);

// For writers that open the file themselves (a C library): call write(temporaryPath), then rename.
void writeFileAtomicallyByPath(const std::string& path, const std::string& what,
                               const std::function<void(const std::string&)>& write);

}  // namespace bvmesh
