#pragma once
// Internal to io/: run file-system work on rank 0 and make every rank agree on the outcome, so an
// error seen by rank 0 (a full disk, a refused directory) is thrown on all ranks instead of leaving
// the others waiting in the next collective call.
#include "common/error.hpp"

#include <mpi.h>

#include <stdexcept>
#include <string>

namespace cfdmpm::io_detail {

inline int rankOf(MPI_Comm comm)
{
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

/// Broadcasts an outcome from rank 0 and throws it on every rank: kind 0 = success,
/// 1 = InputError, 2 = std::runtime_error.
inline void agreeOnOutcome(MPI_Comm comm, int kind, std::string message)
{
  int header[2] = {kind, static_cast<int>(message.size())};
  MPI_Bcast(header, 2, MPI_INT, 0, comm);
  if (header[0] == 0) return;
  message.resize(static_cast<std::size_t>(header[1]));
  MPI_Bcast(message.data(), header[1], MPI_CHAR, 0, comm);
  if (header[0] == 1) throw InputError(message);
  throw std::runtime_error(message);
}

/// Runs `work` on rank 0 only; collective. Whatever it throws is rethrown on every rank
/// (InputError stays InputError, anything else becomes std::runtime_error with the same message).
template <class Work>
void onRankZero(MPI_Comm comm, Work&& work)
{
  int kind = 0;
  std::string message;
  if (rankOf(comm) == 0) {
    try {
      work();
    } catch (const InputError& e) {
      kind = 1;
      message = e.what();
    } catch (const std::exception& e) {
      kind = 2;
      message = e.what();
    }
  }
  agreeOnOutcome(comm, kind, std::move(message));
}

/// True on every rank if `local_failure` is true on any rank.
inline bool anyRank(MPI_Comm comm, bool local_failure)
{
  int local = local_failure ? 1 : 0, any = 0;
  MPI_Allreduce(&local, &any, 1, MPI_INT, MPI_MAX, comm);
  return any != 0;
}

}  // namespace cfdmpm::io_detail
