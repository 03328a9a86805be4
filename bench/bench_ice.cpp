// Benchmark of the ICE step on the dam break at ~280k cells (2-D): microseconds per cell and step for
// the whole step and per phase (Teuchos timers), pressure iterations per step, and the same work
// expressed against a memory-bound reference kernel timed in the same run (a triad over as many
// doubles as the step's cell state holds), because absolute times on shared machines are noisy.
//
// On a loaded machine the process gets only part of a core, so the run also reports its CPU time:
// the per-phase columns "cpu" scale each phase's share of the wall time by the CPU time of the
// measured steps (an estimate that assumes the load was even over the run).
//
// usage: [mpiexec -n N] bench_ice [nx ny [steps [ice]]]     (defaults 840 336 20 "{}")
//   ice: the scene's `ice` section as YAML (flow style), e.g. "{linear_solver: {reuse interval: 1}}"
//        for a full MueLu set-up every solve; "{}" runs the defaults of doc/ice.md.
#include "ice_scene_support.hpp"

#include "bench_support.hpp"

#include <Teuchos_TimeMonitor.hpp>
#include <Tpetra_Core.hpp>

#include <chrono>
#include <ctime>
#include <iomanip>
#include <iostream>

using namespace cfdmpm;

namespace {

/// Wall seconds of a Teuchos timer, 0 if it does not exist (yet).
double timerSeconds(const std::string& name)
{
  const auto timer = Teuchos::TimeMonitor::lookupCounter(name);
  return timer.is_null() ? 0.0 : timer->totalElapsedTime();
}

double processCpuSeconds()
{
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv)
{
  Tpetra::ScopeGuard guard(&argc, &argv);
  {
    const auto comm = Tpetra::getDefaultComm();
    const bool root = comm->getRank() == 0;
    const long long nx = argc > 2 ? std::atoll(argv[1]) : 840, ny = argc > 2 ? std::atoll(argv[2]) : 336;
    const int steps = argc > 3 ? std::atoi(argv[3]) : 20;
    const std::string ice = argc > 4 ? argv[4] : "{}";
    const Scene scene = test::damBreakScene(nx, ny, 64, ice);

    // Phases of the step, then the pressure phase's parts (timers of PressureSolver).
    std::vector<std::string> phases(std::begin(IceSolver<2>::kPhases), std::end(IceSolver<2>::kPhases));
    for (const char* part : {"assemble", "preconditioner", "CG"}) phases.push_back(std::string("pressure solver: ") + part);
    const auto seconds = [&](const std::string& phase) {
      return phase.rfind("pressure solver: ", 0) == 0 ? timerSeconds(phase) : timerSeconds("ice: " + phase);
    };

    test::IceRun<2> run(scene, comm);
    const double dt = 2e-5;  // s: ~CFL 0.25 for the flow at 0.6 mm cells once it moves
    run.runUntil(5 * dt, dt);  // warm-up: allocations, first MueLu set-up
    std::map<std::string, double> before;
    for (const auto& phase : phases) before[phase] = seconds(phase);
    long long iterations = 0, outer = 0;
    const double cpu_start = processCpuSeconds();
    for (int s = 0; s < steps; ++s) {
      run.runUntil(run.time + dt, dt);
      iterations += run.last.linear_iterations;
      outer += run.last.outer_iterations;
    }
    // CPU time of the measured steps on the slowest rank, and its ratio to their wall time.
    double cpu = processCpuSeconds() - cpu_start, cpu_max = 0;
    Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, cpu, Teuchos::outArg(cpu_max));
    double wall_steps = seconds("step") - before["step"], wall_max = 0;
    Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, wall_steps, Teuchos::outArg(wall_max));
    const double cpu_share = cpu_max / wall_max;
    const double cells = double(nx * ny);
    const int ranks = comm->getSize();
    const double triad = bench::triadSeconds(std::size_t(cells / ranks) * 10);  // 10 doubles per cell
    if (root) {
      std::cout << std::fixed << std::setprecision(3) << "ICE dam break, " << nx << " x " << ny << " = " << cells
                << " cells, " << ranks << " rank(s), " << steps << " steps of " << std::scientific << dt
                << std::fixed << " s, ice: " << ice << "\n"
                << "pressure iterations per step: " << double(iterations) / steps
                << ", outer iterations per step: " << double(outer) / steps << "\n"
                << "reference: triad over 10 doubles per cell: " << 1e6 * triad / (cells / ranks)
                << " us per cell (per rank)\n"
                << "CPU time / wall time of the measured steps (slowest rank): " << cpu_share << "\n";
      std::cout << std::left << std::setw(32) << "phase" << std::right << std::setw(14) << "us/cell-step"
                << std::setw(19) << "core-us/cell-step" << std::setw(12) << "x triad" << std::setw(15)
                << "cpu-us (est.)" << "\n";
    }
    for (const auto& phase : phases) {
      double local = seconds(phase) - before[phase], slowest = 0;
      Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, local, Teuchos::outArg(slowest));
      const double per = slowest / (cells * steps);
      if (root)
        std::cout << std::left << std::setw(32) << phase << std::right << std::setw(14) << 1e6 * per << std::setw(19)
                  << 1e6 * per * ranks << std::setw(12) << slowest / steps / triad << std::setw(15)
                  << 1e6 * per * cpu_share << "\n";
    }
  }
  return 0;
}
