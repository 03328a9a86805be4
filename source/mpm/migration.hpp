#pragma once
// Particle migration between ranks: after the position update, every particle whose cell this rank
// does not own goes to the rank that owns the patch holding that cell (Decomposition::patch_owner),
// packed into one buffer per destination; counts go by MPI_Alltoall, the particles point to point
// between the ranks that exchange any. Nothing is lost or
// duplicated: a particle is removed here only when it is sent, and appended there when received.
#include "grid/layout.hpp"
#include "mpm/particles.hpp"

#include <mpi.h>

#include <string>

namespace cfdmpm::mpm {

struct MigrationCounts {
  long long sent = 0;      ///< particles this rank sent
  long long received = 0;  ///< particles this rank received
};

template <int Dim>
class ParticleMigration {
 public:
  explicit ParticleMigration(const Layout<Dim>& layout);

  /// Collective. Moves every particle to the owner of its cell. A particle outside the domain is an
  /// error: every rank throws std::runtime_error; the rank that held it names its id, material and
  /// position in the message, the others name that rank. `local_error`, when not empty, is an error
  /// found earlier on this rank (e.g. an inverted particle) and is raised the same way, so that the
  /// step needs no extra collective for its checks.
  ///
  /// With `candidate_count` >= 0 only the particles candidates(0 .. candidate_count - 1) (indices,
  /// ascending) may have left their rank's cells: the others are known to stay (a rigid body at
  /// rest), and are not looked at.
  MigrationCounts operator()(Particles<Dim>& particles, const std::string& local_error = "",
                             const Kokkos::View<int*, MemorySpace>& candidates = {}, int candidate_count = -1);

 private:
  MPI_Comm comm_;
  int rank_ = 0, ranks_ = 1;
  double lower_[Dim], spacing_[Dim];
  long long cells_[Dim], patch_cells_[Dim], patches_[Dim];
  LocalOrdinal owned_cells_ = 0;
  BoxLookup cell_lookup_;
  Kokkos::View<int*, MemorySpace> patch_owner_;
  // Scratch, kept between calls.
  Kokkos::View<int*, MemorySpace> destination_, slot_;
  Kokkos::View<int*, MemorySpace> leaving_;
};

extern template class ParticleMigration<2>;
extern template class ParticleMigration<3>;

}  // namespace cfdmpm::mpm
