#pragma once
// The progress line on the terminal (rank 0):
//
//   step 1200  t = 0.12345 s (15.4 %)  dt = 1.0234e-04 s  wall 0:01:23  ETA 0:07:36
//
// printed at the first step, at the last, and in between at most once every `interval` seconds of
// wall time. The ETA assumes the wall time per simulated second seen so far.
#include <mpi.h>

#include <functional>
#include <iosfwd>
#include <string>

namespace cfdmpm {

/// The line's text (no newline). ETA is "?" while no simulated time has passed.
std::string progressLine(long long step, double time, double dt, double start_time, double end_time,
                         double wall_seconds);

/// "h:mm:ss", rounded down to whole seconds.
std::string formatWallTime(double seconds);

class ProgressReporter {
 public:
  /// Seconds of wall time, from any fixed origin; tests pass their own clock.
  using Clock = std::function<double()>;

  /// Wall time is counted from construction; the simulation runs from start_time to end_time (s).
  ProgressReporter(MPI_Comm comm, double start_time, double end_time, double interval_seconds,
                   std::ostream& out, Clock clock = {});
  /// Reports to std::cout.
  ProgressReporter(MPI_Comm comm, double start_time, double end_time, double interval_seconds);

  /// Call after every step on every rank (no communication). Prints on rank 0 when this is the
  /// first call, when `last` is true, or when `interval` seconds have passed since the last line.
  /// Returns whether a line was printed.
  bool update(long long step, double time, double dt, bool last = false);

 private:
  bool print_;  // rank 0
  double start_time_;
  double end_time_;
  double interval_;
  std::ostream& out_;
  Clock clock_;
  double wall_start_;
  double last_printed_ = 0;
  bool printed_any_ = false;
};

}  // namespace cfdmpm
