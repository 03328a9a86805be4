// doc/input.md documents every key that validSceneParameters() and the templates define, and its
// reference tables are the ones generated from them.
#include "input/reference.hpp"
#include "input/scene.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace cfdmpm::test {
namespace {

const std::filesystem::path kDocument = std::filesystem::path(CFDMPM_SOURCE_DIR) / "doc" / "input.md";
const std::string kBegin = "<!-- reference: generated from source/input, do not edit by hand -->\n";
const std::string kEnd = "<!-- end of reference -->\n";

std::string readDocument()
{
  std::ifstream file(kDocument);
  EXPECT_TRUE(file) << "cannot open " << kDocument;
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The text under the "### " heading holding `title`, up to the next heading.
std::string sectionOf(const std::string& document, const std::string& title)
{
  const size_t heading = document.find("### " + title + "\n");
  if (heading == std::string::npos) return "";
  const size_t end = document.find("\n#", heading + 4);
  return document.substr(heading, end == std::string::npos ? std::string::npos : end - heading);
}

// Every key of `list` (and of its fixed sublists) appears as `path.key` in `text`.
void expectKeysIn(const std::string& text, const Teuchos::ParameterList& list, const std::string& path,
                  const std::string& where)
{
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string key_path = path + "." + list.name(it);
    EXPECT_NE(text.find("`" + key_path + "`"), std::string::npos) << key_path << " is not documented in " << where;
    if (list.entry(it).isList()) expectKeysIn(text, list.sublist(list.name(it)), key_path, where);
  }
}

TEST(SceneDocumentation, EveryFixedKeyIsDocumented)
{
  expectKeysIn(readDocument(), *validSceneParameters(), "cfdmpm", kDocument.string());
}

TEST(SceneDocumentation, EveryTemplateKeyIsDocumentedInItsSection)
{
  const std::string document = readDocument();
  auto check = [&](const std::string& title, const Teuchos::ParameterList& list, const std::string& path) {
    const std::string section = sectionOf(document, title);
    EXPECT_FALSE(section.empty()) << "no section '### " << title << "' in " << kDocument;
    expectKeysIn(section, list, path, "section '" + title + "'");
  };
  for (const auto& kind : materialKinds())
    check("Material, `kind: " + kind + "`", *validMaterialParameters(kind), "cfdmpm.materials.<name>");
  for (const auto& type : equationOfStateTypes())
    check("Equation of state, `type: " + type + "`", *validEquationOfStateParameters(type),
          "cfdmpm.materials.<name>.equation_of_state");
  for (const auto& type : solidModelTypes())
    check("Solid model, `type: " + type + "`", *validSolidModelParameters(type), "cfdmpm.materials.<name>.model");
  for (const auto& shape : regionShapes())
    check("Region, `shape: " + shape + "`", *validRegionParameters(shape), "cfdmpm.regions.<name>");
  check("Boundary face", *validBoundaryParameters(), "cfdmpm.boundary_conditions.<face>");
}

TEST(SceneDocumentation, EveryKeyHasADocString)
{
  for (const auto& table : sceneParameterTables())
    for (auto it = table.list->begin(); it != table.list->end(); ++it)
      EXPECT_FALSE(table.list->entry(it).docString().empty()) << table.path << "." << table.list->name(it);
}

TEST(SceneDocumentation, ReferenceTablesMatchTheValidParameters)
{
  const std::string document = readDocument();
  std::ostringstream generated;
  writeSceneReference(generated);

  const size_t begin = document.find(kBegin);
  const size_t end = document.find(kEnd);
  ASSERT_NE(begin, std::string::npos) << "no reference marker in " << kDocument;
  ASSERT_NE(end, std::string::npos) << "no end-of-reference marker in " << kDocument;
  const std::string current = document.substr(begin + kBegin.size(), end - begin - kBegin.size());
  if (current != generated.str()) {
    // Write the document with fresh tables next to the test, to be copied over doc/input.md.
    const std::string updated = document.substr(0, begin + kBegin.size()) + generated.str() + document.substr(end);
    const auto path = std::filesystem::current_path() / "input.md.generated";
    std::ofstream(path) << updated;
    FAIL() << "the reference tables in " << kDocument << " are out of date; the updated document is in " << path;
  }
}

}  // namespace
}  // namespace cfdmpm::test
