#include "input/parameter_rule.hpp"

#include <Teuchos_Array.hpp>
#include <Teuchos_ParameterList.hpp>
#include <Teuchos_ParameterListExceptions.hpp>
#include <Teuchos_TwoDArray.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

namespace cfdmpm {

namespace {

std::string join(const std::vector<std::string>& names)
{
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

std::string withUnit(const std::string& text, const std::string& unit)
{
  return unit.empty() ? text : text + " (" + unit + ")";
}

template <class T>
std::string showScalar(const T& value)
{
  if constexpr (std::is_same_v<T, double>) {
    return showNumber(value);
  } else if constexpr (std::is_same_v<T, bool>) {
    return value ? "true" : "false";
  } else if constexpr (std::is_same_v<T, std::string>) {
    return value;
  } else {
    return std::to_string(value);
  }
}

template <class T>
std::string showList(const Teuchos::ArrayView<const T>& values)
{
  std::string text = "[";
  for (Teuchos::Ordinal i = 0; i < values.size(); ++i) text += (i ? ", " : "") + showScalar(values[i]);
  return text + "]";
}

template <class T>
std::string showTable(const Teuchos::TwoDArray<T>& table)
{
  std::string text = "[";
  for (Teuchos::Ordinal row = 0; row < table.getNumRows(); ++row)
    text += (row ? ", " : "") + showList<T>(table[row]);
  return text + "]";
}

// Numbers of any integer or floating type as double, for bounds checks.
std::vector<double> numbersIn(const Teuchos::ParameterEntry& entry)
{
  std::vector<double> numbers;
  if (entry.isType<double>()) numbers.push_back(entry.getValue<double>(nullptr));
  if (entry.isType<int>()) numbers.push_back(entry.getValue<int>(nullptr));
  if (entry.isType<long long>()) numbers.push_back(static_cast<double>(entry.getValue<long long>(nullptr)));
  if (entry.isType<Teuchos::Array<double>>())
    for (double v : entry.getValue<Teuchos::Array<double>>(nullptr)) numbers.push_back(v);
  if (entry.isType<Teuchos::Array<int>>())
    for (int v : entry.getValue<Teuchos::Array<int>>(nullptr)) numbers.push_back(v);
  if (entry.isType<Teuchos::Array<long long>>())
    for (long long v : entry.getValue<Teuchos::Array<long long>>(nullptr)) numbers.push_back(static_cast<double>(v));
  if (entry.isType<Teuchos::TwoDArray<double>>())
    for (double v : entry.getValue<Teuchos::TwoDArray<double>>(nullptr).getDataArray()) numbers.push_back(v);
  return numbers;
}

long listLength(const Teuchos::ParameterEntry& entry)
{
  if (entry.isType<Teuchos::Array<double>>()) return entry.getValue<Teuchos::Array<double>>(nullptr).size();
  if (entry.isType<Teuchos::Array<int>>()) return entry.getValue<Teuchos::Array<int>>(nullptr).size();
  if (entry.isType<Teuchos::Array<long long>>()) return entry.getValue<Teuchos::Array<long long>>(nullptr).size();
  if (entry.isType<Teuchos::Array<std::string>>()) return entry.getValue<Teuchos::Array<std::string>>(nullptr).size();
  return -1;
}

}  // namespace

std::string showNumber(double value)
{
  char buffer[64];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string ParameterRule::allowed() const
{
  const bool has_min = std::isfinite(min);
  const bool has_max = std::isfinite(max);
  if (has_min && has_max) {
    return withUnit("must be in " + std::string(min_open ? "(" : "[") + showNumber(min) + ", " +
                        showNumber(max) + (max_open ? ")" : "]"),
                    unit);
  }
  if (has_min) return withUnit(std::string("must be ") + (min_open ? "> " : ">= ") + showNumber(min), unit);
  if (has_max) return withUnit(std::string("must be ") + (max_open ? "< " : "<= ") + showNumber(max), unit);
  if (!choices.empty()) return "allowed: " + join(choices);
  return "";
}

std::string ParameterRule::problem(const Teuchos::ParameterEntry& entry, int dimension) const
{
  if (entry.isList()) return "";

  const long length = listLength(entry);
  if (per_direction && dimension > 0 && length >= 0 && length != dimension) {
    return "must have " + std::to_string(dimension) + " entries, one per direction (domain.dimension is " +
           std::to_string(dimension) + ")";
  }

  for (double v : numbersIn(entry)) {
    const bool below = min_open ? !(v > min) : !(v >= min);
    const bool above = max_open ? !(v < max) : !(v <= max);
    if (below || above) return (length >= 0 || entry.isTwoDArray() ? "every entry " : "") + allowed();
  }

  if (!choices.empty()) {
    std::vector<std::string> names;
    if (entry.isType<std::string>()) names.push_back(entry.getValue<std::string>(nullptr));
    if (entry.isType<Teuchos::Array<std::string>>())
      for (const auto& name : entry.getValue<Teuchos::Array<std::string>>(nullptr)) names.push_back(name);
    for (const auto& name : names) {
      if (std::find(choices.begin(), choices.end(), name) == choices.end()) {
        return entry.isType<std::string>() ? allowed() : "'" + name + "' is not allowed; " + allowed();
      }
    }
  }
  return "";
}

void ParameterRuleValidator::printDoc(const std::string& doc, std::ostream& out) const
{
  out << "# " << doc << "\n";
  if (!rule_.allowed().empty()) out << "# " << rule_.allowed() << "\n";
}

Teuchos::ParameterEntryValidator::ValidStringsList ParameterRuleValidator::validStringValues() const
{
  if (rule_.choices.empty()) return Teuchos::null;
  return Teuchos::rcp(new Teuchos::Array<std::string>(rule_.choices.begin(), rule_.choices.end()));
}

void ParameterRuleValidator::validate(const Teuchos::ParameterEntry& entry, const std::string& name,
                                      const std::string& sublist_name) const
{
  if (entry.isList()) return;
  const std::string key = sublist_name + "." + name;
  if (std::type_index(entry.getAny(false).type()) != type_) {
    throw Teuchos::Exceptions::InvalidParameterType(key + ": got '" + showValue(entry) +
                                                    "' of the wrong type");
  }
  const std::string problem = rule_.problem(entry, 0);
  if (!problem.empty()) {
    throw Teuchos::Exceptions::InvalidParameterValue(key + ": got '" + showValue(entry) + "'; " + problem);
  }
}

const ParameterRule* ruleOf(const Teuchos::ParameterEntry& entry)
{
  auto validator = Teuchos::rcp_dynamic_cast<const ParameterRuleValidator>(entry.validator());
  return validator.is_null() ? nullptr : &validator->rule();
}

std::string showValue(const Teuchos::ParameterEntry& entry)
{
  if (entry.isList()) return "{...}";
  if (entry.isType<double>()) return showScalar(entry.getValue<double>(nullptr));
  if (entry.isType<int>()) return showScalar(entry.getValue<int>(nullptr));
  if (entry.isType<long long>()) return showScalar(entry.getValue<long long>(nullptr));
  if (entry.isType<bool>()) return showScalar(entry.getValue<bool>(nullptr));
  if (entry.isType<std::string>()) return entry.getValue<std::string>(nullptr);
  if (entry.isType<Teuchos::Array<double>>()) return showList<double>(entry.getValue<Teuchos::Array<double>>(nullptr)());
  if (entry.isType<Teuchos::Array<int>>()) return showList<int>(entry.getValue<Teuchos::Array<int>>(nullptr)());
  if (entry.isType<Teuchos::Array<long long>>())
    return showList<long long>(entry.getValue<Teuchos::Array<long long>>(nullptr)());
  if (entry.isType<Teuchos::Array<std::string>>())
    return showList<std::string>(entry.getValue<Teuchos::Array<std::string>>(nullptr)());
  if (entry.isType<Teuchos::TwoDArray<double>>()) return showTable(entry.getValue<Teuchos::TwoDArray<double>>(nullptr));
  if (entry.isType<Teuchos::TwoDArray<int>>()) return showTable(entry.getValue<Teuchos::TwoDArray<int>>(nullptr));
  if (entry.isType<Teuchos::TwoDArray<std::string>>())
    return showTable(entry.getValue<Teuchos::TwoDArray<std::string>>(nullptr));
  std::ostringstream text;
  text << entry.getAny(false);
  return text.str();
}

std::string describeType(const Teuchos::ParameterEntry& valid_entry, int dimension)
{
  const ParameterRule* rule = ruleOf(valid_entry);
  const bool per_direction = rule && rule->per_direction;
  const std::string count = dimension > 0 ? std::to_string(dimension) + " " : "`dimension` ";
  const std::string list = per_direction ? "list of " + count : "list of ";
  if (valid_entry.isList()) return "section";
  if (valid_entry.isType<double>()) return "number";
  if (valid_entry.isType<int>() || valid_entry.isType<long long>()) return "integer";
  if (valid_entry.isType<bool>()) return "true or false";
  if (valid_entry.isType<std::string>()) return "string";
  if (valid_entry.isType<Teuchos::Array<double>>()) return list + "numbers";
  if (valid_entry.isType<Teuchos::Array<int>>()) return list + "integers";
  if (valid_entry.isType<Teuchos::Array<std::string>>()) return list + "names";
  if (valid_entry.isType<Teuchos::TwoDArray<double>>()) return "list of [x, y] points";
  return valid_entry.getAny(false).typeName();
}

std::string expectedType(const Teuchos::ParameterEntry& valid_entry, int dimension)
{
  const std::string type = describeType(valid_entry, dimension);
  if (valid_entry.isType<bool>()) return type;
  const bool vowel = std::string("aeiou").find(type[0]) != std::string::npos;
  return (vowel ? "an " : "a ") + type;
}

}  // namespace cfdmpm
