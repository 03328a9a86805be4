#include "io/time_series.hpp"

#include "io/collective.hpp"

#include <cerrno>
#include <cstring>
#include <set>
#include <stdexcept>

namespace cfdmpm {
namespace {

/// RFC 4180: a field with a comma, quote or line break is quoted, quotes doubled.
std::string csvField(const std::string& text)
{
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string joined(const std::vector<std::string>& fields)
{
  std::string line;
  for (std::size_t i = 0; i < fields.size(); ++i) line += (i ? "," : "") + fields[i];
  return line + "\n";
}

/// Writes the whole line and flushes it: a killed run keeps complete rows.
void writeLine(std::FILE* file, const std::string& line, const std::string& path)
{
  if (std::fwrite(line.data(), 1, line.size(), file) != line.size() || std::fflush(file) != 0)
    throw std::runtime_error("writing " + path + " failed: " + std::strerror(errno));
}

}  // namespace

CsvValue::CsvValue(double value)
{
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  text_ = text;
}

CsvValue::CsvValue(long long value) : text_(std::to_string(value)) {}

CsvValue::CsvValue(const char* text) : text_(csvField(text)) {}

CsvValue::CsvValue(const std::string& text) : text_(csvField(text)) {}

CsvTimeSeries::CsvTimeSeries(MPI_Comm comm, std::string path, std::vector<std::string> columns)
    : comm_(comm), path_(std::move(path)), columns_(std::move(columns))
{
  std::set<std::string> seen;
  for (const std::string& column : columns_)
    if (column.empty() || !seen.insert(column).second)
      throw std::invalid_argument("time series " + path_ + ": column '" + column +
                                  "' is empty or repeated");
  if (columns_.empty()) throw std::invalid_argument("time series " + path_ + ": no columns");

  io_detail::onRankZero(comm_, [&] {
    file_ = std::fopen(path_.c_str(), "w");
    if (!file_) throw std::runtime_error("cannot create " + path_ + ": " + std::strerror(errno));
    std::vector<std::string> header;
    for (const std::string& column : columns_) header.push_back(csvField(column));
    try {
      writeLine(file_, joined(header), path_);
    } catch (...) {
      std::fclose(file_);
      file_ = nullptr;
      throw;
    }
  });
}

CsvTimeSeries::~CsvTimeSeries()
{
  if (file_) std::fclose(file_);
}

void CsvTimeSeries::append(const std::vector<CsvValue>& row)
{
  if (row.size() != columns_.size())
    throw std::invalid_argument("time series " + path_ + ": a row has " + std::to_string(row.size()) +
                                " values for " + std::to_string(columns_.size()) + " columns");
  io_detail::onRankZero(comm_, [&] {
    std::vector<std::string> fields;
    for (const CsvValue& value : row) fields.push_back(value.text());
    writeLine(file_, joined(fields), path_);
  });
}

}  // namespace cfdmpm
