// SIGINT/SIGTERM: a signal on one rank makes stopRequested true on every rank, and the handler
// gives the signal its default action back so that a second one ends the program.
#include "io/signals.hpp"
#include "io_test_support.hpp"

#include <gtest/gtest.h>

#include <csignal>

#include <signal.h>

namespace cfdmpm {
namespace {

using namespace io_test;

TEST(Signals, SignalOnOneRankStopsEveryRank)
{
  installStopSignalHandlers();
  EXPECT_FALSE(stopRequested(MPI_COMM_WORLD));
  const bool signalled = rank() == size() - 1;
  if (signalled) std::raise(SIGTERM);
  EXPECT_TRUE(stopRequested(MPI_COMM_WORLD));
  EXPECT_EQ(receivedStopSignal(), signalled ? SIGTERM : 0);

  // The handler ran once and restored the default action.
  struct sigaction current;
  sigaction(SIGTERM, nullptr, &current);
  if (signalled) {
    EXPECT_EQ(current.sa_handler, SIG_DFL);
  }

  clearStopRequest();
  EXPECT_FALSE(stopRequested(MPI_COMM_WORLD));
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

TEST(Signals, InterruptIsCaughtLikeTerminate)
{
  installStopSignalHandlers();
  if (rank() == 0) std::raise(SIGINT);
  EXPECT_TRUE(stopRequested(MPI_COMM_WORLD));
  EXPECT_EQ(receivedStopSignal(), rank() == 0 ? SIGINT : 0);
  clearStopRequest();
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

}  // namespace
}  // namespace cfdmpm
