// Benchmark of the MPM step alone (P2G, grid update, G2P, stress update, particle relocation): particle
// steps per second per core for ~1M particles in 2-D (GIMP, 2 x 2 particles per cell, linear elastic
// block settling under gravity), per phase, against a memory-bound reference kernel timed in the
// same run (a triad over 10 doubles per particle).
//
// usage: [mpiexec -n N] bench_mpm [cells_x [steps [usl|musl]]]   (defaults 1000 10 and the solver's
//        default order; the block fills half the width and the whole height of a 2:1 domain:
//        cells_x^2 / 4 cells of it, 4 particles each)
#include "grid/geometry.hpp"
#include "mpm/mpm_solver.hpp"
#include "mpm_scene_builder.hpp"

#include "bench_support.hpp"

#include <Tpetra_Core.hpp>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <string>

using namespace cfdmpm;

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

}  // namespace

int main(int argc, char** argv)
{
  Tpetra::ScopeGuard guard(&argc, &argv);
  {
    const auto comm = Tpetra::getDefaultComm();
    const bool root = comm->getRank() == 0;
    const long long nx = argc > 1 ? std::atoll(argv[1]) : 1000;
    const int steps = argc > 2 ? std::atoi(argv[2]) : 10;
    const long long ny = nx / 2;
    mpm::MpmOptions options;
    if (argc > 3) options.stress_update = std::string(argv[3]) == "usl" ? mpm::StressUpdate::Last : mpm::StressUpdate::ModifiedLast;
    Scene scene = mpm::scenes::dryScene<2>({0, 0, 0}, {1.0, 0.5, 0}, {nx, ny, 1}, {64, 64, 1}, {0, -9.81, 0});
    mpm::scenes::addLinearElastic(scene, "block", 2000.0, 1.0e7, 0.3, 2);
    mpm::scenes::addBox(scene, "block", {0.0, 0.0, 0}, {0.5, 0.5, 0});
    const Grid<2> grid(scene.domain);
    // Patch weights = cells + particles (4 per solid cell), so that METIS balances the particle work.
    const MaterialRegions regions(scene);
    std::vector<double> weight(grid.patchCount());
    for (int p = 0; p < grid.patchCount(); ++p) {
      const Box b = grid.patchCells(p);
      weight[p] = double(b.count());
      for (long long j = b.lower[1]; j < b.upper[1]; ++j)
        for (long long i = b.lower[0]; i < b.upper[0]; ++i)
          if (regions.materialAt({grid.cellCentre(0, i), grid.cellCentre(1, j), 0}) == 1) weight[p] += 4;
    }
    const auto layout =
        std::make_shared<const Layout<2>>(grid, partitionPatches(grid, comm->getSize(), weight), 1, comm);
    mpm::MpmSolver<2> solver(scene, layout, options);
    const double dt = solver.stableTimeStep().dt;
    for (int s = 0; s < 2; ++s) solver.step(dt);  // warm-up

    const char* names[] = {"P2G", "grid", "G2P", "stress", "relocate"};
    double seconds[5] = {0, 0, 0, 0, 0};
    comm->barrier();
    const double start = now();
    for (int s = 0; s < steps; ++s) {
      double t0 = now();
      solver.particlesToGrid();
      double t1 = now();
      solver.integrateGrid(dt);
      double t2 = now();
      solver.gridToParticles(dt);
      double t3 = now();
      solver.updateStress(dt);
      double t4 = now();
      solver.relocateParticles();
      double t5 = now();
      seconds[0] += t1 - t0, seconds[1] += t2 - t1, seconds[2] += t3 - t2, seconds[3] += t4 - t3, seconds[4] += t5 - t4;
    }
    comm->barrier();
    const double total = now() - start;
    const long long particles = solver.particleCount();
    const int ranks = comm->getSize();
    const double triad = bench::triadSeconds(std::size_t(particles / ranks) * 10);
    if (root) {
      std::cout << std::fixed << std::setprecision(3) << "MPM step, " << particles << " particles, " << nx << " x "
                << ny << " cells, " << ranks << " rank(s), " << steps << " steps, "
                << (options.stress_update == mpm::StressUpdate::Last ? "USL" : "MUSL") << "\n"
                << "particle-steps per second per core: " << std::scientific << std::setprecision(3)
                << double(particles) * steps / total / ranks << std::fixed << "\n"
                << "whole step: " << 1e6 * total / (double(particles) * steps) * ranks << " core-us per particle-step, "
                << total / steps / triad << " x triad over 10 doubles per particle\n";
      for (int p = 0; p < 5; ++p)
        std::cout << "  " << std::left << std::setw(10) << names[p] << std::right << std::setw(10)
                  << 100 * seconds[p] / total << " % (rank 0)\n";
    }
  }
  return 0;
}
