// Test e: particle migration. Two spinning blocks of different materials cross the patches of a
// 1, 2 or 3 rank decomposition. No particle and no mass may be lost or duplicated (exact), and the
// particles end in the same state as the same scene run on one rank (MPI_COMM_SELF on rank 0), to
// 1e-10 relative, matched by particle id. Also the bookkeeping that lets a step skip the particles
// of a rigid body at rest (a plate across the ranks): they stay as seeded and on their ranks, also
// after a new decomposition, and the particle bins of a subset visit what the full bins visit.
#include "common/error.hpp"
#include "mpm/mpm_solver.hpp"
#include "mpm/particle_bins.hpp"
#include "mpm_scene_builder.hpp"

#include <gtest/gtest.h>
#include <Teuchos_DefaultMpiComm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

using namespace cfdmpm;
using namespace cfdmpm::mpm;

namespace {

auto world() { return Tpetra::getDefaultComm(); }

// Domain 1 m x 0.75 m, 25 mm cells, 5 x 5 cell patches (8 x 6 patches for METIS to share out).
// "rubber" (linear elastic) moves right, "gel" (neo-Hookean) left, in separate bands, both spinning
// at 2 rad/s: they cross rank borders in x and their corners in y, and carry stress.
Scene crossingScene()
{
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {1.0, 0.75, 0}, {40, 30, 1}, {5, 5, 1}, {0, 0, 0});
  scenes::addLinearElastic(scene, "rubber", 1000.0, 1.0e5, 0.3, 2);
  scenes::addNeoHookean(scene, "gel", 800.0, 1.0e5, 5.0e4, 2);
  scenes::addBox(scene, "rubber", {0.1, 0.1, 0}, {0.3, 0.25, 0}, {2.0, 0.0, 0});
  scenes::addBox(scene, "gel", {0.7, 0.5, 0}, {0.9, 0.6, 0}, {-2.0, 0.0, 0});
  return scene;
}

constexpr double kSpin = 2.0;  // rad/s, about each block's centre

void addSpin(MpmSolver<2>& solver)
{
  const double centre[2][2] = {{0.2, 0.175}, {0.8, 0.55}};
  auto& particles = solver.particles();
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.position);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.velocity);
  auto material = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.material);
  for (int p = 0; p < particles.count; ++p) {
    const double* c = centre[material(p)];
    v(p, 0) += -kSpin * (x(p, 1) - c[1]);
    v(p, 1) += kSpin * (x(p, 0) - c[0]);
  }
  Kokkos::deep_copy(particles.velocity, v);
}

/// One particle's state as compared between runs: x, v, F, sigma, volume.
constexpr int kCompared = 2 + 2 + 4 + 4 + 1;
struct Record {
  long long id;
  double mass;
  int material;
  double value[kCompared];
};

std::vector<Record> records(const MpmSolver<2>& solver)
{
  const auto& particles = solver.particles();
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.position);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.velocity);
  auto F = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.deformation_gradient);
  auto sigma = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.stress);
  auto volume = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.volume);
  auto mass = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.mass);
  auto id = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.id);
  auto material = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.material);
  std::vector<Record> out(particles.count);
  for (int p = 0; p < particles.count; ++p) {
    Record& r = out[p];
    r.id = id(p), r.mass = mass(p), r.material = material(p);
    double* q = r.value;
    for (int d = 0; d < 2; ++d) *q++ = x(p, d);
    for (int d = 0; d < 2; ++d) *q++ = v(p, d);
    for (int d = 0; d < 2; ++d)
      for (int e = 0; e < 2; ++e) *q++ = F(p, d, e);
    for (int d = 0; d < 2; ++d)
      for (int e = 0; e < 2; ++e) *q++ = sigma(p, d, e);
    *q++ = volume(p);
  }
  return out;
}

/// Every rank's records on rank 0, sorted by id (empty elsewhere).
std::vector<Record> gatherSorted(const std::vector<Record>& local)
{
  const MPI_Comm comm = MPI_COMM_WORLD;
  int size = 0, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  const int bytes = int(local.size() * sizeof(Record));
  std::vector<int> counts(size), displs(size, 0);
  MPI_Gather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  for (int q = 1; q < size; ++q) displs[q] = displs[q - 1] + counts[q - 1];
  std::vector<Record> all(rank == 0 ? (displs[size - 1] + counts[size - 1]) / sizeof(Record) : 0);
  MPI_Gatherv(local.data(), bytes, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, 0, comm);
  std::sort(all.begin(), all.end(), [](const Record& a, const Record& b) { return a.id < b.id; });
  return all;
}

constexpr double kDt = 2.5e-4;   // fixed, so both runs take the same steps (stable dt is 3.7e-4)
constexpr int kSteps = 600;      // 0.15 s: each block moves 0.3 m, 12 cells, across 2-3 patches

/// The scene's spinning blocks run kSteps on this rank alone (MPI_COMM_SELF), sorted by id.
std::vector<Record> oneRankRun(const Scene& scene)
{
  const auto self = Teuchos::rcp(new Teuchos::MpiComm<int>(MPI_COMM_SELF));
  MpmSolver<2> serial(scene, scenes::layoutFor<2>(scene, self), MpmOptions{});
  addSpin(serial);
  for (int n = 0; n < kSteps; ++n) serial.step(kDt);
  std::vector<Record> reference = records(serial);
  std::sort(reference.begin(), reference.end(), [](const Record& a, const Record& b) { return a.id < b.id; });
  return reference;
}

/// The crossing scene with a rigid plate at rest along its top, across every rank's patches: two
/// cells thick, 2 cells (50 mm) above the highest corner the spinning gel block reaches (~0.63 m).
Scene crossingSceneWithPlate()
{
  Scene scene = crossingScene();
  scenes::addRigid(scene, "plate", 2000.0);
  scenes::addBox(scene, "plate", {0.0, 0.7, 0}, {1.0, 0.75, 0}, {0.0, 0.0, 0});
  return scene;
}

/// Particles of this rank that lie outside the cells it owns.
int particlesOffOwnedCells(const MpmSolver<2>& solver)
{
  const Layout<2>& layout = solver.layout();
  const BoxLookup cells = layout.cellLookup();
  const Grid<2>& grid = layout.grid();
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), solver.particles().position);
  int off = 0;
  for (int p = 0; p < solver.particles().count; ++p) {
    const long long i = (long long)std::floor((x(p, 0) - grid.lower()[0]) / grid.spacing()[0]);
    const long long j = (long long)std::floor((x(p, 1) - grid.lower()[1]) / grid.spacing()[1]);
    const LocalOrdinal c = cells(i, j, 0);
    if (!(c >= 0 && c < layout.ownedCells())) ++off;
  }
  return off;
}

}  // namespace

TEST(ParticleMigration, BlocksCrossingRankBordersKeepEveryParticleAndMatchOneRank)
{
  const Scene scene = crossingScene();
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, world()), MpmOptions{});
  addSpin(solver);
  const long long count = solver.particleCount();
  const std::vector<double> masses = solver.materialMasses();
  EXPECT_EQ(count, (8 * 6 + 8 * 4) * 4);  // 48 + 32 cells, 2 x 2 particles each
  const std::vector<Record> initial = gatherSorted(records(solver));

  long long sent = 0;
  for (int n = 0; n < kSteps; ++n) {
    solver.particlesToGrid();
    solver.integrateGrid(kDt);
    solver.gridToParticles(kDt);
    solver.updateStress(kDt);
    sent += solver.relocateParticles().sent;
    // Exact: the count is an integer; masses are summed from the same particle masses in one
    // order per rank, so a lost or duplicated particle changes them while round-off cannot
    // (checked to 1e-15 relative: the ranks' partial sums may group differently).
    ASSERT_EQ(solver.particleCount(), count) << "step " << n;
    const std::vector<double> now = solver.materialMasses();
    for (std::size_t m = 0; m < masses.size(); ++m) ASSERT_NEAR(now[m], masses[m], 1e-15 * masses[m]) << "step " << n;
  }
  long long sent_total = 0;
  Teuchos::reduceAll(*world(), Teuchos::REDUCE_SUM, sent, Teuchos::outArg(sent_total));
  const std::vector<Record> parallel = gatherSorted(records(solver));

  // The same scene on one rank, on rank 0 only.
  if (world()->getRank() == 0) {
    const std::vector<Record> reference = oneRankRun(scene);

    std::printf("[ migrate  ] %d rank(s): %lld particles, %lld migrations over %d steps\n", world()->getSize(), count,
                sent_total, kSteps);
    if (world()->getSize() > 1) {
      EXPECT_GT(sent_total, 0);  // the blocks did cross rank borders
    }
    // Same particles with the same masses, bitwise: nothing lost, nothing duplicated.
    ASSERT_EQ(parallel.size(), initial.size());
    ASSERT_EQ(reference.size(), initial.size());
    for (std::size_t i = 0; i < initial.size(); ++i) {
      ASSERT_EQ(parallel[i].id, initial[i].id);
      ASSERT_EQ(parallel[i].mass, initial[i].mass);
      ASSERT_EQ(parallel[i].material, initial[i].material);
      ASSERT_EQ(reference[i].id, initial[i].id);
    }
    // Same state to 1e-10 relative to each quantity's largest magnitude: the runs differ only in
    // the order of floating-point sums at rank borders (round-off, ~1e-16 per step).
    const char* names[kCompared] = {"x", "y", "vx", "vy", "Fxx", "Fxy", "Fyx", "Fyy",
                                    "sxx", "sxy", "syx", "syy", "V"};
    for (int q = 0; q < kCompared; ++q) {
      double scale = 0, difference = 0;
      for (std::size_t i = 0; i < reference.size(); ++i) {
        scale = std::max(scale, std::abs(reference[i].value[q]));
        difference = std::max(difference, std::abs(parallel[i].value[q] - reference[i].value[q]));
      }
      std::printf("[ migrate  ]   %-4s max |%d ranks - 1 rank| / max |value| = %.2e (max |value| %.3e)\n", names[q],
                  world()->getSize(), difference / scale, scale);
      EXPECT_LE(difference, 1e-10 * scale) << names[q];
    }
  }
}

TEST(ParticleMigration, ParticleLeavingTheDomainStopsEveryRankWithItsPosition)
{
  const Scene scene = crossingScene();
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, world()), MpmOptions{});
  // The lowest rank that holds a particle puts its first particle at x = 1.5 m, outside.
  const int holder_local = solver.particles().count > 0 ? world()->getRank() : world()->getSize();
  int holder = 0;
  Teuchos::reduceAll(*world(), Teuchos::REDUCE_MIN, holder_local, Teuchos::outArg(holder));
  if (world()->getRank() == holder) {
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), solver.particles().position);
    x(0, 0) = 1.5;
    x(0, 1) = 0.375;
    Kokkos::deep_copy(solver.particles().position, x);
  }
  try {
    solver.step(kDt);
    ADD_FAILURE() << "no error for a particle outside the domain";
  } catch (const StepFailure& e) {
    // Every rank gets the holder's message.
    const std::string message = e.what();
    EXPECT_NE(message.find("left the domain"), std::string::npos) << message;
    EXPECT_NE(message.find("(1.5, 0.375)"), std::string::npos) << message;
    EXPECT_NE(message.find("(rank " + std::to_string(holder) + ")"), std::string::npos) << message;
  }
}

TEST(ParticleMigration, RepartitionSendsParticlesToTheirNewOwners)
{
  const Scene scene = crossingScene();
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, world()), MpmOptions{});
  const long long count = solver.particleCount();
  // A new decomposition weighted by work: patches with particles count 20 times a cell's weight.
  const Grid<2> grid(scene.domain);
  std::vector<double> weight(grid.patchCount(), 25.0);
  for (const RegionSpec& region : scene.regions)
    for (int p = 0; p < grid.patchCount(); ++p) {
      const Box cells = grid.patchCells(p);
      const bool overlaps = grid.nodePosition(0, cells.lower[0]) < region.upper[0] &&
                            grid.nodePosition(0, cells.upper[0]) > region.lower[0] &&
                            grid.nodePosition(1, cells.lower[1]) < region.upper[1] &&
                            grid.nodePosition(1, cells.upper[1]) > region.lower[1];
      if (overlaps) weight[p] = 25.0 * 20;
    }
  const auto layout = std::make_shared<const Layout<2>>(grid, partitionPatches(grid, world()->getSize(), weight),
                                                        scene.domain.ghost_width, world());
  solver.repartition(layout);
  EXPECT_EQ(solver.particleCount(), count);
  // Every particle now lies in a cell its rank owns: a second relocation sends nothing.
  long long sent = solver.relocateParticles().sent, total = 0;
  Teuchos::reduceAll(*world(), Teuchos::REDUCE_SUM, sent, Teuchos::outArg(total));
  EXPECT_EQ(total, 0);
  // And the solver steps on the new layout.
  solver.step(kDt);
  EXPECT_EQ(solver.particleCount(), count);
}

TEST(ParticleMigration, ParticlesPerPatchAreTheSameOnEveryRankCount)
{
  // The particles of every patch, summed over the ranks: the weights of a rebalance. They must add
  // up to the particle count and not depend on the decomposition (here: on 1, 2 or 3 ranks against
  // the count from the seeding lattice of each patch on rank 0 alone).
  const Scene scene = crossingScene();
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, world()), MpmOptions{});
  const std::vector<long long> per_patch = solver.particlesPerPatch();
  long long sum = 0;
  for (long long n : per_patch) sum += n;
  EXPECT_EQ(sum, solver.particleCount());
  const auto alone = world()->split(world()->getRank() == 0 ? 0 : 1, world()->getRank());
  if (world()->getRank() == 0) {
    MpmSolver<2> one(scene, scenes::layoutFor<2>(scene, alone), MpmOptions{});
    EXPECT_EQ(one.particlesPerPatch(), per_patch);
  }
}

// The weights of a rebalance count the particles a step works on: a plate at rest (a bed) is left
// out, as the step passes over it and copies its sums in; with its sums made every step
// (stationary_sums_once off) it is counted.
TEST(ParticleMigration, ParticlesPerPatchLeaveOutARigidBodyAtRest)
{
  const Scene scene = crossingSceneWithPlate();
  const auto layout = scenes::layoutFor<2>(scene, world());
  const long long plate = 40 * 2 * 4;  // its cells times 4 particles (crossingSceneWithPlate)
  MpmSolver<2> solver(scene, layout, MpmOptions{});
  long long counted = 0;
  for (long long n : solver.particlesPerPatch()) counted += n;
  EXPECT_EQ(counted, solver.particleCount() - plate);
  MpmOptions every_step;
  every_step.stationary_sums_once = false;
  MpmSolver<2> summed(scene, layout, every_step);
  counted = 0;
  for (long long n : summed.particlesPerPatch()) counted += n;
  EXPECT_EQ(counted, summed.particleCount());
}

// A step skips the particles of a rigid material at rest (MpmSolver's ParticleSet::Changing): the
// stress update, G2P, the checks and the migration look at the blocks alone. With a plate at rest
// across the ranks' patches, while the blocks cross rank borders: no particle lost or duplicated
// (exact), every plate particle exactly as seeded (nothing may write it) and on a cell its rank
// owns, the blocks as on one rank to 1e-10 (as the test above); then a new decomposition moves the
// plate's particles to their new owners too.
TEST(ParticleMigration, PlateAtRestIsSkippedStaysAsSeededAndFollowsANewDecomposition)
{
  const Scene scene = crossingSceneWithPlate();
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, world()), MpmOptions{});
  addSpin(solver);
  const long long count = solver.particleCount();
  EXPECT_EQ(count, (8 * 6 + 8 * 4 + 40 * 2) * 4);  // the blocks' cells and the plate's 40 x 2
  const std::vector<Record> initial = gatherSorted(records(solver));
  for (int n = 0; n < kSteps; ++n) {
    solver.step(kDt);
    ASSERT_EQ(solver.particleCount(), count) << "step " << n;
  }
  EXPECT_EQ(particlesOffOwnedCells(solver), 0);
  const std::vector<Record> parallel = gatherSorted(records(solver));

  if (world()->getRank() == 0) {
    const std::vector<Record> reference = oneRankRun(scene);
    ASSERT_EQ(parallel.size(), initial.size());
    ASSERT_EQ(reference.size(), initial.size());
    int plate = 0;
    double worst = 0;
    for (std::size_t i = 0; i < initial.size(); ++i) {
      ASSERT_EQ(parallel[i].id, initial[i].id);
      ASSERT_EQ(parallel[i].material, initial[i].material);
      if (initial[i].material == 2) {  // the plate: bit for bit as seeded
        ++plate;
        for (int q = 0; q < kCompared; ++q) ASSERT_EQ(parallel[i].value[q], initial[i].value[q]) << "quantity " << q;
        continue;
      }
      for (int q = 0; q < 4; ++q)  // position and velocity of the blocks, against one rank
        worst = std::max(worst, std::abs(parallel[i].value[q] - reference[i].value[q]) /
                                    std::max(1.0, std::abs(reference[i].value[q])));
    }
    EXPECT_EQ(plate, 40 * 2 * 4);
    std::printf("[ migrate  ] %d rank(s) with a plate at rest: blocks against one rank %.2e\n", world()->getSize(),
                worst);
    EXPECT_LE(worst, 1e-10);  // the sums' order at rank borders: round-off, as the test above
  }

  // A new decomposition (the patches of the plate's row weigh 20 times more): every particle, the
  // plate's too, goes to the owner of its cell.
  const Grid<2> grid(scene.domain);
  std::vector<double> weight(grid.patchCount(), 25.0);
  for (int p = 0; p < grid.patchCount(); ++p)
    if (grid.nodePosition(1, grid.patchCells(p).upper[1]) > 0.7) weight[p] = 25.0 * 20;
  const auto layout = std::make_shared<const Layout<2>>(grid, partitionPatches(grid, world()->getSize(), weight),
                                                        scene.domain.ghost_width, world());
  solver.repartition(layout);
  EXPECT_EQ(solver.particleCount(), count);
  EXPECT_EQ(particlesOffOwnedCells(solver), 0);
  for (int n = 0; n < 40; ++n) solver.step(kDt);
  EXPECT_EQ(solver.particleCount(), count);
  EXPECT_EQ(particlesOffOwnedCells(solver), 0);
}

// The particle bins of a subset (the particles a step changes) visit exactly that subset, each
// particle once and in the order the bins of every particle visit it: the scatters then add in the
// same order whichever set the bins hold (bit for bit).
TEST(ParticleBins, SubsetVisitsItsParticlesInTheFullBinsOrder)
{
  const Scene scene = crossingSceneWithPlate();
  const auto layout = scenes::layoutFor<2>(scene, world());
  MpmSolver<2> solver(scene, layout, MpmOptions{});
  const Particles<2>& particles = solver.particles();
  const int n = particles.count;
  auto material = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.material);
  std::vector<int> subset_host;
  for (int p = 0; p < n; ++p)
    if (material(p) != 2) subset_host.push_back(p);  // all but the plate
  Kokkos::View<int*, MemorySpace> subset("subset", subset_host.size());
  {
    auto host = Kokkos::create_mirror_view(subset);
    for (std::size_t i = 0; i < subset_host.size(); ++i) host(i) = subset_host[i];
    Kokkos::deep_copy(subset, host);
  }
  for (int chunks : {1, 3}) {
    ParticleBins<2> all, part;
    all.build(particles, layout->grid(), layout->nodeLookup(), chunks);
    part.build(particles, layout->grid(), layout->nodeLookup(), chunks, subset, int(subset_host.size()));
    // The visits in the order they happened (on one thread a fixed list; on more, the tiles of a
    // colour run side by side, so only the set is compared).
    std::vector<int> visited_all, visited_part;
    Kokkos::View<int*, Kokkos::HostSpace> trace("trace", n + 1);
    const auto record = [&](const ParticleBins<2>& bins, std::vector<int>& out) {
      Kokkos::View<int, Kokkos::HostSpace> next("next");
      bins.forEachParticle([=](const int p) { trace(Kokkos::atomic_fetch_add(&next(), 1)) = p; });
      Kokkos::fence();
      out.assign(trace.data(), trace.data() + next());
    };
    record(all, visited_all);
    record(part, visited_part);
    std::vector<int> expected;
    for (int p : visited_all)
      if (material(p) != 2) expected.push_back(p);
    ASSERT_EQ(int(visited_all.size()), n) << "chunks " << chunks;
    if (ExecutionSpace().concurrency() > 1) {
      std::sort(expected.begin(), expected.end());
      std::sort(visited_part.begin(), visited_part.end());
    }
    EXPECT_EQ(visited_part, expected) << "chunks " << chunks;
  }
}
