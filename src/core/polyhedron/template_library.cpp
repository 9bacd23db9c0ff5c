#include "core/polyhedron/template_library.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/common/errors.h"
#include "core/common/input_file.h"

namespace bvmesh::polyhedron {
namespace {

constexpr const char* kMagic = "bvmesh-template";

const std::pair<const char*, Generator> kGenerators[] = {
    {"box", Generator::Box},   {"sphere", Generator::Sphere},   {"revolution", Generator::Revolution},
    {"wing", Generator::Wing}, {"nacelle", Generator::Nacelle}, {"wing_fuselage", Generator::WingFuselage},
};

bool parseInteger(const std::string& text, int& value) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const long parsed = std::strtol(begin, &end, 10);
  if (end == begin || *end != '\0' || errno == ERANGE || parsed < -1000000 || parsed > 1000000) return false;
  value = static_cast<int>(parsed);
  return true;
}

// Checks a value against a parameter; returns an empty string or what is wrong.
std::string checkValue(const TemplateParameter& parameter, const std::string& value) {
  if (parameter.isInteger) {
    int number = 0;
    if (!parseInteger(value, number)) return "'" + value + "' is not an integer";
    if (number < parameter.minimum || number > parameter.maximum) {
      return value + " is outside " + std::to_string(parameter.minimum) + ".." +
             std::to_string(parameter.maximum);
    }
    return {};
  }
  if (std::find(parameter.choices.begin(), parameter.choices.end(), value) != parameter.choices.end())
    return {};
  std::string allowed;
  for (const std::string& choice : parameter.choices) allowed += (allowed.empty() ? "" : ", ") + choice;
  return "'" + value + "' is not one of " + allowed;
}

}  // namespace

const char* generatorName(Generator generator) {
  for (const auto& [name, value] : kGenerators) {
    if (value == generator) return name;
  }
  return "?";
}

const TemplateParameter* PolyhedronTemplate::find(const std::string& parameter) const {
  for (const TemplateParameter& p : parameters) {
    if (p.name == parameter) return &p;
  }
  return nullptr;
}

PolyhedronTemplate parseTemplate(std::istream& in, const std::string& name) {
  PolyhedronTemplate result;
  result.source = name;
  const auto fail = [&](int line, const std::string& what) {
    throw InvalidInputError(name + " line " + std::to_string(line) + ": " + what);
  };
  std::string text;
  int number = 0;
  bool headerSeen = false;
  bool generatorSeen = false;
  while (std::getline(in, text)) {
    ++number;
    const size_t hash = text.find('#');
    std::string comment;
    if (hash != std::string::npos) {
      comment = text.substr(hash + 1);
      text.resize(hash);
    }
    std::istringstream words(text);
    std::vector<std::string> tokens;
    for (std::string word; words >> word;) tokens.push_back(word);
    if (tokens.empty()) continue;
    const std::string& keyword = tokens[0];
    // The rest of the line after the keyword, trimmed.
    const auto rest = [&]() {
      const size_t start = text.find(keyword) + keyword.size();
      const size_t first = text.find_first_not_of(" \t", start);
      const size_t last = text.find_last_not_of(" \t\r");
      return first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
    };
    if (!headerSeen) {
      if (tokens.size() != 2 || keyword != kMagic)
        fail(number, "not a BVMesh template (expected 'bvmesh-template 1')");
      if (tokens[1] != "1") fail(number, "unsupported template version " + tokens[1]);
      headerSeen = true;
    } else if (keyword == "name") {
      if (tokens.size() != 2) fail(number, "expected 'name <identifier>'");
      result.name = tokens[1];
    } else if (keyword == "description") {
      result.description += (result.description.empty() ? "" : " ") + rest();
    } else if (keyword == "generator") {
      if (tokens.size() != 2) fail(number, "expected 'generator <kind>'");
      bool known = false;
      for (const auto& [generatorText, value] : kGenerators) {
        if (tokens[1] == generatorText) {
          result.generator = value;
          known = true;
        }
      }
      if (!known)
        fail(number, "unknown generator '" + tokens[1] + "' (box, sphere, revolution, wing, nacelle, wing_fuselage)");
      generatorSeen = true;
    } else if (keyword == "relaxation" || keyword == "pushout") {
      int passes = 0;
      if (tokens.size() != 2 || !parseInteger(tokens[1], passes) || passes < 0 || passes > 100) {
        fail(number, "expected '" + keyword + " <passes 0..100>'");
      }
      (keyword == "relaxation" ? result.relaxationPasses : result.pushOutPasses) = passes;
    } else if (keyword == "integer" || keyword == "choice") {
      TemplateParameter parameter;
      const size_t first = comment.find_first_not_of(" \t");
      if (first != std::string::npos) parameter.description = comment.substr(first);
      if (keyword == "integer") {
        if (tokens.size() != 5) fail(number, "expected 'integer <name> <default> <min> <max>'");
        parameter.isInteger = true;
        if (!parseInteger(tokens[3], parameter.minimum) || !parseInteger(tokens[4], parameter.maximum) ||
            parameter.minimum > parameter.maximum) {
          fail(number, "bad limits '" + tokens[3] + " " + tokens[4] + "'");
        }
      } else {
        if (tokens.size() < 4) fail(number, "expected 'choice <name> <default> <option> <option>...'");
        parameter.choices.assign(tokens.begin() + 3, tokens.end());
      }
      parameter.name = tokens[1];
      parameter.value = tokens[2];
      if (result.find(parameter.name)) fail(number, "parameter '" + parameter.name + "' appears twice");
      const std::string problem = checkValue(parameter, parameter.value);
      if (!problem.empty()) fail(number, "default of '" + parameter.name + "': " + problem);
      result.parameters.push_back(std::move(parameter));
    } else {
      fail(number, "unknown keyword '" + keyword + "'");
    }
  }
  if (!headerSeen) throw InvalidInputError(name + ": empty template file");
  if (result.name.empty()) throw InvalidInputError(name + ": the template has no 'name'");
  if (!generatorSeen) throw InvalidInputError(name + ": the template has no 'generator'");
  return result;
}

PolyhedronTemplate readTemplate(const std::string& path) {
  std::ifstream in = openInputFile(path, "the template file");
  return parseTemplate(in, path);
}

std::vector<PolyhedronTemplate> readTemplateLibrary(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(folder, error))
    throw InvalidInputError("template folder '" + folder + "' does not exist");
  std::vector<std::string> paths;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && entry.path().extension() == ".template")
      paths.push_back(entry.path().string());
  }
  std::vector<PolyhedronTemplate> result;
  for (const std::string& path : paths) result.push_back(readTemplate(path));
  std::sort(result.begin(), result.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  for (size_t k = 1; k < result.size(); ++k) {
    if (result[k].name == result[k - 1].name) {
      throw InvalidInputError("templates '" + result[k - 1].source + "' and '" + result[k].source +
                              "' share the name '" + result[k].name + "'");
    }
  }
  return result;
}

TemplateValues::TemplateValues(const PolyhedronTemplate& polyhedronTemplate,
                               const std::map<std::string, std::string>& overrides)
    : templateName_(polyhedronTemplate.name) {
  for (const TemplateParameter& parameter : polyhedronTemplate.parameters)
    values_[parameter.name] = parameter.value;
  for (const auto& [name, value] : overrides) {
    const TemplateParameter* parameter = polyhedronTemplate.find(name);
    if (!parameter) {
      std::string known;
      for (const TemplateParameter& p : polyhedronTemplate.parameters)
        known += (known.empty() ? "" : ", ") + p.name;
      throw InvalidInputError("template '" + templateName_ + "' has no parameter '" + name + "' (it has " +
                              known + ")");
    }
    const std::string problem = checkValue(*parameter, value);
    if (!problem.empty())
      throw InvalidInputError("template '" + templateName_ + "', parameter '" + name + "': " + problem);
    values_[name] = value;
  }
}

int TemplateValues::integer(const std::string& name) const {
  const auto found = values_.find(name);
  int value = 0;
  if (found == values_.end() || !parseInteger(found->second, value)) {
    throw InvalidInputError("template '" + templateName_ + "' lacks the integer parameter '" + name +
                            "' its generator needs");
  }
  return value;
}

const std::string& TemplateValues::choice(const std::string& name) const {
  const auto found = values_.find(name);
  if (found == values_.end()) {
    throw InvalidInputError("template '" + templateName_ + "' lacks the parameter '" + name +
                            "' its generator needs");
  }
  return found->second;
}

}  // namespace bvmesh::polyhedron
