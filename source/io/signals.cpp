#include "io/signals.hpp"

#include <csignal>
#include <cstring>
#include <stdexcept>
#include <string>

#include <signal.h>

namespace cfdmpm {
namespace {

volatile std::sig_atomic_t received_signal = 0;

extern "C" void recordStopSignal(int signal_number)
{
  // Only an async-signal-safe store here; SA_RESETHAND has already restored the default action.
  received_signal = signal_number;
}

}  // namespace

void installStopSignalHandlers()
{
  struct sigaction action;
  std::memset(&action, 0, sizeof action);
  action.sa_handler = recordStopSignal;
  sigemptyset(&action.sa_mask);
  // SA_RESETHAND: a second signal takes the default action (ends the program).
  // SA_RESTART: a blocking system call interrupted by the signal resumes instead of failing.
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  for (int signal_number : {SIGINT, SIGTERM})
    if (sigaction(signal_number, &action, nullptr) != 0)
      throw std::runtime_error("cannot install the handler for signal " + std::to_string(signal_number));
}

bool stopRequested(MPI_Comm comm)
{
  int local = received_signal != 0 ? 1 : 0, any = 0;
  MPI_Allreduce(&local, &any, 1, MPI_INT, MPI_MAX, comm);
  return any != 0;
}

int receivedStopSignal() { return received_signal; }

void clearStopRequest() { received_signal = 0; }

}  // namespace cfdmpm
