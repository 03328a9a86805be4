#pragma once
// A CSV time series of diagnostics, one row per step, written by rank 0. The driver chooses the
// columns once (step, time, dt, dt_limiter, then its own: solver iterations, mass per material...)
// and appends a row per call. Numbers keep every digit (%.17g, so they read back bit for bit) and
// each row is flushed as a whole, so a run stopped at any moment leaves complete rows only.
#include <mpi.h>

#include <cstdio>
#include <string>
#include <vector>

namespace cfdmpm {

/// One cell of a row: a floating-point number, an integer or a text (quoted when it needs it).
class CsvValue {
 public:
  CsvValue(double value);
  CsvValue(float value) : CsvValue(static_cast<double>(value)) {}
  CsvValue(int value) : CsvValue(static_cast<long long>(value)) {}
  CsvValue(long value) : CsvValue(static_cast<long long>(value)) {}
  CsvValue(long long value);
  CsvValue(unsigned value) : CsvValue(static_cast<long long>(value)) {}
  CsvValue(unsigned long value) : CsvValue(static_cast<long long>(value)) {}
  CsvValue(unsigned long long value) : CsvValue(static_cast<long long>(value)) {}
  CsvValue(const char* text);
  CsvValue(const std::string& text);

  const std::string& text() const { return text_; }  // as it appears in the file

 private:
  std::string text_;
};

class CsvTimeSeries {
 public:
  /// Creates (truncates) `path` and writes the header row. Collective; every rank throws if the
  /// file cannot be written. Column names must be unique and non-empty.
  CsvTimeSeries(MPI_Comm comm, std::string path, std::vector<std::string> columns);
  /// Continues the series in `path` after a restart: the header must be `columns`; the rows of
  /// steps 0 to `last_step` (the first column) are kept and must all be there, in order; later rows
  /// are dropped (the file is rewritten through a temporary file and a rename). Collective; every
  /// rank throws InputError naming the file if it is missing or does not match.
  CsvTimeSeries(MPI_Comm comm, std::string path, std::vector<std::string> columns, long long last_step);
  ~CsvTimeSeries();
  CsvTimeSeries(const CsvTimeSeries&) = delete;
  CsvTimeSeries& operator=(const CsvTimeSeries&) = delete;

  /// Appends one row, values in column order (std::invalid_argument if the count differs).
  /// Collective: every rank calls it, rank 0's values are written and flushed.
  void append(const std::vector<CsvValue>& row);

  const std::vector<std::string>& columns() const { return columns_; }
  const std::string& path() const { return path_; }

 private:
  MPI_Comm comm_;
  std::string path_;
  std::vector<std::string> columns_;
  void checkColumns() const;

  std::FILE* file_ = nullptr;  // rank 0 only
};

}  // namespace cfdmpm
