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

void CsvTimeSeries::checkColumns() const
{
  std::set<std::string> seen;
  for (const std::string& column : columns_)
    if (column.empty() || !seen.insert(column).second)
      throw std::invalid_argument("time series " + path_ + ": column '" + column +
                                  "' is empty or repeated");
  if (columns_.empty()) throw std::invalid_argument("time series " + path_ + ": no columns");
}

CsvTimeSeries::CsvTimeSeries(MPI_Comm comm, std::string path, std::vector<std::string> columns)
    : comm_(comm), path_(std::move(path)), columns_(std::move(columns))
{
  checkColumns();

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

CsvTimeSeries::CsvTimeSeries(MPI_Comm comm, std::string path, std::vector<std::string> columns, long long last_step)
    : comm_(comm), path_(std::move(path)), columns_(std::move(columns))
{
  checkColumns();
  io_detail::onRankZero(comm_, [&] {
    std::FILE* old = std::fopen(path_.c_str(), "rb");
    if (!old) throw InputError("restart: cannot open the time series " + path_ + ": " + std::strerror(errno));
    std::string text;
    char buffer[1 << 16];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, old)) > 0) text.append(buffer, n);
    std::fclose(old);

    std::vector<std::string> header;
    for (const std::string& column : columns_) header.push_back(csvField(column));
    const std::string header_line = joined(header);
    if (text.compare(0, header_line.size(), header_line) != 0)
      throw InputError("restart: the time series " + path_ +
                       " does not have the columns this scene writes (a different scene or version?)");
    // Rows are whole lines (each written and flushed at once); the step is the first field.
    std::size_t end = header_line.size();
    for (long long step = 0; step <= last_step; ++step) {
      const std::size_t line_end = text.find('\n', end);
      const std::string first = line_end == std::string::npos ? "" : text.substr(end, text.find(',', end) - end);
      if (line_end == std::string::npos || first != std::to_string(step))
        throw InputError("restart: the time series " + path_ + " lacks the row of step " + std::to_string(step) +
                         " (the checkpoint is at step " + std::to_string(last_step) + ")");
      end = line_end + 1;
    }
    const std::string temporary = path_ + ".tmp";
    std::FILE* kept = std::fopen(temporary.c_str(), "wb");
    if (!kept) throw std::runtime_error("cannot create " + temporary + ": " + std::strerror(errno));
    const bool written = std::fwrite(text.data(), 1, end, kept) == end;
    if (std::fclose(kept) != 0 || !written || std::rename(temporary.c_str(), path_.c_str()) != 0)
      throw std::runtime_error("rewriting " + path_ + " failed: " + std::strerror(errno));
    file_ = std::fopen(path_.c_str(), "a");
    if (!file_) throw std::runtime_error("cannot append to " + path_ + ": " + std::strerror(errno));
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
