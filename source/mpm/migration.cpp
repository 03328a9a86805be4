#include "mpm/migration.hpp"

#include "common/error.hpp"
#include "common/mpi_comm.hpp"

#include <sstream>
#include <stdexcept>

namespace cfdmpm::mpm {

namespace {

constexpr int kStays = -1;
constexpr int kOutsideDomain = -2;

template <class View>
void ensureSize(View& view, int n, const char* label)
{
  if (int(view.extent(0)) < n) view = View(std::string(label), std::size_t(std::max(n, int(view.extent(0)) * 3 / 2 + 16)));
}

}  // namespace

template <int Dim>
ParticleMigration<Dim>::ParticleMigration(const Layout<Dim>& layout)
    : comm_(rawMpiComm(layout.comm())),
      rank_(layout.comm()->getRank()),
      ranks_(layout.comm()->getSize()),
      owned_cells_(layout.ownedCells()),
      cell_lookup_(layout.cellLookup())
{
  const Grid<Dim>& grid = layout.grid();
  const Box first_patch = grid.patchCells(0);  // patches are full size except the last per direction
  for (int d = 0; d < Dim; ++d) {
    lower_[d] = grid.lower()[d];
    spacing_[d] = grid.spacing()[d];
    cells_[d] = grid.cells()[d];
    patch_cells_[d] = first_patch.extent(d);
    patches_[d] = grid.patchCounts()[d];
  }
  const std::vector<int>& owner = layout.decomposition().patch_owner;
  patch_owner_ = Kokkos::View<int*, MemorySpace>("patch owner", owner.size());
  auto host = Kokkos::create_mirror_view(patch_owner_);
  for (std::size_t p = 0; p < owner.size(); ++p) host(p) = owner[p];
  Kokkos::deep_copy(patch_owner_, host);
}

template <int Dim>
MigrationCounts ParticleMigration<Dim>::operator()(Particles<Dim>& particles, const std::string& local_error,
                                                   const Kokkos::View<int*, MemorySpace>& candidates,
                                                   int candidate_count)
{
  const int n = particles.count;
  // The particles looked at: every one, or the candidates; index i of the range is particle
  // every ? i : candidates(i), ascending either way.
  const bool every = candidate_count < 0;
  const int looked_at = every ? n : candidate_count;
  constexpr int K = Particles<Dim>::kPackedSize;
  ensureSize(destination_, n, "particle destination");
  ensureSize(slot_, n, "particle slot");

  // 1. Destination of every particle: stays, another rank, or outside the domain.
  {
    const auto position = particles.position;
    const auto destination = destination_;
    const auto lookup = cell_lookup_;
    const auto owner = patch_owner_;
    const LocalOrdinal owned = owned_cells_;
    double lower[Dim], spacing[Dim];
    long long cells[Dim], patch_cells[Dim], patches[Dim];
    for (int d = 0; d < Dim; ++d) {
      lower[d] = lower_[d], spacing[d] = spacing_[d];
      cells[d] = cells_[d], patch_cells[d] = patch_cells_[d], patches[d] = patches_[d];
    }
    Kokkos::parallel_for(
        "mpm::migration_destination", Kokkos::RangePolicy<ExecutionSpace>(0, looked_at), KOKKOS_LAMBDA(const int i) {
          const int p = every ? i : candidates(i);
          long long c[3] = {0, 0, 0};
          for (int d = 0; d < Dim; ++d) {
            c[d] = static_cast<long long>(math::floor((position(p, d) - lower[d]) / spacing[d]));
            if (!(c[d] >= 0 && c[d] < cells[d])) {  // also catches NaN positions
              destination(p) = kOutsideDomain;
              return;
            }
          }
          const LocalOrdinal lid = lookup(c[0], c[1], c[2]);
          if (lid >= 0 && lid < owned) {
            destination(p) = kStays;
            return;
          }
          long long patch = 0, stride = 1;
          for (int d = 0; d < Dim; ++d) {
            patch += (c[d] / patch_cells[d]) * stride;
            stride *= patches[d];
          }
          destination(p) = owner(patch);
        });
  }

  // 2. A particle outside the domain is an error; it is raised on every rank after the count
  //    exchange below, so that no rank waits for the others in vain.
  int first_outside = n;
  {
    const auto destination = destination_;
    Kokkos::parallel_reduce(
        "mpm::migration_check", Kokkos::RangePolicy<ExecutionSpace>(0, looked_at),
        KOKKOS_LAMBDA(const int i, int& first) {
          const int p = every ? i : candidates(i);
          if (destination(p) == kOutsideDomain && p < first) first = p;
        },
        Kokkos::Min<int>(first_outside));
  }
  std::string error = local_error;
  if (first_outside < n && error.empty()) {
    std::ostringstream message;
    message.precision(10);
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.position);
    auto id = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.id);
    auto material = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.material);
    message << "MPM: particle " << id(first_outside) << " (material " << material(first_outside)
            << ") left the domain: position (";
    for (int d = 0; d < Dim; ++d) message << (d ? ", " : "") << x(first_outside, d);
    message << ") m, domain [";
    for (int d = 0; d < Dim; ++d) message << (d ? ", " : "") << lower_[d];
    message << "] to [";
    for (int d = 0; d < Dim; ++d) message << (d ? ", " : "") << lower_[d] + cells_[d] * spacing_[d];
    message << "] m (rank " << rank_ << ")";
    error = message.str();
  }

  // 3. The leaving particles in ascending index order.
  int leaving_count = 0;
  {
    const auto destination = destination_;
    const auto slot = slot_;
    Kokkos::parallel_scan(
        "mpm::migration_scan", Kokkos::RangePolicy<ExecutionSpace>(0, looked_at),
        KOKKOS_LAMBDA(const int i, int& offset, const bool final) {
          const int p = every ? i : candidates(i);
          const bool leaves = destination(p) >= 0;
          if (final && leaves) slot(p) = offset;
          if (leaves) ++offset;
        },
        leaving_count);
  }
  ensureSize(leaving_, leaving_count, "leaving particles");
  {
    const auto destination = destination_;
    const auto slot = slot_;
    const auto leaving = leaving_;
    Kokkos::parallel_for(
        "mpm::migration_list", Kokkos::RangePolicy<ExecutionSpace>(0, looked_at), KOKKOS_LAMBDA(const int i) {
          const int p = every ? i : candidates(i);
          if (destination(p) >= 0) leaving(slot(p)) = p;
        });
  }

  // 4. Send buffer ordered by destination rank (a counting sort of the few leaving particles).
  auto leaving_host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), leaving_);
  auto destination_host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), destination_);
  std::vector<int> send_counts(ranks_, 0), send_offsets(ranks_ + 1, 0);
  for (int r = 0; r < leaving_count; ++r) ++send_counts[destination_host(leaving_host(r))];
  for (int q = 0; q < ranks_; ++q) send_offsets[q + 1] = send_offsets[q] + send_counts[q];
  Kokkos::View<int*, MemorySpace> row_of("send row", leaving_count);
  {
    auto row_host = Kokkos::create_mirror_view(row_of);
    std::vector<int> next(send_offsets.begin(), send_offsets.end() - 1);
    for (int r = 0; r < leaving_count; ++r) row_host(r) = next[destination_host(leaving_host(r))]++;
    Kokkos::deep_copy(row_of, row_host);
  }
  // Buffers live in MemorySpace, which is host memory on the Serial and OpenMP back ends that
  // cfdmpm builds with; a GPU build would need CUDA-aware MPI or host mirrors here.
  Kokkos::View<double**, Kokkos::LayoutRight, MemorySpace> send("send buffer", leaving_count, K);
  {
    const Particles<Dim> p_view = particles;
    const auto leaving = leaving_;
    Kokkos::parallel_for(
        "mpm::migration_pack", Kokkos::RangePolicy<ExecutionSpace>(0, leaving_count), KOKKOS_LAMBDA(const int r) {
          p_view.pack(leaving(r), &send(row_of(r), 0));
        });
  }

  // 5. Exchange counts and error flags with every rank, then the packed particles with the ranks
  //    that send or receive any (point to point: a sparse all-to-all).
  std::vector<int> send_header(2 * ranks_), recv_header(2 * ranks_);
  for (int q = 0; q < ranks_; ++q) send_header[2 * q] = send_counts[q], send_header[2 * q + 1] = error.empty() ? 0 : 1;
  MPI_Alltoall(send_header.data(), 2, MPI_INT, recv_header.data(), 2, MPI_INT, comm_);
  int failed_rank = -1;
  for (int q = 0; q < ranks_ && failed_rank < 0; ++q)
    if (recv_header[2 * q + 1]) failed_rank = q;
  if (failed_rank >= 0) throw StepFailure(broadcastText(comm_, failed_rank, error));

  std::vector<int> recv_counts(ranks_, 0), recv_offsets(ranks_ + 1, 0);
  for (int q = 0; q < ranks_; ++q) recv_counts[q] = recv_header[2 * q];
  for (int q = 0; q < ranks_; ++q) recv_offsets[q + 1] = recv_offsets[q] + recv_counts[q];
  const int received = recv_offsets[ranks_];
  Kokkos::View<double**, Kokkos::LayoutRight, MemorySpace> recv("receive buffer", received, K);
  constexpr int kTag = 7301;
  std::vector<MPI_Request> requests;
  for (int q = 0; q < ranks_; ++q)
    if (recv_counts[q] > 0) {
      requests.emplace_back();
      MPI_Irecv(recv.data() + std::size_t(recv_offsets[q]) * K, recv_counts[q] * K, MPI_DOUBLE, q, kTag, comm_,
                &requests.back());
    }
  for (int q = 0; q < ranks_; ++q)
    if (send_counts[q] > 0) {
      requests.emplace_back();
      MPI_Isend(send.data() + std::size_t(send_offsets[q]) * K, send_counts[q] * K, MPI_DOUBLE, q, kTag, comm_,
                &requests.back());
    }
  MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);

  // 6. Close the holes the leavers left: the staying particles beyond the new count move into the
  //    holes below it (both lists ascending, so the result does not depend on thread timing).
  const int kept = n - leaving_count;
  if (leaving_count > 0) {
    std::vector<int> holes, sources;
    int next_leaver = 0;
    for (int r = 0; r < leaving_count; ++r)
      if (leaving_host(r) < kept) holes.push_back(leaving_host(r));
    while (next_leaver < leaving_count && leaving_host(next_leaver) < kept) ++next_leaver;
    for (int p = kept; p < n; ++p) {
      if (next_leaver < leaving_count && leaving_host(next_leaver) == p) {
        ++next_leaver;
        continue;
      }
      sources.push_back(p);
    }
    const int moves = int(holes.size());
    Kokkos::View<int*[2], MemorySpace> pairs("hole pairs", moves);
    auto pairs_host = Kokkos::create_mirror_view(pairs);
    for (int i = 0; i < moves; ++i) pairs_host(i, 0) = sources[i], pairs_host(i, 1) = holes[i];
    Kokkos::deep_copy(pairs, pairs_host);
    const Particles<Dim> p_view = particles;
    Kokkos::parallel_for(
        "mpm::migration_compact", Kokkos::RangePolicy<ExecutionSpace>(0, moves),
        KOKKOS_LAMBDA(const int i) { p_view.copyParticle(pairs(i, 0), pairs(i, 1)); });
  }

  // 7. Append the received particles.
  particles.resize(kept + received);
  {
    const Particles<Dim> p_view = particles;
    Kokkos::parallel_for(
        "mpm::migration_unpack", Kokkos::RangePolicy<ExecutionSpace>(0, received),
        KOKKOS_LAMBDA(const int r) { p_view.unpack(&recv(r, 0), kept + r); });
  }
  Kokkos::fence();
  return MigrationCounts{leaving_count, received};
}

template class ParticleMigration<2>;
template class ParticleMigration<3>;

}  // namespace cfdmpm::mpm
