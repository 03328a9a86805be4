#pragma once
// The MPI communicator behind a Teuchos communicator, for the modules that call MPI or MPI-IO
// directly (output, particle migration).
#include <Teuchos_Comm.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_RCP.hpp>

#include <mpi.h>

namespace cfdmpm {

inline MPI_Comm rawMpiComm(const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  return *Teuchos::rcp_dynamic_cast<const Teuchos::MpiComm<int>>(comm, true)->getRawMpiComm();
}

}  // namespace cfdmpm
