#pragma once
// Stopping a run cleanly on SIGINT (Ctrl-C) or SIGTERM (a batch system's time limit).
//
// The handler only sets a flag; the driver asks stopRequested() once per step, and when it is true
// on any rank it is true on all of them, so every rank finishes the current output together and
// exits. Output files are written under a temporary name and renamed when complete, so even a run
// killed outright (SIGKILL) leaves only complete files behind. The handler restores the default
// action when it runs: a second Ctrl-C ends the program at once.
#include <mpi.h>

namespace cfdmpm {

/// Installs the SIGINT and SIGTERM handlers (again after they have fired, too).
void installStopSignalHandlers();

/// True on every rank if any rank has received SIGINT or SIGTERM since the handlers were
/// installed. Collective (one MPI_Allreduce).
bool stopRequested(MPI_Comm comm);

/// The signal this rank received (SIGINT or SIGTERM), 0 if none.
int receivedStopSignal();

/// Forgets a received signal (for tests and for a driver that decides to go on).
void clearStopRequest();

}  // namespace cfdmpm
