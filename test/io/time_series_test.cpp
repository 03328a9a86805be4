// The CSV time series: header from the registered columns, rows that read back to the very numbers
// written, each row on disk as soon as it is appended.
#include "io/time_series.hpp"
#include "io_test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

namespace cfdmpm {
namespace {

using namespace io_test;

std::vector<std::string> lines(const std::string& text)
{
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::vector<std::string> splitCommas(const std::string& line)
{
  std::vector<std::string> fields;
  std::size_t start = 0, end;
  while ((end = line.find(',', start)) != std::string::npos) {
    fields.push_back(line.substr(start, end - start));
    start = end + 1;
  }
  fields.push_back(line.substr(start));
  return fields;
}

TEST(CsvTimeSeries, HeaderAndRowsReadBackToTheNumbersWritten)
{
  const std::string path = freshDirectory("csv") + "/run.csv";
  const std::vector<std::string> columns{"step", "time", "dt", "dt_limiter", "pressure_iterations",
                                         "outer_iterations", "mass_water"};
  // Numbers that need all 17 digits, extremes and a negative zero.
  const std::vector<double> times{0.0, 0.1, 1.0 / 3.0, 2.0 / 3.0 + 1e-12};
  const std::vector<double> dts{1e-300, 6.02214076e23, std::acos(-1.0), -0.0};
  const std::vector<double> masses{1000.0 / 7.0, 1e-17, 123456789.123456789, 5e-324};
  const std::vector<std::string> limiters{"cfl", "dt_max", "growth", "cfl"};
  {
    CsvTimeSeries series(MPI_COMM_WORLD, path, columns);
    for (int row = 0; row < 4; ++row)
      series.append({row * 10LL, times[row], dts[row], limiters[row], 3 + row, 2, masses[row]});
  }
  if (rank() == 0) {
    const std::vector<std::string> text = lines(readText(path));
    ASSERT_EQ(text.size(), 5u);
    EXPECT_EQ(text[0], "step,time,dt,dt_limiter,pressure_iterations,outer_iterations,mass_water");
    for (int row = 0; row < 4; ++row) {
      const std::vector<std::string> fields = splitCommas(text[row + 1]);
      ASSERT_EQ(fields.size(), columns.size()) << text[row + 1];
      EXPECT_EQ(std::atoll(fields[0].c_str()), row * 10LL);
      // Exact: %.17g round-trips every double.
      EXPECT_EQ(std::strtod(fields[1].c_str(), nullptr), times[row]);
      EXPECT_EQ(std::strtod(fields[2].c_str(), nullptr), dts[row]);
      EXPECT_EQ(fields[3], limiters[row]);
      EXPECT_EQ(std::atoll(fields[4].c_str()), 3 + row);
      EXPECT_EQ(std::atoll(fields[5].c_str()), 2);
      EXPECT_EQ(std::strtod(fields[6].c_str(), nullptr), masses[row]);
    }
    EXPECT_TRUE(std::signbit(std::strtod(splitCommas(text[4])[2].c_str(), nullptr)));
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(CsvTimeSeries, EachRowIsOnDiskAsSoonAsItIsAppended)
{
  const std::string path = freshDirectory("csv_flush") + "/run.csv";
  CsvTimeSeries series(MPI_COMM_WORLD, path, {"step", "time"});
  series.append({1, 0.5});
  if (rank() == 0) {
    EXPECT_EQ(readText(path), "step,time\n1,0.5\n");
  }
  series.append({2, 0.75});
  if (rank() == 0) {
    EXPECT_EQ(readText(path), "step,time\n1,0.5\n2,0.75\n");
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(CsvTimeSeries, TextWithCommaOrQuoteIsQuoted)
{
  EXPECT_EQ(CsvValue("cfl").text(), "cfl");
  EXPECT_EQ(CsvValue("a,b").text(), "\"a,b\"");
  EXPECT_EQ(CsvValue("say \"hi\"").text(), "\"say \"\"hi\"\"\"");
}

TEST(CsvTimeSeries, RowOfTheWrongLengthOrBadColumnsThrow)
{
  const std::string path = freshDirectory("csv_wrong") + "/run.csv";
  CsvTimeSeries series(MPI_COMM_WORLD, path, {"step", "time", "dt"});
  EXPECT_THROW(series.append({1, 0.5}), std::invalid_argument);
  EXPECT_THROW(CsvTimeSeries(MPI_COMM_WORLD, path, {"step", "step"}), std::invalid_argument);
}

}  // namespace
}  // namespace cfdmpm
