#pragma once
// The rule one scene parameter obeys: required or optional, SI unit, numeric bounds, allowed names,
// one entry per direction. It rides on the parameter's entry in a valid-parameter list as a Teuchos
// validator, so one definition serves three readers: readScene (which checks each key itself to
// name key, value and limit in its message), Teuchos's validateParametersAndSetDefaults (which runs
// the same check again), and the reference tables of doc/input.md.
#include <Teuchos_ParameterEntry.hpp>
#include <Teuchos_ParameterEntryValidator.hpp>

#include <limits>
#include <string>
#include <typeindex>
#include <vector>

namespace cfdmpm {

struct ParameterRule {
  bool required = false;
  bool per_direction = false;   // a list with one entry per direction (domain.dimension entries)
  std::string unit;             // SI unit; empty for pure numbers, names and flags
  std::string derived_default;  // a default that depends on other keys, filled in by readScene
  double min = -std::numeric_limits<double>::infinity();  // bounds on a number, or on every entry
  double max = std::numeric_limits<double>::infinity();   // of a list of numbers
  bool min_open = false;        // true: min itself is not allowed
  bool max_open = false;
  std::vector<std::string> choices;  // allowed names of a string, or of every entry of a string list

  /// What a value must be: "must be > 0", "must be in (0, 1]", "allowed: fluid, solid"; empty when
  /// any value of the right type goes.
  std::string allowed() const;

  /// Why the value in `entry` breaks the rule, e.g. "must be >= 0 (Pa s)"; empty when it does not.
  /// `dimension` (2 or 3) checks the length of per-direction lists; 0 skips that check.
  std::string problem(const Teuchos::ParameterEntry& entry, int dimension) const;
};

/// Carries a ParameterRule inside a valid-parameter list. Teuchos calls validate() for every given
/// entry; sublists pass (their keys are checked one level down).
class ParameterRuleValidator : public Teuchos::ParameterEntryValidator {
 public:
  ParameterRuleValidator(ParameterRule rule, std::type_index type) : rule_(std::move(rule)), type_(type) {}

  const ParameterRule& rule() const { return rule_; }

  const std::string getXMLTypeName() const override { return "cfdmpmParameterRule"; }
  void printDoc(const std::string& doc, std::ostream& out) const override;
  ValidStringsList validStringValues() const override;
  void validate(const Teuchos::ParameterEntry& entry, const std::string& name,
                const std::string& sublist_name) const override;

 private:
  ParameterRule rule_;
  std::type_index type_;
};

/// The rule attached to an entry of a valid-parameter list; nullptr when it has none.
const ParameterRule* ruleOf(const Teuchos::ParameterEntry& entry);

/// The value of an entry written as in YAML: 0.001, [0, 1], [[0, 0], [1, 0]], water, {...}.
std::string showValue(const Teuchos::ParameterEntry& entry);

/// What kind of value an entry of a valid list holds: "number", "integer", "list of 2 numbers",
/// "list of [x, y] points", "section". `dimension` 0 writes "list of `dimension` numbers".
std::string describeType(const Teuchos::ParameterEntry& valid_entry, int dimension);
/// The same with its article, as an error message's "expected ...": "a number", "an integer",
/// "true or false".
std::string expectedType(const Teuchos::ParameterEntry& valid_entry, int dimension);

/// A number written in its shortest exact form (0.001, 2.15e+09, 101325).
std::string showNumber(double value);

}  // namespace cfdmpm
