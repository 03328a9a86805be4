// The progress line: its numbers (percent, wall time, ETA from wall time per simulated second) and
// when it is printed (first step, last step, at most once per interval in between, rank 0 only).
#include "io/progress.hpp"
#include "io_test_support.hpp"

#include <gtest/gtest.h>

namespace cfdmpm {
namespace {

using namespace io_test;

TEST(Progress, LineShowsStepTimePercentDtWallTimeAndEta)
{
  // 30 s of wall time for 0.25 s simulated: 120 s per simulated second, 0.75 s to go -> 90 s.
  EXPECT_EQ(progressLine(1200, 0.25, 1.0234e-4, 0.0, 1.0, 30.0),
            "step 1200  t = 0.25 s (25.0 %)  dt = 1.0234e-04 s  wall 0:00:30  ETA 0:01:30");
  // Restarted at t = 0.5: the rate counts only the time simulated since then.
  EXPECT_EQ(progressLine(10, 0.75, 1e-3, 0.5, 1.0, 3600.0),
            "step 10  t = 0.75 s (75.0 %)  dt = 1.0000e-03 s  wall 1:00:00  ETA 1:00:00");
  EXPECT_EQ(progressLine(0, 0.0, 1e-5, 0.0, 2.0, 0.0),
            "step 0  t = 0 s (0.0 %)  dt = 1.0000e-05 s  wall 0:00:00  ETA ?");
}

TEST(Progress, WallTimeIsHoursMinutesSeconds)
{
  EXPECT_EQ(formatWallTime(3725.9), "1:02:05");
  EXPECT_EQ(formatWallTime(59.99), "0:00:59");
  EXPECT_EQ(formatWallTime(-1.0), "0:00:00");
  EXPECT_EQ(formatWallTime(100 * 3600.0), "100:00:00");
}

TEST(Progress, PrintedAtFirstAndLastStepAndAtMostOncePerInterval)
{
  double wall = 100.0;  // the test's clock, s
  std::ostringstream out;
  ProgressReporter progress(MPI_COMM_WORLD, 0.0, 1.0, 10.0, out, [&] { return wall; });
  const bool rank_zero = rank() == 0;
  struct Call { double wall; bool last; bool printed; };
  const std::vector<Call> calls{{100.0, false, true},   // first step
                                {101.0, false, false},
                                {109.9, false, false},  // 9.9 s since the last line
                                {110.0, false, true},   // 10 s
                                {115.0, false, false},
                                {116.0, true, true}};   // last step
  long long step = 0;
  for (const Call& call : calls) {
    wall = call.wall;
    ++step;
    EXPECT_EQ(progress.update(step, 0.01 * step, 0.01, call.last), rank_zero && call.printed)
        << "at wall time " << call.wall;
  }
  const std::vector<std::string> expected_lines{
      progressLine(1, 0.01 * 1, 0.01, 0.0, 1.0, 0.0), progressLine(4, 0.01 * 4, 0.01, 0.0, 1.0, 10.0),
      progressLine(6, 0.01 * 6, 0.01, 0.0, 1.0, 16.0)};
  std::string expected;
  for (const std::string& line : expected_lines) expected += line + "\n";
  EXPECT_EQ(out.str(), rank_zero ? expected : std::string());
}

}  // namespace
}  // namespace cfdmpm
