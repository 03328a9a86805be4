#pragma once
// The reference tables of doc/input.md, generated from the valid-parameter lists so that the
// documentation and the validation cannot drift apart (test/input checks the file against them).
#include <Teuchos_ParameterList.hpp>
#include <Teuchos_RCP.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace cfdmpm {

struct ParameterTable {
  std::string title;  // heading, e.g. "Material, `kind: fluid`"
  std::string path;   // key path of the list's entries, e.g. "cfdmpm.materials.<name>"
  Teuchos::RCP<const Teuchos::ParameterList> list;
};

/// Every list a scene key can belong to (the fixed sections and each template), in document order.
std::vector<ParameterTable> sceneParameterTables();

/// Markdown: a heading and a table (key, type, default, allowed, unit, meaning) per ParameterTable.
void writeSceneReference(std::ostream& out);

}  // namespace cfdmpm
