#include "input/reference.hpp"

#include "input/parameter_rule.hpp"
#include "input/scene.hpp"

namespace cfdmpm {

namespace {

std::string escapeCell(std::string text)
{
  for (size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2)) text.replace(at, 1, "\\|");
  return text;
}

std::string defaultCell(const Teuchos::ParameterEntry& entry, const ParameterRule* rule)
{
  if (rule && rule->required) return "required";
  if (rule && !rule->derived_default.empty()) return rule->derived_default;
  if (entry.isList()) return "";
  const std::string value = showValue(entry);
  return "`" + (value.empty() ? std::string("\"\"") : value) + "`";
}

// The allowed values without the unit (it has its own column) and without "must be".
std::string allowedCell(const ParameterRule* rule)
{
  if (!rule) return "";
  ParameterRule bare = *rule;
  bare.unit.clear();
  std::string text = bare.allowed();
  for (const std::string prefix : {"must be ", "allowed: "})
    if (text.rfind(prefix, 0) == 0) text.erase(0, prefix.size());
  return text;
}

}  // namespace

std::vector<ParameterTable> sceneParameterTables()
{
  const auto scene = validSceneParameters();
  auto section = [&](const std::string& key) { return Teuchos::rcpFromRef(scene->sublist(key)); };
  std::vector<ParameterTable> tables{{"Top level", "cfdmpm", scene},
                                     {"`cfdmpm.domain`", "cfdmpm.domain", section("domain")}};
  for (const auto& kind : materialKinds()) {
    tables.push_back({"Material, `kind: " + kind + "`", "cfdmpm.materials.<name>", validMaterialParameters(kind)});
    if (kind == "fluid") {
      for (const auto& type : equationOfStateTypes())
        tables.push_back({"Equation of state, `type: " + type + "`", "cfdmpm.materials.<name>.equation_of_state",
                          validEquationOfStateParameters(type)});
    } else {
      for (const auto& type : solidModelTypes())
        tables.push_back({"Solid model, `type: " + type + "`", "cfdmpm.materials.<name>.model",
                          validSolidModelParameters(type)});
    }
  }
  tables.push_back({"`cfdmpm.initial_state`", "cfdmpm.initial_state", section("initial_state")});
  for (const auto& shape : regionShapes())
    tables.push_back({"Region, `shape: " + shape + "`", "cfdmpm.regions.<name>", validRegionParameters(shape)});
  tables.push_back({"Boundary face", "cfdmpm.boundary_conditions.<face>", validBoundaryParameters()});
  tables.push_back({"`cfdmpm.time`", "cfdmpm.time", section("time")});
  tables.push_back({"`cfdmpm.output`", "cfdmpm.output", section("output")});
  tables.push_back({"`cfdmpm.ice`", "cfdmpm.ice", section("ice")});
  tables.push_back({"`cfdmpm.mpm`", "cfdmpm.mpm", section("mpm")});
  return tables;
}

void writeSceneReference(std::ostream& out)
{
  bool first = true;
  for (const auto& table : sceneParameterTables()) {
    out << (first ? "" : "\n") << "### " << table.title << "\n\n"
        << "| key | type | default | allowed | unit | meaning |\n"
        << "|---|---|---|---|---|---|\n";
    first = false;
    for (auto it = table.list->begin(); it != table.list->end(); ++it) {
      const Teuchos::ParameterEntry& entry = table.list->entry(it);
      const ParameterRule* rule = ruleOf(entry);
      out << "| `" << table.path << "." << table.list->name(it) << "` | " << describeType(entry, 0) << " | "
          << escapeCell(defaultCell(entry, rule)) << " | " << escapeCell(allowedCell(rule)) << " | "
          << (rule ? rule->unit : "") << " | " << escapeCell(entry.docString()) << " |\n";
    }
  }
}

}  // namespace cfdmpm
