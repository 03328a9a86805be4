#include "io/progress.hpp"

#include "io/collective.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

namespace cfdmpm {

std::string formatWallTime(double seconds)
{
  const long long total = seconds > 0 ? static_cast<long long>(std::floor(seconds)) : 0;
  char text[48];
  std::snprintf(text, sizeof text, "%lld:%02lld:%02lld", total / 3600, total / 60 % 60, total % 60);
  return text;
}

std::string progressLine(long long step, double time, double dt, double start_time, double end_time,
                         double wall_seconds)
{
  const double percent = end_time > 0 ? 100.0 * time / end_time : 0.0;
  std::string eta = "?";
  if (time > start_time && end_time > start_time) {
    const double wall_per_simulated_second = wall_seconds / (time - start_time);
    eta = formatWallTime(std::max(0.0, end_time - time) * wall_per_simulated_second);
  }
  char text[256];
  std::snprintf(text, sizeof text, "step %lld  t = %.6g s (%.1f %%)  dt = %.4e s  wall %s  ETA %s",
                step, time, percent, dt, formatWallTime(wall_seconds).c_str(), eta.c_str());
  return text;
}

namespace {
double steadySeconds()
{
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}
}  // namespace

ProgressReporter::ProgressReporter(MPI_Comm comm, double start_time, double end_time,
                                   double interval_seconds, std::ostream& out, Clock clock)
    : print_(io_detail::rankOf(comm) == 0),
      start_time_(start_time),
      end_time_(end_time),
      interval_(interval_seconds),
      out_(out),
      clock_(clock ? std::move(clock) : Clock(steadySeconds)),
      wall_start_(clock_())
{
}

ProgressReporter::ProgressReporter(MPI_Comm comm, double start_time, double end_time,
                                   double interval_seconds)
    : ProgressReporter(comm, start_time, end_time, interval_seconds, std::cout)
{
}

bool ProgressReporter::update(long long step, double time, double dt, bool last)
{
  if (!print_) return false;
  const double now = clock_();
  if (printed_any_ && !last && now - last_printed_ < interval_) return false;
  // One insertion of the whole line, then flush: lines never interleave with other output.
  out_ << progressLine(step, time, dt, start_time_, end_time_, now - wall_start_) + "\n" << std::flush;
  printed_any_ = true;
  last_printed_ = now;
  return true;
}

}  // namespace cfdmpm
