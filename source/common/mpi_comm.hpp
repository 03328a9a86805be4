#pragma once
// The MPI communicator behind a Teuchos communicator, for the modules that call MPI or MPI-IO
// directly (output, particle migration).
#include <Teuchos_Comm.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_RCP.hpp>

#include <mpi.h>

#include <string>

namespace cfdmpm {

inline MPI_Comm rawMpiComm(const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  return *Teuchos::rcp_dynamic_cast<const Teuchos::MpiComm<int>>(comm, true)->getRawMpiComm();
}

/// Every rank gets `text` as rank `root` has it (collective): a message that one rank composed, so
/// that all ranks report the same error.
inline std::string broadcastText(MPI_Comm comm, int root, std::string text)
{
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  long long length = rank == root ? static_cast<long long>(text.size()) : 0;
  MPI_Bcast(&length, 1, MPI_LONG_LONG, root, comm);
  text.resize(std::size_t(length));
  if (length > 0) MPI_Bcast(text.data(), int(length), MPI_CHAR, root, comm);
  return text;
}

}  // namespace cfdmpm
