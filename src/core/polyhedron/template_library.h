// Templates of initial polyhedra: small human-editable text files (resources/templates/*.template,
// format in docs/templates.md) that name a generator (the topology family: box, sphere,
// revolution body, wing, nacelle ring, wing-fuselage half model), set its parameters' defaults and limits, and describe
// the template. placeTemplate (placement.h) builds the polyhedron on a target.
#pragma once

#include <iosfwd>
#include <map>
#include <string>
#include <vector>

namespace bvmesh::polyhedron {

enum class Generator { Box, Sphere, Revolution, Wing, Nacelle, WingFuselage };

struct TemplateParameter {
  std::string name;
  std::string value;  // default, as text
  std::string description;
  bool isInteger = false;  // integer in [minimum, maximum], else one of choices
  int minimum = 0;
  int maximum = 0;
  std::vector<std::string> choices;
};

struct PolyhedronTemplate {
  std::string name;
  std::string description;
  Generator generator = Generator::Box;
  std::vector<TemplateParameter> parameters;
  // Improvement passes suited to the generator's placement (-1: ImproveOptions' defaults).
  int relaxationPasses = -1;
  int pushOutPasses = -1;
  std::string source;  // file the template was read from (or the stream name)

  const TemplateParameter* find(const std::string& parameter) const;
};

// Parameter values of a template: its defaults with `overrides` applied and checked. Throws
// InvalidInputError naming the template and parameter for an unknown name or a bad value.
class TemplateValues {
 public:
  TemplateValues(const PolyhedronTemplate& polyhedronTemplate,
                 const std::map<std::string, std::string>& overrides);
  int integer(const std::string& name) const;
  const std::string& choice(const std::string& name) const;
  const std::map<std::string, std::string>& all() const { return values_; }
  const std::string& templateName() const { return templateName_; }

 private:
  std::string templateName_;
  std::map<std::string, std::string> values_;
};

PolyhedronTemplate parseTemplate(std::istream& in, const std::string& name);
PolyhedronTemplate readTemplate(const std::string& path);
// Every *.template file of a folder, sorted by name. Throws InvalidInputError for a missing
// folder, a bad file (naming it) or two templates of the same name.
std::vector<PolyhedronTemplate> readTemplateLibrary(const std::string& folder);

const char* generatorName(Generator generator);

}  // namespace bvmesh::polyhedron
