// Benchmark of the coupled step on the seed scene (input/rzadkiewicz.yaml, 10 mm cells): microseconds
// per cell and step of the whole coupled step and per phase (Teuchos timers "mpmice: <phase>"), next
// to the fluid step alone on the same grid in the same run (the scene without its solids: water and
// air), and their ratio. Both run the same number of steps at the same fixed Δt, after a warm-up.
//
// usage: [mpiexec -n N] bench_mpmice [steps [dt]]     (defaults 200 steps of 2e-5 s)
#include "coupled_support.hpp"
#include "mpmice/run_state.hpp"

#include <Tpetra_Core.hpp>

#include <iomanip>
#include <iostream>

using namespace cfdmpm;

namespace {

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

/// Runs `steps` steps of dt after 5 warm-up steps; returns the slowest rank's seconds per phase.
/// Also the outer and linear (CG) pressure iterations per step, and the ICE pressure phase [5] alone
/// (outer iterations, matrix, solves) as the phase "5 pressure" (inside "3-6 fluid pressure").
std::map<std::string, double> measure(const Scene& scene, int steps, double dt, double& outer_per_step,
                                      double& linear_per_step, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  // The division the program takes: by cells, or with the cells that rigid bodies fill weighed
  // less (divisionByOpenCells), from the initial state.
  const Grid<2> grid(scene.domain);
  const Decomposition division =
      divisionByOpenCells(buildRunState(scene, grid, partitionPatches(grid, comm->getSize()), comm), 0.0)
          .decomposition;
  test::CoupledRun<2> run(scene, comm, division);
  const auto advance = [&] {
    run.last = run.stepper.step(run.state, dt);
    run.time += dt;
  };
  for (int s = 0; s < 5; ++s) advance();
  std::map<std::string, double> before, spent;
  const auto seconds = [&](const std::string& phase) {
    return phase == "5 pressure" ? run.stepper.fluids()->phaseSeconds("pressure") : run.stepper.phaseSeconds(phase);
  };
  for (const std::string& phase : phases()) before[phase] = seconds(phase);
  long long outer = 0, linear = 0;
  for (int s = 0; s < steps; ++s) {
    advance();
    outer += run.last.ice.outer_iterations;
    linear += run.last.ice.linear_iterations;
  }
  outer_per_step = double(outer) / steps;
  linear_per_step = double(linear) / steps;
  for (const std::string& phase : phases()) {
    double local = seconds(phase) - before[phase], slowest = 0;
    Teuchos::reduceAll(*comm, Teuchos::REDUCE_MAX, local, Teuchos::outArg(slowest));
    spent[phase] = slowest;
  }
  return spent;
}

}  // namespace

int main(int argc, char** argv)
{
  Tpetra::ScopeGuard guard(&argc, &argv);
  {
    const auto comm = Tpetra::getDefaultComm();
    const bool root = comm->getRank() == 0;
    const int steps = argc > 1 ? std::atoi(argv[1]) : 200;
    const double dt = argc > 2 ? std::atof(argv[2]) : 2e-5;
    const Scene scene = readScene(std::string(CFDMPM_SOURCE_DIR) + "/input/rzadkiewicz.yaml");
    const double cells = double(scene.domain.cells[0] * scene.domain.cells[1]);
    double outer_coupled = 0, outer_fluid = 0, linear_coupled = 0, linear_fluid = 0;
    const auto coupled = measure(scene, steps, dt, outer_coupled, linear_coupled, comm);
    const auto fluid = measure(fluidsOnly(scene), steps, dt, outer_fluid, linear_fluid, comm);
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
      std::cout << "coupled / fluids alone (whole step): " << coupled.at("step") / fluid.at("step") << "\n";
    }
  }
  return 0;
}
