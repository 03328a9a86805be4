// GoogleTest main for tests that may run on several MPI ranks: initialises MPI and Kokkos
// (through Tpetra::ScopeGuard), prints only on rank 0, and fails on every rank when any rank fails.
#include <gtest/gtest.h>
#include <mpi.h>
#include <Tpetra_Core.hpp>

int main(int argc, char** argv)
{
  Tpetra::ScopeGuard tpetra(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);

  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }

  int local_failed = RUN_ALL_TESTS();
  int any_failed = 0;
  MPI_Allreduce(&local_failed, &any_failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return any_failed;
}
