#include "core/cad/step_scan.h"

#include <fstream>
#include <vector>

#include "core/common/errors.h"

namespace bvmesh::cad {
namespace {

struct OpenList {
  std::int64_t commas = 0;
  bool empty = true;
};

}  // namespace

void checkStepLists(const std::string& path, const StepListLimits& limits) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InvalidInputError("CAD file \"" + path + "\" cannot be opened");
  const auto where = [&](std::int64_t entity, std::int64_t line) {
    return (entity >= 0 ? "entity #" + std::to_string(entity) + " (line " : "line ") + std::to_string(line) +
           (entity >= 0 ? ")" : "");
  };
  std::vector<OpenList> open;
  std::int64_t line = 1, entity = -1, entityLine = 1;
  bool inString = false, quote = false;    // quote: a ' inside a string, '' if another follows
  bool inComment = false, slash = false, star = false;
  bool inNumber = false;                   // reading the digits of #N at depth 0
  std::vector<char> buffer(1 << 20);
  while (file) {
    file.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const std::streamsize count = file.gcount();
    for (std::streamsize i = 0; i < count; ++i) {
      const char c = buffer[static_cast<size_t>(i)];
      if (c == '\n') ++line;
      if (inComment) {
        if (star && c == '/') inComment = false;
        star = c == '*';
        continue;
      }
      if (inString) {
        if (quote) {
          quote = false;
          if (c == '\'') continue;  // '' is a quote within the string
          inString = false;          // the string ended at the previous quote: c is outside it
        } else {
          if (c == '\'') quote = true;
          continue;
        }
      }
      if (slash && c == '*') {
        inComment = true;
        slash = star = false;
        continue;
      }
      slash = c == '/';
      if (inNumber) {
        if (c >= '0' && c <= '9' && entity < (std::int64_t{1} << 56)) {
          entity = 10 * entity + (c - '0');
          continue;
        }
        inNumber = false;
      }
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n') continue;
      if (!open.empty() && c != ')') open.back().empty = false;
      switch (c) {
        case '\'':
          inString = true;
          break;
        case '#':
          if (open.empty()) {
            entity = 0;
            entityLine = line;
            inNumber = true;
          }
          break;
        case '(':
          if (static_cast<int>(open.size()) >= limits.maxDepth) {
            throw InvalidInputError("\"" + path + "\" is refused as STEP: " + where(entity, entityLine) +
                                    " nests lists more than " + std::to_string(limits.maxDepth) +
                                    " deep; OpenCASCADE's STEP reader crashes on deep nesting (a stack overflow at "
                                    "100 000 levels) and real files nest a few levels");
          }
          open.push_back({});
          break;
        case ',':
          if (!open.empty()) ++open.back().commas;
          break;
        case ')':
          if (!open.empty()) {
            const OpenList list = open.back();
            open.pop_back();
            const std::int64_t items = list.empty ? 0 : list.commas + 1;
            if (items > limits.maxItems) {
              throw InvalidInputError("\"" + path + "\" is refused as STEP: " + where(entity, entityLine) +
                                      " has a list of " + std::to_string(items) +
                                      " items; OpenCASCADE's STEP parser takes time growing with the square of a "
                                      "list's length (seconds for 100 000 items, an hour for two million), and no "
                                      "real file has a list of more than " +
                                      std::to_string(limits.maxItems) + " items");
            }
          }
          break;
        default:
          break;
      }
    }
  }
  // A list cut off by the end of the file is counted as far as it goes.
  for (const OpenList& list : open) {
    if (list.commas + 1 > limits.maxItems) {
      throw InvalidInputError("\"" + path + "\" is refused as STEP: " + where(entity, entityLine) +
                              " has a list of more than " + std::to_string(limits.maxItems) +
                              " items, cut off by the end of the file");
    }
  }
}

}  // namespace bvmesh::cad
