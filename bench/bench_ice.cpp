// Benchmark of the ICE step on the dam break at ~280k cells (2-D): microseconds per cell and step for
// the whole step and per phase (Teuchos timers), pressure iterations per step, and the same work
// expressed against a memory-bound reference kernel timed in the same run (a triad over as many
// doubles as the step's cell state holds), because absolute times on shared machines are noisy.
//
// usage: [mpiexec -n N] bench_ice [nx ny [steps [reuse]]]     (defaults 840 336 20 1)
//   reuse: full MueLu set-up every `reuse` solves (the pressure solver's "reuse interval")
#include "ice_scene_support.hpp"

#include "bench_support.hpp"

#include <Tpetra_Core.hpp>

#include <chrono>
#include <iomanip>
#include <iostream>

using namespace cfdmpm;

int main(int argc, char** argv)
{
  Tpetra::ScopeGuard guard(&argc, &argv);
  {
    const auto comm = Tpetra::getDefaultComm();
    const bool root = comm->getRank() == 0;
    const long long nx = argc > 2 ? std::atoll(argv[1]) : 840, ny = argc > 2 ? std::atoll(argv[2]) : 336;
    const int steps = argc > 3 ? std::atoi(argv[3]) : 20;
    const int reuse = argc > 4 ? std::atoi(argv[4]) : 1;
    const Scene scene = test::damBreakScene(nx, ny, 64, "{linear_solver: {reuse interval: " + std::to_string(reuse) + "}}");

    test::IceRun<2> run(scene, comm);
    const double dt = 2e-5;  // s: ~CFL 0.25 for the flow at 0.6 mm cells once it moves
    run.runUntil(5 * dt, dt);  // warm-up: allocations, first MueLu set-up
    std::map<std::string, double> before;
    for (const char* phase : IceSolver<2>::kPhases) before[phase] = run.solver.phaseSeconds(phase);
    long long iterations = 0;
    for (int s = 0; s < steps; ++s) {
      run.runUntil(run.time + dt, dt);
      iterations += run.last.linear_iterations;
    }
    const double cells = double(nx * ny);
    const int ranks = comm->getSize();
    const double triad = bench::triadSeconds(std::size_t(cells / ranks) * 10);  // 10 doubles per cell
    if (root) {
      std::cout << std::fixed << std::setprecision(3) << "ICE dam break, " << nx << " x " << ny << " = " << cells
                << " cells, " << ranks << " rank(s), " << steps << " steps of " << std::scientific << dt
                << std::fixed << " s, MueLu set-up every " << reuse << " solve(s)\n"
                << "pressure iterations per step: " << double(iterations) / steps << "\n"
                << "reference: triad over 10 doubles per cell: " << 1e6 * triad / (cells / ranks)
                << " us per cell (per rank)\n";
      std::cout << std::left << std::setw(24) << "phase" << std::right << std::setw(16) << "us/cell-step"
                << std::setw(20) << "core-us/cell-step" << std::setw(14) << "x triad" << "\n";
    }
    for (const char* phase : IceSolver<2>::kPhases) {
      double local = run.solver.phaseSeconds(phase) - before[phase], slowest = 0;
      Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, local, Teuchos::outArg(slowest));
      const double per = slowest / (cells * steps);
      if (root)
        std::cout << std::left << std::setw(24) << phase << std::right << std::setw(16) << 1e6 * per << std::setw(20)
                  << 1e6 * per * ranks << std::setw(14) << slowest / steps / triad << "\n";
    }
  }
  return 0;
}
