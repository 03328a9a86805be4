#include "mpmice/simulation.hpp"

#include "ice/material_eos.hpp"
#include "io/output_directory.hpp"
#include "io/progress.hpp"
#include "io/signals.hpp"
#include "io/time_series.hpp"
#include "mpmice/initial_state.hpp"
#include "mpmice/state_output.hpp"

#include <Teuchos_DefaultMpiComm.hpp>

#include <filesystem>
#include <iostream>

namespace cfdmpm {

namespace {

MPI_Comm rawComm(const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  return *Teuchos::rcp_dynamic_cast<const Teuchos::MpiComm<int>>(comm, true)->getRawMpiComm();
}

/// Mass of every material over the whole domain (kg, or kg/m in 2-D).
template <int Dim>
std::vector<double> materialMasses(const CellState<Dim>& state)
{
  const auto rho = state.density.view();
  const double volume = state.density.layout().grid().cellVolume();
  std::vector<double> local(state.materials, 0.0), total(state.materials, 0.0);
  for (LocalOrdinal c = 0; c < state.density.ownedCount(); ++c)
    for (int m = 0; m < state.materials; ++m) local[m] += rho(c, m) * volume;
  Teuchos::reduceAll(*state.density.layout().comm(), Teuchos::REDUCE_SUM, state.materials, local.data(),
                     total.data());
  return total;
}

template <int Dim>
RunSummary run(const Scene& scene, const RunOptions& options, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  const bool root = comm->getRank() == 0;
  const MPI_Comm mpi = rawComm(comm);

  // 1. Grid, decomposition of its patches with METIS, and this rank's share.
  const Grid<Dim> grid(scene.domain);
  const Decomposition decomposition = partitionPatches(grid, comm->getSize());
  const auto layout = std::make_shared<const Layout<Dim>>(grid, decomposition, scene.domain.ghost_width, comm);
  if (root)
    std::cout << "cfdmpm: " << (scene.title.empty() ? scene.path : scene.title) << "\n"
              << "  grid " << grid.cells()[0] << " x " << grid.cells()[1]
              << (Dim == 3 ? " x " + std::to_string(grid.cells()[2]) : std::string()) << " cells, "
              << grid.patchCount() << " patches on " << comm->getSize() << " rank(s)\n";

  // 2. The initial state from the scene's regions and the materials' equations of state.
  CellState<Dim> state(layout, int(scene.materials.size()));
  setInitialState(scene, densityFunctions(scene), state);

  // 3. Output: the directory (refused if it holds an earlier run, unless overwrite), the fields of
  //    step 0, and the diagnostics time series.
  prepareOutputDirectory(mpi, scene.output.directory, options.overwrite || scene.output.overwrite);
  const std::string run_name = std::filesystem::path(scene.path).stem().string();
  StateOutput<Dim> output(scene, *layout, run_name);
  std::vector<std::string> columns{"step", "time", "dt", "dt_limiter"};
  for (const auto& m : scene.materials) columns.push_back("mass_" + m.name);
  const std::string csv_path = scene.output.directory + "/" + run_name + ".csv";
  CsvTimeSeries diagnostics(mpi, csv_path, columns);
  auto report = [&](long long step, double time, double dt, const std::string& limiter) {
    std::vector<CsvValue> row{step, time, dt, limiter};
    for (double mass : materialMasses(state)) row.emplace_back(mass);
    diagnostics.append(row);
  };

  installStopSignalHandlers();
  RunSummary summary;
  summary.output_directory = scene.output.directory;
  summary.diagnostics = csv_path;
  const std::string first = output.write(0, 0.0, state);
  report(0, 0.0, 0.0, "initial");
  if (root) std::cout << "  wrote initial state: " << first << "\n";

  // 4. The time loop. The fluid (ICE) and particle (MPM) steps are not part of this version: the run
  //    sets up the scene and writes its initial state.
  if (root)
    std::cout << "  no time integration in this version (fluid and particle solvers in progress): "
                 "stopping after the initial state\n";
  summary.time_series = output.seriesPath();
  summary.stopped_by_signal = stopRequested(mpi);
  return summary;
}

}  // namespace

RunSummary runScene(const Scene& scene, const RunOptions& options, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  return scene.domain.dimension == 3 ? run<3>(scene, options, comm) : run<2>(scene, options, comm);
}

}  // namespace cfdmpm
