// Reading a scene: the file is parsed by Teuchos, then every section is checked key by key against
// its valid-parameter list (input/valid_parameters.cpp) so that each complaint names the full key,
// the value given and what is allowed; then Teuchos fills in the defaults, and the typed structs
// are filled from the completed list. Nothing is written anywhere.
#include "input/scene.hpp"

#include "input/parameter_rule.hpp"
#include "input/scene_checks.hpp"

#include <Teuchos_Array.hpp>
#include <Teuchos_Parser.hpp>
#include <Teuchos_TwoDArray.hpp>
#include <Teuchos_YamlParameterListHelpers.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>

namespace cfdmpm {

namespace {

using Teuchos::Array;
using Teuchos::ParameterEntry;
using Teuchos::ParameterList;
using Teuchos::RCP;
using Teuchos::TwoDArray;

const std::string kRoot = "cfdmpm";

std::string join(const std::vector<std::string>& names)
{
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

std::vector<std::string> keysOf(const ParameterList& list)
{
  std::vector<std::string> keys;
  for (auto it = list.begin(); it != list.end(); ++it) keys.push_back(list.name(it));
  return keys;
}

// --- The file itself ---------------------------------------------------------------------------

std::string readText(const std::string& path)
{
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) throw InputError(path + ": cannot open the scene file: " + std::strerror(errno));
  std::string text;
  char buffer[4096];
  size_t count = 0;
  while ((count = std::fread(buffer, 1, sizeof buffer, file)) > 0) text.append(buffer, count);
  const int read_error = std::ferror(file) ? errno : 0;
  std::fclose(file);
  if (read_error) throw InputError(path + ": cannot read the scene file: " + std::strerror(read_error));
  return text;
}

// The YAML reader is slow on large input (~12 s per MB of a long flow list, measured) and stops on
// any byte above 127, even in a comment. Real scenes are a few kB; one with a surveyed outline of
// 10^4 polygon points is ~200 kB. Nesting: the deepest key of a scene is 4-6 levels down
// (cfdmpm.ice.linear_solver.muelu.<...>).
constexpr std::size_t kMaxSceneBytes = 1 << 20;
constexpr int kMaxSceneDepth = 32;

std::string lineColumn(const std::string& path, int line, std::size_t column)
{
  return path + ":" + std::to_string(line) + ":" + std::to_string(column) + ": ";
}

// Before the YAML reader: the file's size, bytes that are not text, non-ASCII characters outside
// comments (named with line, column and code point) and the nesting depth. Returns the text with
// the non-ASCII characters of comments blanked, which is what the reader gets.
std::string screenText(const std::string& text, const std::string& path)
{
  if (text.size() > kMaxSceneBytes) {
    throw InputError(path + ": the file has " + std::to_string(text.size()) + " bytes; a scene file may have at most " +
                     std::to_string(kMaxSceneBytes) + " (1 MiB), since the YAML reader needs seconds per 100 kB");
  }
  std::string screened = text;
  int line = 1, flow_depth = 0;
  std::size_t line_start = 0;
  bool in_comment = false, in_single = false, in_double = false, at_line_start = true;
  std::vector<std::size_t> indents;  // the block structure: indentation of each open level
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++line, line_start = i + 1, in_comment = in_single = in_double = false, at_line_start = true;
      continue;
    }
    if ((c < 32 && c != '\t' && c != '\r') || c == 127) {
      throw InputError(path + ": is not a text file (byte " + std::to_string(i) + ", on line " + std::to_string(line) +
                       ", is the control character " + std::to_string(c) + "); give the scene's YAML file");
    }
    if (c >= 128) {
      // The UTF-8 sequence of one character: its length from the first byte, then continuation bytes.
      const int length = (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 0;
      unsigned code = length == 2 ? c & 0x1F : length == 3 ? c & 0x0F : c & 0x07;
      bool valid = length > 0 && i + length <= text.size();
      for (int k = 1; valid && k < length; ++k) {
        const unsigned char next = static_cast<unsigned char>(text[i + k]);
        valid = (next & 0xC0) == 0x80;
        code = code << 6 | (next & 0x3F);
      }
      if (!valid) {
        throw InputError(path + ": is not a text file (byte " + std::to_string(i) + ", on line " + std::to_string(line) +
                         ", is not UTF-8); give the scene's YAML file");
      }
      if (in_comment) {
        for (int k = 0; k < length; ++k) screened[i + k] = ' ';
        i += length - 1;
        continue;
      }
      char hex[16];
      std::snprintf(hex, sizeof hex, "U+%04X", code);
      throw InputError(lineColumn(path, line, i - line_start + 1) + "the character '" + text.substr(i, length) + "' (" +
                       hex + ") is not ASCII; the YAML reader takes ASCII only (outside comments): write names, "
                       "keys and titles with ASCII letters");
    }
    if (in_comment) continue;
    if (in_double) {
      if (c == '\\') ++i;
      else if (c == '"') in_double = false;
      continue;
    }
    if (in_single) {
      if (c == '\'') in_single = false;
      continue;
    }
    const char before = i > line_start ? text[i - 1] : ' ';
    const bool token_start = before == ' ' || before == '\t' || before == '[' || before == '{' || before == ',' ||
                             before == ':';
    if (at_line_start && c != ' ' && c != '\t' && c != '\r' && c != '#') {
      // A line with content: its indentation closes the deeper block levels and opens one.
      const std::size_t indent = i - line_start;
      while (!indents.empty() && indents.back() >= indent) indents.pop_back();
      indents.push_back(indent);
      at_line_start = false;
    }
    if (c == '-' && token_start && i + 4 < text.size() && text[i + 1] == '.') {
      // YAML's -.inf, which the reader cannot parse (it reads .inf as a string, refused later as
      // "expected a number"): say so with the key before it on the line.
      std::string word = text.substr(i + 2, 3);
      for (char& w : word) w = char(std::tolower(static_cast<unsigned char>(w)));
      if (word == "inf" || word == "nan") {
        const std::string before_token = text.substr(line_start, i - line_start);
        const std::size_t colon = before_token.find_last_of(':');
        std::size_t key_start = before_token.find_last_of(" \t{,", colon == std::string::npos ? 0 : colon - 1);
        key_start = key_start == std::string::npos ? 0 : key_start + 1;
        const std::string key = colon == std::string::npos ? "" : before_token.substr(key_start, colon - key_start);
        throw InputError(lineColumn(path, line, i - line_start + 1) + (key.empty() ? "" : key + ": ") + "got '" +
                         text.substr(i, 5) + "'; numbers must be finite (neither .inf nor -.inf nor .nan)");
      }
    }
    if (c == '#' && token_start) in_comment = true;
    else if (c == '"' && token_start) in_double = true;
    else if (c == '\'' && token_start) in_single = true;
    else if (c == '{' || c == '[') ++flow_depth;
    else if (c == '}' || c == ']') flow_depth = std::max(0, flow_depth - 1);
    const int depth = int(indents.size()) + flow_depth;
    if (depth > kMaxSceneDepth) {
      throw InputError(lineColumn(path, line, i - line_start + 1) + "the file nests " + std::to_string(depth) +
                       " levels deep here; a scene nests at most " + std::to_string(kMaxSceneDepth) +
                       " (its deepest keys are 4 to 6 levels down)");
    }
  }
  return screened;
}

// The key of a line that starts in column 0: the text before the first ": " (or a final ':'),
// without quotes; the whole line, without a comment, when there is no such colon.
std::string topLevelKey(const std::string& line, std::string& rest)
{
  if (line[0] == '"' || line[0] == '\'') {
    const size_t close = line.find(line[0], 1);
    if (close != std::string::npos && line.compare(close + 1, 1, ":") == 0) {
      rest = line.substr(close + 2);
      return line.substr(1, close - 1);
    }
  }
  for (size_t i = 0; i < line.size(); ++i) {
    if (line[i] == ':' && (i + 1 == line.size() || line[i + 1] == ' ' || line[i + 1] == '\t')) {
      rest = line.substr(i + 1);
      std::string key = line.substr(0, i);
      key.erase(key.find_last_not_of(" \t") + 1);
      return key;
    }
  }
  rest.clear();
  std::string key = line.substr(0, line.find(" #"));
  key.erase(key.find_last_not_of(" \t") + 1);
  return key;
}

// Teuchos returns the first top-level key of a file as the list and drops any further ones without
// a word, so the text is checked here for exactly one top-level key, `cfdmpm`, holding a map.
void refuseOtherTopLevelKeys(const std::string& text, const std::string& path)
{
  const std::string rule =
      "a scene file has exactly one top-level key, `cfdmpm:`, with every section indented below it";
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  int root_line = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == ' ' || line[0] == '\t' || line[0] == '#' || line[0] == '%') continue;
    if (line.rfind("---", 0) == 0 || line.rfind("...", 0) == 0) continue;

    std::string rest;
    const std::string key = topLevelKey(line, rest);
    const std::string where = path + ":" + std::to_string(number) + ": top-level key";
    if (key != kRoot) throw InputError(where + ": got '" + key + "'; " + rule);
    if (root_line) {
      throw InputError(where + ": got '" + key + "' again (first on line " + std::to_string(root_line) + "); " + rule);
    }
    root_line = number;

    rest = rest.substr(0, rest.find('#'));
    rest.erase(0, rest.find_first_not_of(" \t"));
    rest.erase(rest.find_last_not_of(" \t") + 1);
    if (!rest.empty() && rest[0] != '{') {
      throw InputError(path + ":" + std::to_string(number) + ": " + kRoot + ": got '" + rest +
                       "'; must hold the scene's sections, indented below `cfdmpm:`");
    }
  }
  if (!root_line) throw InputError(path + ": no top-level key; " + rule);
}

// --- The keys as written ------------------------------------------------------------------------
//
// Teuchos's YAML reader keeps the numbers it reads, not their text, and stops at a repeated key with
// 'Parameter "x" already exists in list "ANONYMOUS"' at the line after it. This pass reads the
// structure of the file (block maps by indentation, flow maps and lists on one line, as the reader
// takes them) to refuse a repeated key with its own line and column, and to keep each value's text,
// so that messages echo 40.0 as 40.0 and 1e-400 as 1e-400, not as 40 and 0.

struct WrittenValue {
  std::string text;
  int line = 0;
};
using WrittenValues = std::map<std::string, WrittenValue>;  // by key path: cfdmpm.time.cfl

class SceneIndexer {
 public:
  SceneIndexer(const std::string& path, WrittenValues& values) : path_(path), values_(values) {}

  void read(const std::string& text)
  {
    std::istringstream lines(text);
    std::string line;
    int number = 0;
    levels_.push_back({0, "", {}, false});  // the file: its keys start in column 0
    while (std::getline(lines, line)) {
      ++number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const std::size_t indent = line.find_first_not_of(' ');
      if (indent == std::string::npos || line[indent] == '#' || line[indent] == '%') continue;
      if (indent == 0 && (line.rfind("---", 0) == 0 || line.rfind("...", 0) == 0)) continue;
      if (line[indent] == '\t') return;  // tabs: leave the structure to the YAML reader
      const int column = int(indent);
      if (levels_.back().pending) {
        if (column > levels_[levels_.size() - 2].indent) {
          levels_.back().indent = column, levels_.back().pending = false;
        } else {
          levels_.pop_back();
        }
      }
      while (levels_.size() > 1 && levels_.back().indent > column) levels_.pop_back();
      if (levels_.back().indent != column || line[indent] == '-') continue;  // continuation, list item
      std::size_t at = indent;
      std::string key;
      if (!readKey(line, at, key)) continue;
      Level& level = levels_.back();
      const std::string key_path = childPath(level.path, key);
      refuseRepeated(level, key, number, indent);
      const std::string rest = valueText(line, at);
      if (rest.empty()) {
        levels_.push_back({-1, key_path, {}, true});
      } else {
        std::size_t position = line.find_first_not_of(" \t", at);
        readValue(line, position, key_path, number);
      }
    }
  }

 private:
  struct Level {
    int indent;
    std::string path;
    std::map<std::string, int> keys;  // key -> line
    bool pending;                     // opened by a key without a value; its indent comes next
  };

  static std::string childPath(const std::string& parent, const std::string& key)
  {
    return parent.empty() ? key : parent + "." + key;
  }

  // The text after a block key's colon, without a comment and surrounding blanks.
  static std::string valueText(const std::string& line, std::size_t at)
  {
    std::string rest = line.substr(at);
    for (std::size_t i = 0; i < rest.size(); ++i)
      if (rest[i] == '#' && (i == 0 || rest[i - 1] == ' ' || rest[i - 1] == '\t')) {
        rest.erase(i);
        break;
      }
    const std::size_t first = rest.find_first_not_of(" \t");
    if (first == std::string::npos) return "";
    return rest.substr(first, rest.find_last_not_of(" \t") + 1 - first);
  }

  // A key ending in ': ' (or ':' at the end, or before a flow value in a flow map); `at` moves past
  // the colon. Quoted keys lose their quotes.
  bool readKey(const std::string& line, std::size_t& at, std::string& key) const
  {
    if (at < line.size() && (line[at] == '"' || line[at] == '\'')) {
      const std::size_t close = line.find(line[at], at + 1);
      if (close == std::string::npos || close + 1 >= line.size() || line[close + 1] != ':') return false;
      key = line.substr(at + 1, close - at - 1);
      at = close + 2;
      return true;
    }
    for (std::size_t i = at; i < line.size(); ++i) {
      const char c = line[i];
      if (c == '#' && i > at && (line[i - 1] == ' ' || line[i - 1] == '\t')) return false;
      if (c == ',' || c == '}' || c == '{' || c == '[' || c == ']') return false;
      if (c == ':' && (i + 1 == line.size() || line[i + 1] == ' ' || line[i + 1] == '\t')) {
        key = line.substr(at, i - at);
        key.erase(key.find_last_not_of(" \t") + 1);
        at = i + 1;
        return !key.empty();
      }
    }
    return false;
  }

  void refuseRepeated(Level& level, const std::string& key, int line, std::size_t index)
  {
    const auto [first, inserted] = level.keys.emplace(key, line);
    if (inserted) return;
    throw InputError(path_ + ":" + std::to_string(line) + ":" + std::to_string(index + 1) + ": key '" + key + "' of " +
                     (level.path.empty() ? std::string("the file") : level.path) + " given twice (first on line " +
                     std::to_string(first->second) + "); give each key once");
  }

  // A value starting at line[at]: a flow map, a flow list (its text kept whole), a quoted string
  // (skipped) or a plain scalar (its text kept); `at` moves past it.
  void readValue(const std::string& line, std::size_t& at, const std::string& key_path, int number)
  {
    if (at >= line.size()) return;
    const char c = line[at];
    if (c == '{') {
      readFlowMap(line, at, key_path, number);
    } else if (c == '[') {
      const std::size_t start = at;
      int depth = 0;
      for (; at < line.size(); ++at) {
        if (line[at] == '[') ++depth;
        if (line[at] == ']' && --depth == 0) break;
      }
      if (at < line.size()) values_[key_path] = {line.substr(start, at - start + 1), number};
      ++at;
    } else if (c == '"' || c == '\'') {
      const std::size_t close = line.find(c, at + 1);
      at = close == std::string::npos ? line.size() : close + 1;
    } else {
      const std::size_t start = at;
      while (at < line.size() && line[at] != ',' && line[at] != '}' && line[at] != ']' &&
             !(line[at] == '#' && (line[at - 1] == ' ' || line[at - 1] == '\t')))
        ++at;
      std::string text = line.substr(start, at - start);
      text.erase(text.find_last_not_of(" \t") + 1);
      if (!text.empty()) values_[key_path] = {text, number};
    }
  }

  void readFlowMap(const std::string& line, std::size_t& at, const std::string& path, int number)
  {
    Level level{-1, path, {}, false};
    ++at;  // '{'
    while (at < line.size()) {
      at = line.find_first_not_of(" \t,", at);
      if (at == std::string::npos || line[at] == '}') {
        if (at != std::string::npos) ++at;
        return;
      }
      const std::size_t key_start = at;
      std::string key;
      if (!readKey(line, at, key)) return;  // not a form this pass knows: the reader decides
      refuseRepeated(level, key, number, key_start);
      at = line.find_first_not_of(" \t", at);
      if (at == std::string::npos) return;
      readValue(line, at, childPath(path, key), number);
    }
  }

  const std::string& path_;
  WrittenValues& values_;
  std::vector<Level> levels_;
};

// The values of the scene being read, as written (readSceneText sets it for the time it reads).
const WrittenValues* g_written_values = nullptr;

// A value for a message, quoted: as the file wrote it when known, else as read. A number beyond the
// range of a double says what it became ('1e-400' (read as 0: ...)).
std::string shownValue(const std::string& key_path, const ParameterEntry& entry)
{
  const auto found = g_written_values ? g_written_values->find(key_path) : WrittenValues::const_iterator();
  if (!g_written_values || found == g_written_values->end()) return "'" + showValue(entry) + "'";
  const std::string& text = found->second.text;
  if (entry.isType<double>()) {
    errno = 0;
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (errno == ERANGE && end && *end == '\0' && (value == 0 || std::isinf(value)))
      return "'" + text + "' (read as " + showValue(entry) + ": beyond the range of a double)";
  }
  return "'" + text + "'";
}

// Teuchos messages carry source locations and "Throw number" lines; keep what a user can act on.
std::string cleanTeuchosMessage(const std::string& message)
{
  std::istringstream lines(message);
  std::string line;
  std::string cleaned;
  bool in_lexer_text = false;  // the parser's lexer buffer, quoted over several lines
  while (std::getline(lines, line)) {
    if (line.rfind("Lexer text: \"", 0) == 0) in_lexer_text = true;
    if (in_lexer_text) {
      in_lexer_text = !(line.size() > 0 && line.back() == '"' && line != "Lexer text: \"");
      continue;
    }
    if (line.rfind("Parser was in state", 0) == 0) continue;
    if (line.rfind("error: ", 0) == 0) line.erase(0, 7);
    const bool noise = line.rfind("./", 0) == 0 || line.find(".cpp:") != std::string::npos ||
                       line.rfind("Throw number", 0) == 0 || line.rfind("Throw test that evaluated", 0) == 0 ||
                       line.find_first_not_of(" \t") == std::string::npos;
    if (!noise) cleaned += (cleaned.empty() ? "" : "\n") + line;
  }
  return cleaned;
}

RCP<ParameterList> parseYaml(const std::string& text, const std::string& path)
{
  try {
    return Teuchos::getParametersFromYamlString(text);
  } catch (const Teuchos::ParserFail& error) {
    // Teuchos' parser reads a subset of YAML; two common forms it rejects get a hint.
    throw InputError(path + ": YAML syntax error: " + cleanTeuchosMessage(error.what()) +
                     "\n(note: write a list as [a, b] on one line, or as '- a' items indented deeper than their "
                     "key; a [...] or {...} must not break across lines)");
  } catch (const std::exception& error) {
    throw InputError(path + ": cannot be read as a scene: " + cleanTeuchosMessage(error.what()));
  }
}

// --- Checking one list against its valid list ---------------------------------------------------

std::string givenType(const ParameterEntry& entry)
{
  if (entry.isList()) return "a section";
  if (entry.isType<double>()) return "a number";
  if (entry.isType<int>() || entry.isType<long long>()) return "an integer";
  if (entry.isType<bool>()) return "true/false";
  if (entry.isType<std::string>()) return "a string";
  if (entry.isTwoDArray()) return "a list of lists";
  if (entry.isType<Array<std::string>>()) return "a list of strings";
  if (entry.isType<Array<double>>()) return "a list of numbers";
  if (entry.isArray()) return "a list of integers";
  return "a " + entry.getAny(false).typeName();
}

// "a number; must be >= 0 (Pa s)": what a key of the valid list expects.
std::string expectation(const ParameterEntry& valid_entry, int dimension)
{
  std::string text = expectedType(valid_entry, dimension);
  if (valid_entry.isList()) text += " (keys indented below it)";
  const ParameterRule* rule = ruleOf(valid_entry);
  if (rule && !rule->allowed().empty()) {
    const bool list = valid_entry.isArray() || valid_entry.isTwoDArray();
    text += std::string("; ") + (list && rule->choices.empty() ? "every entry " : "") + rule->allowed();
  }
  return text;
}

InputError wrongType(const std::string& key_path, const ParameterEntry& entry, const ParameterEntry& valid_entry,
                     int dimension)
{
  return InputError(key_path + ": got " + shownValue(key_path, entry) + " (" + givenType(entry) + "); expected " +
                    expectation(valid_entry, dimension));
}

// YAML writes 0 as an integer and [0, 1] as a list of integers: convert them where the valid list
// holds a number; and a bare integer where it holds a string (a title such as 2024).
void convertIntegers(ParameterEntry& entry, const ParameterEntry& valid_entry)
{
  const std::type_info& want = valid_entry.getAny(false).type();
  if (want == typeid(double)) {
    if (entry.isType<int>()) entry.setValue<double>(entry.getValue<int>(nullptr));
    if (entry.isType<long long>()) entry.setValue<double>(static_cast<double>(entry.getValue<long long>(nullptr)));
  } else if (want == typeid(long long)) {
    if (entry.isType<int>()) entry.setValue<long long>(entry.getValue<int>(nullptr));
  } else if (want == typeid(std::string)) {
    if (entry.isType<int>()) entry.setValue<std::string>(std::to_string(entry.getValue<int>(nullptr)));
    if (entry.isType<long long>()) entry.setValue<std::string>(std::to_string(entry.getValue<long long>(nullptr)));
  } else if (want == typeid(Array<double>)) {
    if (entry.isType<Array<int>>()) {
      const auto& values = entry.getValue<Array<int>>(nullptr);
      entry.setValue(Array<double>(values.begin(), values.end()));
    } else if (entry.isType<Array<long long>>()) {
      const auto& values = entry.getValue<Array<long long>>(nullptr);
      entry.setValue(Array<double>(values.begin(), values.end()));
    }
  } else if (want == typeid(TwoDArray<double>)) {
    if (entry.isType<TwoDArray<int>>()) {
      const auto& table = entry.getValue<TwoDArray<int>>(nullptr);
      TwoDArray<double> converted(table.getNumRows(), table.getNumCols());
      for (Teuchos::Ordinal i = 0; i < table.getNumRows(); ++i)
        for (Teuchos::Ordinal j = 0; j < table.getNumCols(); ++j) converted(i, j) = table(i, j);
      entry.setValue(converted);
    }
  }
}

void checkEntry(ParameterEntry& entry, const ParameterEntry& valid_entry, const std::string& key_path, int dimension)
{
  if (entry.isList() != valid_entry.isList()) throw wrongType(key_path, entry, valid_entry, dimension);
  if (entry.isList()) return;
  convertIntegers(entry, valid_entry);
  if (entry.getAny(false).type() != valid_entry.getAny(false).type()) {
    throw wrongType(key_path, entry, valid_entry, dimension);
  }
  if (const ParameterRule* rule = ruleOf(valid_entry)) {
    const std::string problem = rule->problem(entry, dimension);
    if (!problem.empty()) throw InputError(key_path + ": got " + shownValue(key_path, entry) + "; " + problem);
  }
}

InputError missingKey(const std::string& key_path, const ParameterEntry& valid_entry, int dimension)
{
  return InputError(key_path + ": required key is missing; expected " + expectation(valid_entry, dimension) +
                    " (" + valid_entry.docString() + ")");
}

// Every given key must be in `valid`, of its type and within its rule; every required key given.
void checkKeys(ParameterList& given, const ParameterList& valid, const std::string& path, int dimension)
{
  for (auto it = given.begin(); it != given.end(); ++it) {
    const std::string& key = given.name(it);
    const ParameterEntry* valid_entry = valid.getEntryPtr(key);
    if (!valid_entry) {
      throw InputError(path + "." + key + ": unknown key; allowed keys in " + path + ": " + join(keysOf(valid)));
    }
    checkEntry(given.getEntry(key), *valid_entry, path + "." + key, dimension);
  }
  for (auto it = valid.begin(); it != valid.end(); ++it) {
    const ParameterRule* rule = ruleOf(valid.entry(it));
    if (rule && rule->required && !given.isParameter(valid.name(it))) {
      throw missingKey(path + "." + valid.name(it), valid.entry(it), dimension);
    }
  }
}

// Teuchos's own validation, after checkKeys has passed, fills in the defaults.
void setDefaults(ParameterList& given, const ParameterList& valid, const std::string& path)
{
  try {
    given.validateParametersAndSetDefaults(valid, 0);
  } catch (const std::exception& error) {
    throw InputError(path + ": " + cleanTeuchosMessage(error.what()));
  }
}

// The value of a key that chooses a template (kind, type, shape), checked against any template.
std::string selectorValue(ParameterList& given, const std::string& key, const ParameterList& any_template,
                          const std::string& path)
{
  const ParameterEntry& valid_entry = any_template.getEntry(key);
  if (!given.isParameter(key)) throw missingKey(path + "." + key, valid_entry, 0);
  checkEntry(given.getEntry(key), valid_entry, path + "." + key, 0);
  return given.get<std::string>(key);
}

// A named entry (material, region) must be a section, and its name usable in file and field names.
ParameterList& namedEntry(ParameterList& section, const std::string& name, const std::string& path,
                          const std::string& what)
{
  const std::string key_path = path + "." + name;
  const bool letters = !name.empty() && std::isalpha(static_cast<unsigned char>(name[0])) &&
                       std::all_of(name.begin(), name.end(), [](char c) {
                         return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
                       });
  if (!letters) {
    throw inputError(key_path, name, what + " names start with a letter and hold only letters, digits, '_' and '-'");
  }
  if (!section.isSublist(name)) {
    throw InputError(key_path + ": got '" + showValue(section.getEntry(name)) + "' (" +
                     givenType(section.getEntry(name)) + "); expected a section with the " + what + "'s keys");
  }
  return section.sublist(name);
}

void setIfMissing(ParameterList& list, const std::string& key, const Array<double>& value)
{
  if (!list.isParameter(key)) list.set(key, value);
}

void setIfMissing(ParameterList& list, const std::string& key, double value)
{
  if (!list.isParameter(key)) list.set(key, value);
}

template <class Target, class Source>
std::array<Target, 3> padded(const Array<Source>& values, Target fill)
{
  std::array<Target, 3> result{fill, fill, fill};
  for (Teuchos::Ordinal i = 0; i < values.size() && i < 3; ++i) result[i] = static_cast<Target>(values[i]);
  return result;
}

std::string showPoint(const std::array<double, 3>& point, int dimension)
{
  std::string text = "[";
  for (int i = 0; i < dimension; ++i) text += (i ? ", " : "") + showNumber(point[i]);
  return text + "]";
}

// --- The sections ----------------------------------------------------------------------------

// A length or count for a message, to 10 significant digits: 3.52 rather than 3.5199999999999996.
std::string showRounded(double value)
{
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

// `cells` from `cell_size`: (upper - lower) / cell_size in every direction, which must be a whole
// number (to a relative 1e-9, the round-off of the division).
Array<int> cellsOfSize(const ParameterList& list, const std::string& path, int dimension,
                       const std::array<double, 3>& lower, const std::array<double, 3>& upper)
{
  const std::string key = path + ".cell_size";
  const double size = list.get<double>("cell_size");
  const std::string given = key + ": got " + shownValue(key, list.getEntry("cell_size")) + "; ";
  std::string extents = "[";
  for (int i = 0; i < dimension; ++i) extents += (i ? ", " : "") + showRounded(upper[i] - lower[i]);
  extents += "] m";
  const char* const axes[] = {"x", "y", "z"};
  Array<int> cells(dimension);
  for (int i = 0; i < dimension; ++i) {
    const double extent = upper[i] - lower[i];
    const double count = extent / size;
    const double whole = std::round(count);
    if (whole < 1 || std::abs(count - whole) > 1e-9 * count) {
      throw InputError(given + "it does not divide the domain in " + axes[i] + ": upper - lower = " +
                       showRounded(extent) + " m holds " + showRounded(count) + " cells of " + showRounded(size) +
                       " m, not a whole number; cell_size must divide the extent upper - lower = " + extents +
                       " into a whole number of cells in every direction, or give `cells` (cells per "
                       "direction) instead of cell_size");
    }
    if (whole > double(std::numeric_limits<int>::max())) {
      throw InputError(given + "it makes " + showRounded(whole) + " cells in " + axes[i] + ", more than the " +
                       std::to_string(std::numeric_limits<int>::max()) +
                       " a direction may have; use a larger cell_size");
    }
    cells[i] = static_cast<int>(whole);
  }
  return cells;
}

DomainSpec readDomain(ParameterList& list)
{
  const std::string path = kRoot + ".domain";
  const ParameterList& valid = validSceneParameters()->sublist("domain");
  // The dimension first: it sets the length of every per-direction list.
  if (!list.isParameter("dimension")) throw missingKey(path + ".dimension", valid.getEntry("dimension"), 0);
  checkEntry(list.getEntry("dimension"), valid.getEntry("dimension"), path + ".dimension", 0);
  const int dimension = list.get<int>("dimension");
  checkKeys(list, valid, path, dimension);

  DomainSpec domain;
  domain.dimension = dimension;
  domain.lower = padded<double>(list.get<Array<double>>("lower"), 0.0);
  domain.upper = padded<double>(list.get<Array<double>>("upper"), 1.0);
  for (int i = 0; i < dimension; ++i) {
    if (!(domain.upper[i] > domain.lower[i])) {
      throw inputError(path + ".upper", showPoint(domain.upper, dimension),
                       "must be above lower = " + showPoint(domain.lower, dimension) + " in every direction");
    }
  }

  // The cells: counted per direction (`cells`) or from one edge length (`cell_size`), never both.
  // From here on the list holds `cells` either way, as if the file had given it.
  const bool cells_given = list.isParameter("cells");
  const bool size_given = list.isParameter("cell_size");
  if (cells_given == size_given) {
    throw InputError(path + ": " +
                     (cells_given ? "both `cells` (" + showValue(list.getEntry("cells")) + ") and `cell_size` (" +
                                        showValue(list.getEntry("cell_size")) + ") are given"
                                  : std::string("neither `cells` nor `cell_size` is given")) +
                     "; give exactly one of them: " + path + ".cells, " + std::to_string(dimension) +
                     " integers (the cells per direction), or " + path +
                     ".cell_size, a number > 0 (m) (the cells' edge length, the same in every direction)");
  }
  if (size_given) list.set("cells", cellsOfSize(list, path, dimension, domain.lower, domain.upper));
  const Array<int> cells = list.get<Array<int>>("cells");
  if (!list.isParameter("patch_cells")) {
    Array<int> patch_cells(dimension);
    for (int i = 0; i < dimension; ++i) patch_cells[i] = std::min(16, cells[i]);
    list.set("patch_cells", patch_cells);
  }
  setDefaults(list, valid, path);
  if (!size_given) list.remove("cell_size");  // not given: no default stands in for it

  domain.cells = padded<long long>(cells, 1LL);
  domain.patch_cells = padded<long long>(list.get<Array<int>>("patch_cells"), 1LL);
  for (int i = 0; i < 3; ++i) domain.patch_cells[i] = std::min(domain.patch_cells[i], domain.cells[i]);
  domain.ghost_width = list.get<int>("ghost_width");
  domain.gravity = padded<double>(list.get<Array<double>>("gravity"), 0.0);
  domain.rebalance_interval = list.get<int>("rebalance_interval");
  return domain;
}

// The equation of state of a fluid or the model of a solid: a section whose keys depend on `type`.
std::string readTyped(ParameterList& list, const std::string& path, int dimension,
                      Teuchos::RCP<const ParameterList> (*templateFor)(const std::string&),
                      const std::vector<std::string>& types)
{
  const std::string type = selectorValue(list, "type", *templateFor(types.front()), path);
  const ParameterList& valid = *templateFor(type);
  checkKeys(list, valid, path, dimension);
  if (type == "rigid") setIfMissing(list, "velocity", Array<double>(dimension, 0.0));
  setDefaults(list, valid, path);
  return type;
}

}  // namespace

std::string defaultInteriorPressure(const std::string& model_type)
{
  // A plastic body's particles shear off their lattice (the seed scene's sand); an elastic body's
  // stay on it, and its interior takes the pressure that the pressure equation solved for.
  return model_type == "tresca" || model_type == "drucker_prager" ? "reference" : "cell";
}

namespace {

std::vector<MaterialSpec> readMaterials(ParameterList& section, int dimension)
{
  const std::string path = kRoot + ".materials";
  if (section.numParams() == 0) {
    throw inputError(path, "{}", "at least one material is required (a fluid to fill the background)");
  }
  std::vector<MaterialSpec> materials;
  for (const std::string& name : keysOf(section)) {
    const std::string material_path = path + "." + name;
    ParameterList& list = namedEntry(section, name, path, "material");
    const std::string kind = selectorValue(list, "kind", *validMaterialParameters("fluid"), material_path);
    const ParameterList& valid = *validMaterialParameters(kind);
    checkKeys(list, valid, material_path, dimension);

    if (kind == "fluid") {
      ParameterList& eos = list.sublist("equation_of_state");
      const std::string eos_path = material_path + ".equation_of_state";
      const std::string type =
          readTyped(eos, eos_path, dimension, validEquationOfStateParameters, equationOfStateTypes());
      if (type == "ideal_gas") {
        // c_v of an ideal gas follows from its equation of state: R = (gamma - 1) c_v.
        const double cv = eos.get<double>("gas_constant") / (eos.get<double>("gamma") - 1);
        if (!list.isParameter("specific_heat")) list.set("specific_heat", cv);
        const double given = list.get<double>("specific_heat");
        if (std::abs(given - cv) > 1e-9 * cv) {
          throw inputError(material_path + ".specific_heat", showNumber(given),
                           "an ideal gas has c_v = gas_constant / (gamma - 1) = " + showNumber(cv) +
                               " J/(kg K); leave specific_heat out or change gas_constant");
        }
      } else if (!list.isParameter("specific_heat")) {
        throw InputError(material_path + ".specific_heat: required key is missing for equation_of_state type '" +
                         type + "'; expected a number; " + ruleOf(valid.getEntry("specific_heat"))->allowed());
      }
    } else {
      ParameterList& model = list.sublist("model");
      const std::string model_path = material_path + ".model";
      const std::string type = readTyped(model, model_path, dimension, validSolidModelParameters, solidModelTypes());
      if (!list.isParameter("interior_pressure")) list.set("interior_pressure", defaultInteriorPressure(type));
      if (type == "drucker_prager") {
        const double friction = model.get<double>("friction_angle");
        if (model.get<double>("dilatancy_angle") > friction) {
          throw inputError(model_path + ".dilatancy_angle", showNumber(model.get<double>("dilatancy_angle")),
                           "must be <= friction_angle (" + showNumber(friction) + " degree)");
        }
        if (friction == 0 && !(model.get<double>("cohesion") > 0)) {
          throw inputError(model_path + ".cohesion", showNumber(model.get<double>("cohesion")),
                           "must be > 0 (Pa) when friction_angle is 0, or the material has no strength");
        }
      }
    }
    setDefaults(list, valid, material_path);
    materials.push_back(MaterialSpec{name, kind, list});
  }
  return materials;
}

std::vector<std::string> materialNames(const std::vector<MaterialSpec>& materials, const std::string& kind = "")
{
  std::vector<std::string> names;
  for (const auto& material : materials)
    if (kind.empty() || material.kind == kind) names.push_back(material.name);
  return names;
}

/// A fixed section of the root (no per-direction keys): its keys checked and its defaults filled in.
ParameterList& checkedSection(ParameterList& list, const std::string& name)
{
  const std::string path = kRoot + "." + name;
  const ParameterList& valid = validSceneParameters()->sublist(name);
  checkKeys(list, valid, path, 0);
  setDefaults(list, valid, path);
  return list;
}

/// The `ice` section, read by the ICE solver: checked as a fixed section, with the solid-fluid
/// exchange coefficient following the fluids' unless given.
void checkIce(ParameterList& list)
{
  const std::string path = kRoot + ".ice";
  const ParameterList& valid = validSceneParameters()->sublist("ice");
  checkKeys(list, valid, path, 0);
  if (!list.isParameter("solid_exchange_coefficient") && list.isParameter("exchange_coefficient"))
    list.set("solid_exchange_coefficient", list.get<double>("exchange_coefficient"));
  setDefaults(list, valid, path);
}

InitialStateSpec readInitialState(ParameterList& list, const std::vector<MaterialSpec>& materials)
{
  const std::string path = kRoot + ".initial_state";
  checkedSection(list, "initial_state");

  InitialStateSpec initial;
  initial.background_material = list.get<std::string>("background_material");
  initial.temperature = list.get<double>("temperature");
  initial.pressure = list.get<double>("pressure");
  initial.hydrostatic = list.get<bool>("hydrostatic");

  const std::vector<std::string> fluids = materialNames(materials, "fluid");
  const auto names = materialNames(materials);
  if (std::find(names.begin(), names.end(), initial.background_material) == names.end()) {
    throw inputError(path + ".background_material", initial.background_material,
                     "must name a fluid material; known materials: " + join(names));
  }
  if (std::find(fluids.begin(), fluids.end(), initial.background_material) == fluids.end()) {
    throw inputError(path + ".background_material", initial.background_material,
                     "must name a fluid material; fluids: " +
                         (fluids.empty() ? std::string("none (every scene has a background fluid; a dry scene of solids "
                                                       "alone declares one, e.g. air, and sets ice.enabled: false, as "
                                                       "input/granular-column.yaml does)")
                                         : join(fluids)));
  }
  return initial;
}

// Box corners and polygon vertices must lie in the domain, up to round-off in its size.
bool insideDomain(const DomainSpec& domain, int direction, double x)
{
  const double tolerance = 1e-12 * (domain.upper[direction] - domain.lower[direction]);
  return x >= domain.lower[direction] - tolerance && x <= domain.upper[direction] + tolerance;
}

std::string domainRange(const DomainSpec& domain, int dimensions)
{
  const char* axis = "xyz";
  std::string text;
  for (int i = 0; i < dimensions; ++i) {
    text += std::string(i ? ", " : "") + axis[i] + " in [" + showNumber(domain.lower[i]) + ", " +
            showNumber(domain.upper[i]) + "]";
  }
  return text;
}

void checkRegionGeometry(const RegionSpec& region, const DomainSpec& domain, const std::string& path)
{
  const int dimension = domain.dimension;
  if (region.shape == "box") {
    for (const auto& [key, corner] : {std::pair{"lower", region.lower}, std::pair{"upper", region.upper}}) {
      for (int i = 0; i < dimension; ++i) {
        if (!insideDomain(domain, i, corner[i])) {
          throw inputError(path + "." + key, showPoint(corner, dimension),
                           "must lie inside the domain: " + domainRange(domain, dimension));
        }
      }
    }
    for (int i = 0; i < dimension; ++i) {
      if (!(region.upper[i] > region.lower[i])) {
        throw inputError(path + ".upper", showPoint(region.upper, dimension),
                         "must be above lower = " + showPoint(region.lower, dimension) + " in every direction");
      }
    }
  } else if (region.shape == "polygon") {
    for (size_t k = 0; k < region.vertices.size(); ++k) {
      const auto& vertex = region.vertices[k];
      if (!insideDomain(domain, 0, vertex[0]) || !insideDomain(domain, 1, vertex[1])) {
        throw inputError(path + ".vertices", showPoint({vertex[0], vertex[1], 0}, 2),
                         "vertex " + std::to_string(k + 1) + " must lie inside the domain: " + domainRange(domain, 2));
      }
    }
  } else {
    double length = 0;
    for (int i = 0; i < dimension; ++i) length += region.normal[i] * region.normal[i];
    if (!(length > 0)) throw inputError(path + ".normal", showPoint(region.normal, dimension), "must not be zero");
  }
}

std::vector<RegionSpec> readRegions(ParameterList& section, const Scene& scene)
{
  const std::string path = kRoot + ".regions";
  const int dimension = scene.domain.dimension;
  std::vector<RegionSpec> regions;
  for (const std::string& name : keysOf(section)) {
    const std::string region_path = path + "." + name;
    ParameterList& list = namedEntry(section, name, path, "region");
    const std::string shape = selectorValue(list, "shape", *validRegionParameters("box"), region_path);
    const ParameterList& valid = *validRegionParameters(shape);
    checkKeys(list, valid, region_path, dimension);
    setIfMissing(list, "velocity", Array<double>(dimension, 0.0));
    setIfMissing(list, "temperature", scene.initial.temperature);
    setDefaults(list, valid, region_path);

    RegionSpec region;
    region.name = name;
    region.material = list.get<std::string>("material");
    region.shape = shape;
    region.velocity = padded<double>(list.get<Array<double>>("velocity"), 0.0);
    region.temperature = list.get<double>("temperature");
    if (shape == "box") {
      region.lower = padded<double>(list.get<Array<double>>("lower"), 0.0);
      region.upper = padded<double>(list.get<Array<double>>("upper"), 0.0);
    } else if (shape == "polygon") {
      const auto& vertices = list.get<TwoDArray<double>>("vertices");
      if (vertices.getNumCols() != 2 || vertices.getNumRows() < 3) {
        throw inputError(region_path + ".vertices", showValue(list.getEntry("vertices")),
                         "must be a list of at least 3 points [x, y]");
      }
      for (Teuchos::Ordinal k = 0; k < vertices.getNumRows(); ++k)
        region.vertices.push_back({vertices(k, 0), vertices(k, 1)});
    } else {
      region.point = padded<double>(list.get<Array<double>>("point"), 0.0);
      region.normal = padded<double>(list.get<Array<double>>("normal"), 0.0);
    }

    const auto names = materialNames(scene.materials);
    if (std::find(names.begin(), names.end(), region.material) == names.end()) {
      throw inputError(region_path + ".material", region.material, "known materials: " + join(names));
    }
    checkRegionGeometry(region, scene.domain, region_path);
    if (shape == "half_plane") {  // unit normal for the users of RegionSpec
      const double length = std::sqrt(region.normal[0] * region.normal[0] + region.normal[1] * region.normal[1] +
                                       region.normal[2] * region.normal[2]);
      for (double& component : region.normal) component /= length;
    }
    regions.push_back(region);
  }
  return regions;
}

std::vector<BoundarySpec> readBoundaries(ParameterList& section, int dimension, double initial_temperature)
{
  const std::string path = kRoot + ".boundary_conditions";
  const std::vector<std::string> faces = boundaryFaces(dimension);
  for (const std::string& key : keysOf(section)) {
    if (std::find(faces.begin(), faces.end(), key) == faces.end()) {
      throw InputError(path + "." + key + ": unknown key; allowed keys in " + path + ": " + join(faces) +
                       (dimension == 2 ? " (z-, z+ only in 3-D)" : ""));
    }
  }
  const ParameterList& valid = *validBoundaryParameters();
  std::vector<BoundarySpec> boundaries;
  for (const std::string& face : faces) {
    const std::string face_path = path + "." + face;
    if (section.isParameter(face) && !section.isSublist(face)) {
      throw InputError(face_path + ": got '" + showValue(section.getEntry(face)) + "' (" +
                       givenType(section.getEntry(face)) + "); expected a section with the face's keys");
    }
    ParameterList& list = section.sublist(face);
    checkKeys(list, valid, face_path, dimension);
    setIfMissing(list, "temperature_value", initial_temperature);
    setDefaults(list, valid, face_path);
    boundaries.push_back(BoundarySpec{face, list.get<std::string>("velocity"), list.get<std::string>("temperature"),
                                      list.get<double>("temperature_value")});
  }
  return boundaries;
}

TimeSpec readTime(ParameterList& list)
{
  const std::string path = kRoot + ".time";
  checkedSection(list, "time");

  TimeSpec time;
  time.end_time = list.get<double>("end_time");
  time.cfl = list.get<double>("cfl");
  time.dt_initial = list.get<double>("dt_initial");
  time.dt_min = list.get<double>("dt_min");
  time.dt_max = list.get<double>("dt_max");
  time.max_steps = list.get<long long>("max_steps");
  time.step_retries = list.get<int>("step_retries");
  if (time.dt_min > time.dt_max) {
    throw inputError(path + ".dt_min", showNumber(time.dt_min), "must be <= dt_max (" + showNumber(time.dt_max) + " s)");
  }
  if (time.dt_initial < time.dt_min || time.dt_initial > time.dt_max) {
    throw inputError(path + ".dt_initial", showNumber(time.dt_initial),
                     "must be in [dt_min, dt_max] = [" + showNumber(time.dt_min) + ", " + showNumber(time.dt_max) +
                         "] (s)");
  }
  return time;
}

MpmSpec readMpm(ParameterList& list)
{
  checkedSection(list, "mpm");
  MpmSpec mpm;
  mpm.shape_function = list.get<std::string>("shape_function");
  mpm.flip_fraction = list.get<double>("flip_fraction");
  mpm.stress_update = list.get<std::string>("stress_update");
  mpm.wall_friction = list.get<double>("wall_friction");
  mpm.contact = list.get<bool>("contact");
  mpm.contact_friction = list.get<double>("contact_friction");
  mpm.velocity_damping = list.get<double>("velocity_damping");
  mpm.face_layer = list.get<double>("face_layer");
  mpm.coupling = list.get<std::string>("coupling");
  mpm.solid_volume = list.get<std::string>("solid_volume");
  mpm.substeps = list.get<int>("substeps");
  return mpm;
}

OutputSpec readOutput(ParameterList& list)
{
  const std::string path = kRoot + ".output";
  checkedSection(list, "output");

  OutputSpec output;
  output.directory = list.get<std::string>("directory");
  output.interval = list.get<double>("interval");
  const auto& fields = list.get<Array<std::string>>("fields");
  output.fields.assign(fields.begin(), fields.end());
  output.overwrite = list.get<bool>("overwrite");
  output.progress_interval = list.get<double>("progress_interval");
  output.checkpoint_interval = list.get<double>("checkpoint_interval");
  output.checkpoint_wall_interval = list.get<double>("checkpoint_wall_interval");
  output.checkpoints_kept = list.get<int>("checkpoints_kept");
  if (output.directory.empty()) throw inputError(path + ".directory", "", "must name a directory");
  for (size_t i = 0; i < output.fields.size(); ++i) {
    if (std::find(output.fields.begin(), output.fields.begin() + i, output.fields[i]) != output.fields.begin() + i) {
      throw inputError(path + ".fields", showValue(list.getEntry("fields")),
                       "'" + output.fields[i] + "' is listed twice; list each field once");
    }
  }
  return output;
}

}  // namespace

int Scene::materialIndex(const std::string& name) const
{
  for (size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == name) return static_cast<int>(i);
  throw inputError("material", name, "known materials: " + join(materialNames(materials)));
}

Scene readScene(const std::string& path)
{
  return readSceneText(readText(path), path);
}

Scene readSceneText(const std::string& file_text, const std::string& path)
{
  // 1. The file: one top-level key `cfdmpm`, valid YAML.
  const std::string text = screenText(file_text, path);
  refuseOtherTopLevelKeys(text, path);
  WrittenValues written;
  SceneIndexer(path, written).read(text);
  RCP<ParameterList> root = parseYaml(text, path);
  struct WrittenValuesScope {
    explicit WrittenValuesScope(const WrittenValues& values) { g_written_values = &values; }
    ~WrittenValuesScope() { g_written_values = nullptr; }
  } written_scope(written);

  Scene scene;
  scene.path = path;
  scene.text = file_text;
  scene.parameters = root;
  try {
    // 2. The top level: known sections of the right type, required ones present, optional ones added.
    const ParameterList& valid = *validSceneParameters();
    checkKeys(*root, valid, kRoot, 0);
    setDefaults(*root, valid, kRoot);

    // 3. Each section, the domain first (its dimension sets the length of per-direction lists),
    //    then the materials (regions and the background refer to them).
    scene.title = root->get<std::string>("title");
    scene.domain = readDomain(root->sublist("domain"));
    scene.materials = readMaterials(root->sublist("materials"), scene.domain.dimension);
    scene.initial = readInitialState(root->sublist("initial_state"), scene.materials);
    scene.regions = readRegions(root->sublist("regions"), scene);
    scene.boundaries = readBoundaries(root->sublist("boundary_conditions"), scene.domain.dimension,
                                      scene.initial.temperature);
    scene.time = readTime(root->sublist("time"));
    scene.output = readOutput(root->sublist("output"));
    scene.mpm = readMpm(root->sublist("mpm"));
    checkIce(root->sublist("ice"));  // read by the ICE solver (IceSettings::fromScene)

    // 4. The scene as a whole: what the regions place, the solvers' own settings, derived
    //    quantities, the grid's size (input/scene_checks.hpp).
    checkSceneAsAWhole(scene);
  } catch (const InputError& error) {
    throw InputError(path + ": " + error.what());
  }
  return scene;
}

}  // namespace cfdmpm
