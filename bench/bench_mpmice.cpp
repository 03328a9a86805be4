// Benchmark of the coupled step on the seed scene (input/rzadkiewicz.yaml, 10 mm cells): microseconds
// per cell and step of the whole coupled step and per phase (Teuchos timers "mpmice: <phase>"), next
// to the fluid step alone on the same grid in the same run (the scene without its solids: water and
// air), and their ratio. Both run the same number of steps at the same fixed Δt, after a warm-up,
// in alternating blocks of steps (the ratio of each block shows the host's noise). On more than one
// rank the coupled step runs a second time, on the division with its particles that
// domain.rebalance_interval makes, in the same alternation.
//
// usage: [mpiexec -n N] bench_mpmice [steps [dt]]     (defaults 200 steps of 2e-5 s)
#include "coupled_support.hpp"
#include "mpmice/run_state.hpp"

#include <Tpetra_Core.hpp>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>

using namespace cfdmpm;

namespace {

// Steps per block: the runs alternate every kBlockSteps steps (~0.1-0.3 s of each on one core).
constexpr int kBlockSteps = 10;

/// The scene without its solid materials and their regions: the fluids alone on the same grid.
Scene fluidsOnly(const Scene& scene)
{
  Scene fluids = scene;
  fluids.materials.clear();
  fluids.regions.clear();
  for (const MaterialSpec& m : scene.materials)
    if (m.kind == "fluid") fluids.materials.push_back(m);
  for (const RegionSpec& r : scene.regions)
    if (scene.materials[scene.materialIndex(r.material)].kind == "fluid") fluids.regions.push_back(r);
  return fluids;
}

/// The coupled step's phases, with the pressure phase of the ICE step after "3-6 fluid pressure".
std::vector<std::string> phases()
{
  std::vector<std::string> all;
  for (const char* phase : MpmIceStep<2>::kPhases) {
    all.emplace_back(phase);
    if (all.back() == "3-6 fluid pressure") all.emplace_back("5 pressure");
  }
  return all;
}

/// One of the two runs the benchmark times: its phases' seconds on this rank and its pressure
/// iterations, summed over the blocks of steps it took.
class TimedRun {
 public:
  /// The division the program takes: by cells, or with the cells that rigid bodies fill weighed
  /// less (divisionByOpenCells), from the initial state, and where the scene sets
  /// domain.rebalance_interval, divided again with its particles before the first step
  /// (divisionWithParticles); then 5 warm-up steps of dt.
  TimedRun(const Scene& scene, double dt, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
      : run_(scene, comm, division(scene, comm)), dt_(dt)
  {
    for (int s = 0; s < 5; ++s) advance();
    for (const std::string& phase : phases()) spent_[phase] = 0.0;
  }

  /// `steps` more steps; returns this rank's seconds of the whole step over them.
  double block(int steps)
  {
    std::map<std::string, double> before;
    for (const std::string& phase : phases()) before[phase] = seconds(phase);
    for (int s = 0; s < steps; ++s) {
      advance();
      outer_ += run_.last.ice.outer_iterations;
      linear_ += run_.last.ice.linear_iterations;
    }
    for (const std::string& phase : phases()) spent_[phase] += seconds(phase) - before[phase];
    steps_ += steps;
    return seconds("step") - before["step"];
  }

  /// The slowest rank's seconds per phase over every block (collective).
  std::map<std::string, double> slowest(const Teuchos::Comm<int>& comm) const
  {
    std::map<std::string, double> result;
    for (const auto& [phase, local] : spent_) {
      double value = 0;
      Teuchos::reduceAll(comm, Teuchos::REDUCE_MAX, local, Teuchos::outArg(value));
      result[phase] = value;
    }
    return result;
  }
  double outerPerStep() const { return double(outer_) / steps_; }
  double linearPerStep() const { return double(linear_) / steps_; }

 private:
  static Decomposition division(const Scene& scene, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
  {
    const Grid<2> grid(scene.domain);
    const Decomposition by_cells =
        divisionByOpenCells(buildRunState(scene, grid, partitionPatches(grid, comm->getSize()), comm), kRebalanceGain)
            .decomposition;
    if (!(scene.domain.rebalance_interval > 0)) return by_cells;
    return divisionWithParticles(buildRunState(scene, grid, by_cells, comm), kRebalanceGain).decomposition;
  }
  void advance()
  {
    run_.last = run_.stepper.step(run_.state, dt_);
    run_.time += dt_;
  }
  /// The ICE pressure phase [5] alone (outer iterations, matrix, solves) is "5 pressure", inside
  /// "3-6 fluid pressure".
  double seconds(const std::string& phase)
  {
    return phase == "5 pressure" ? run_.stepper.fluids()->phaseSeconds("pressure") : run_.stepper.phaseSeconds(phase);
  }

  test::CoupledRun<2> run_;
  double dt_;
  std::map<std::string, double> spent_;
  long long outer_ = 0, linear_ = 0;
  int steps_ = 0;
};

}  // namespace

int main(int argc, char** argv)
{
  Tpetra::ScopeGuard guard(&argc, &argv);
  {
    const auto comm = Tpetra::getDefaultComm();
    const bool root = comm->getRank() == 0;
    const int steps = argc > 1 ? std::atoi(argv[1]) : 200;
    const double dt = argc > 2 ? std::atof(argv[2]) : 2e-5;
    if (steps < 1 || !(dt > 0)) {
      if (root) std::cerr << "usage: bench_mpmice [steps [dt]]: steps >= 1 and dt > 0 s (got " << steps << ", " << dt << ")\n";
      return 2;
    }
    const Scene scene = readScene(std::string(CFDMPM_SOURCE_DIR) + "/input/rzadkiewicz.yaml");
    const double cells = double(scene.domain.cells[0] * scene.domain.cells[1]);
    // The two runs take their steps in alternating blocks, so that a change of the shared host's
    // speed during the run weighs on both alike; each block's ratio shows how much it moved.
    TimedRun coupled_run(scene, dt, comm), fluid_run(fluidsOnly(scene), dt, comm);
    // On more than one rank, and where the scene does not divide with its particles itself, the
    // coupled step also runs on the division with its particles (domain.rebalance_interval), in
    // the same alternation: what a rebalance would gain, measured against the same fluid run.
    std::unique_ptr<TimedRun> rebalanced_run;
    if (comm->getSize() > 1 && !(scene.domain.rebalance_interval > 0)) {
      Scene with_particles = scene;
      with_particles.domain.rebalance_interval = std::numeric_limits<int>::max();
      rebalanced_run = std::make_unique<TimedRun>(with_particles, dt, comm);
    }
    std::vector<double> block_ratios, rebalanced_ratios;
    for (int done = 0; done < steps; done += kBlockSteps) {
      const int block = std::min(kBlockSteps, steps - done);
      const double local[3] = {coupled_run.block(block), fluid_run.block(block),
                               rebalanced_run ? rebalanced_run->block(block) : 0.0};
      double slowest[3] = {0, 0, 0};
      Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, 3, local, slowest);
      block_ratios.push_back(slowest[0] / slowest[1]);
      rebalanced_ratios.push_back(slowest[2] / slowest[1]);
    }
    std::sort(block_ratios.begin(), block_ratios.end());
    std::sort(rebalanced_ratios.begin(), rebalanced_ratios.end());
    const auto rebalanced = rebalanced_run ? rebalanced_run->slowest(*comm) : std::map<std::string, double>{};
    const auto coupled = coupled_run.slowest(*comm);
    const auto fluid = fluid_run.slowest(*comm);
    const double outer_coupled = coupled_run.outerPerStep(), outer_fluid = fluid_run.outerPerStep();
    const double linear_coupled = coupled_run.linearPerStep(), linear_fluid = fluid_run.linearPerStep();
    if (root) {
      std::cout << "Rzadkiewicz slide, " << scene.domain.cells[0] << " x " << scene.domain.cells[1] << " cells, "
                << comm->getSize() << " rank(s), " << steps << " steps of " << dt << " s\n"
                << "outer pressure iterations per step: coupled " << outer_coupled << ", fluids alone " << outer_fluid
                << "\n"
                << "linear (CG) iterations per step: coupled " << linear_coupled << ", fluids alone " << linear_fluid
                << "\n"
                << std::left << std::setw(26) << "phase" << std::right << std::setw(16) << "coupled us/c-s"
                << std::setw(16) << "fluids us/c-s" << "\n"
                << std::fixed << std::setprecision(3);
      for (const std::string& phase : phases())
        std::cout << std::left << std::setw(26) << phase << std::right << std::setw(16)
                  << 1e6 * coupled.at(phase) / (cells * steps) << std::setw(16) << 1e6 * fluid.at(phase) / (cells * steps)
                  << "\n";
      std::cout << "coupled / fluids alone (whole step): " << coupled.at("step") / fluid.at("step") << "\n"
                << "  per block of " << kBlockSteps << " steps (the runs alternating): lowest " << block_ratios.front()
                << ", median " << block_ratios[block_ratios.size() / 2] << ", highest " << block_ratios.back() << "\n";
      if (rebalanced_run) {
        std::cout << "divided with the particles (domain.rebalance_interval): coupled / fluids alone "
                  << rebalanced.at("step") / fluid.at("step") << " (per block: median "
                  << rebalanced_ratios[rebalanced_ratios.size() / 2] << "); us/c-s:";
        for (const std::string& phase : phases())
          std::cout << (phase == phases().front() ? " " : ", ") << phase << " "
                    << 1e6 * rebalanced.at(phase) / (cells * steps);
        std::cout << "\n";
      }
    }
  }
  return 0;
}
