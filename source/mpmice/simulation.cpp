#include "mpmice/simulation.hpp"

#include "common/error.hpp"
#include "common/mpi_comm.hpp"
#include "input/parameter_rule.hpp"
#include "mpmice/checkpoint.hpp"
#include "mpmice/mpmice_step.hpp"
#include "io/output_directory.hpp"
#include "io/progress.hpp"
#include "io/signals.hpp"
#include "io/time_series.hpp"
#include "mpmice/run_state.hpp"
#include "mpmice/state_output.hpp"

#include <Teuchos_TimeMonitor.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

namespace cfdmpm {

namespace {

/// Per material: mass, momentum components and kinetic energy summed over the owned cells, as one
/// Kokkos reduction into an array (so that it runs on every thread of a threaded build).
template <int Dim, class DensityView, class VelocityView>
struct ConservedSums {
  using value_type = double[];
  using size_type = std::size_t;
  size_type value_count;  // materials * (Dim + 2)
  DensityView rho;
  VelocityView u;
  double volume;
  int materials;

  KOKKOS_INLINE_FUNCTION void operator()(const LocalOrdinal c, value_type sums) const
  {
    for (int m = 0; m < materials; ++m) {
      const double mass = rho(c, m) * volume;
      double speed2 = 0;
      sums[m * (Dim + 2)] += mass;
      for (int d = 0; d < Dim; ++d) {
        const double ud = u(c, CellState<Dim>::velocityColumn(m, d));
        sums[m * (Dim + 2) + 1 + d] += mass * ud;
        speed2 += ud * ud;
      }
      sums[m * (Dim + 2) + 1 + Dim] += 0.5 * mass * speed2;
    }
  }
  KOKKOS_INLINE_FUNCTION void init(value_type sums) const
  {
    for (size_type i = 0; i < value_count; ++i) sums[i] = 0.0;
  }
  KOKKOS_INLINE_FUNCTION void join(volatile value_type sums, const volatile value_type other) const
  {
    for (size_type i = 0; i < value_count; ++i) sums[i] += other[i];
  }
};

/// Conserved quantities per material over the whole domain (per metre of depth in 2-D): mass (kg),
/// momentum components (kg m/s) and kinetic energy (J), in the order of conservedColumns().
template <int Dim>
std::vector<double> conservedQuantities(const CellState<Dim>& state)
{
  const auto rho = state.density.view();
  const auto u = state.velocity.view();
  ConservedSums<Dim, decltype(rho), decltype(u)> sums{std::size_t(state.materials * (Dim + 2)), rho, u,
                                                      state.density.layout().grid().cellVolume(), state.materials};
  std::vector<double> local(sums.value_count, 0.0), total(local.size(), 0.0);
  Kokkos::parallel_reduce("conserved quantities", Kokkos::RangePolicy<ExecutionSpace>(0, state.density.ownedCount()),
                          sums, local.data());
  Teuchos::reduceAll(*state.density.layout().comm(), Teuchos::REDUCE_SUM, int(local.size()), local.data(),
                     total.data());
  return total;
}

template <int Dim>
std::vector<std::string> conservedColumns(const Scene& scene, bool fluids_only = false)
{
  std::vector<std::string> columns;
  for (const auto& m : scene.materials) {
    if (fluids_only && m.kind != "fluid") continue;
    columns.push_back("mass_" + m.name);
    for (int d = 0; d < Dim; ++d) columns.push_back(std::string("momentum_") + "xyz"[d] + "_" + m.name);
    columns.push_back("kinetic_energy_" + m.name);
  }
  return columns;
}

/// The failure of the lowest rank that has one, on every rank; empty when no rank failed.
/// Collective: every rank ends each step attempt here, so a failure on any rank stops all of them
/// together instead of leaving some waiting in the next collective.
std::string agreedFailure(MPI_Comm comm, const std::string& failure)
{
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  int reporter = failure.empty() ? ranks : rank, first = ranks;
  MPI_Allreduce(&reporter, &first, 1, MPI_INT, MPI_MIN, comm);
  return first == ranks ? std::string() : broadcastText(comm, first, failure);
}

/// What redoing the decomposition found: the estimated imbalance (loadImbalance) of the division
/// before and after, and the patches that changed rank (0: the run kept its division).
struct RebalanceReport {
  double imbalance_before = 0;
  double imbalance_after = 0;
  int patches_moved = 0;
};

template <int Dim>
RunSummary run(const Scene& scene, const RunOptions& options, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  const bool root = comm->getRank() == 0;
  const MPI_Comm mpi = rawMpiComm(comm);

  // 1. Grid and the decomposition of its patches with METIS by their cells. A restart on as many
  //    ranks continues on the checkpoint's decomposition (a rebalance may have changed it); on
  //    another number it starts from cells and, with rebalancing on, is redone with the particles
  //    before its first step.
  const Grid<Dim> grid(scene.domain);
  const int ranks = comm->getSize();
  const bool restarting = !options.restart_checkpoint.empty();
  Decomposition decomposition;
  bool rebalance_first = false;
  bool continues_division = false;  // a restart on the checkpoint's decomposition
  if (restarting) {
    const CheckpointHeader header = readCheckpointHeader(mpi, options.restart_checkpoint);
    if (header.ranks == ranks) {
      if (int(header.decomposition.size()) != grid.patchCount() ||
          std::any_of(header.decomposition.begin(), header.decomposition.end(), [&](int r) { return r < 0 || r >= ranks; }))
        throw InputError("checkpoint '" + header.path + "': its attribute decomposition is not one rank of " +
                         std::to_string(ranks) + " for each of the grid's " + std::to_string(grid.patchCount()) +
                         " patches");
      decomposition.ranks = ranks;
      decomposition.patch_owner = header.decomposition;
      continues_division = true;
    } else {
      decomposition = partitionPatches(grid, ranks);
      rebalance_first = scene.domain.rebalance_interval > 0;
    }
  } else {
    decomposition = partitionPatches(grid, ranks);
  }
  if (root)
    std::cout << "cfdmpm: " << (scene.title.empty() ? scene.path : scene.title) << "\n"
              << "  grid " << grid.cells()[0] << " x " << grid.cells()[1]
              << (Dim == 3 ? " x " + std::to_string(grid.cells()[2]) : std::string()) << " cells, "
              << grid.patchCount() << " patches on " << ranks << " rank(s)\n";

  // 2. The initial state from the scene's regions and the materials' equations of state, and the
  //    coupled step with the material sets the scene has (their settings are checked here, before
  //    any output): fluids move unless ice.enabled is false (then they are an inert background, a
  //    dry scene for the particles alone); solids are particles.
  //    A rebalance replaces all three (layout, state, step) with new ones: `run_state` is the
  //    current set.
  RunState<Dim> run_state = buildRunState(scene, grid, decomposition, comm);
  // Where rigid bodies fill cells the fluid phases skip them (IceSolver::closedCells), and a
  // division by cell counts leaves the rank that holds a bed waiting for the others: the patches
  // are divided again with those cells at kClosedCellWork (not on a restart that continues on the
  // checkpoint's division, which was made so).
  if (!continues_division) {
    const Division division = divisionByOpenCells(run_state, kRebalanceGain);
    if (!(division.decomposition.patch_owner == run_state.layout->decomposition().patch_owner)) {
      run_state = buildRunState(scene, grid, division.decomposition, comm);
      if (root) {
        std::ostringstream line;
        line.precision(3);
        line << "  patches divided by their open cells (" << division.closed_cells
             << " cells inside rigid bodies, each " << kClosedCellWork << " of an open one): imbalance "
             << division.imbalance_before << " -> " << division.imbalance_after << "\n";
        std::cout << line.str();
      }
    }
  }
  CoupledStepReport step_report;
  const bool moves = run_state.step->fluidsMove() || run_state.step->hasParticles();
  const bool fluids_move = run_state.step->fluidsMove(), has_particles = run_state.step->hasParticles();
  std::vector<std::string> physics_columns;
  if (fluids_move) {
    physics_columns = {"outer_iterations", "pressure_iterations", "outer_residual", "max_outflux_fraction"};
    // With particles, the solids' columns are theirs (exact masses), not the cells'.
    for (const std::string& c : conservedColumns<Dim>(scene, has_particles)) physics_columns.push_back(c);
    physics_columns.insert(physics_columns.end(), {"equilibration_failures", "equilibration_jump", "exchange_failures", "pressure_converged"});
    if (has_particles) physics_columns.push_back("reference_shift");
  }
  if (has_particles) {
    if (fluids_move) physics_columns.push_back("particle_steps");
    physics_columns.push_back("particles");
    for (const auto& m : scene.materials)
      if (m.kind == "solid") physics_columns.push_back("mass_" + m.name);
    for (int d = 0; d < Dim; ++d) physics_columns.push_back(std::string("momentum_") + "xyz"[d] + "_particles");
    physics_columns.push_back("kinetic_energy_particles");
  }
  auto physicsRow = [&] {
    std::vector<CsvValue> row;
    if (fluids_move) {
      const IceStepReport& r = step_report.ice;
      row = {r.outer_iterations, r.linear_iterations, r.outer_residual, r.max_outflux_fraction};
      const std::vector<double> sums = conservedQuantities(*run_state.cells);
      for (int m = 0; m < run_state.cells->materials; ++m)
        if (!has_particles || scene.materials[m].kind == "fluid")
          for (int k = 0; k < Dim + 2; ++k) row.emplace_back(sums[m * (Dim + 2) + k]);
      row.insert(row.end(), {CsvValue(r.equilibration_failures), CsvValue(r.equilibration_jump), CsvValue(r.exchange_failures),
                             CsvValue(r.converged ? 1 : 0)});
      if (has_particles) row.emplace_back(r.reference_shift);
    }
    if (const mpm::MpmSolver<Dim>* particles = run_state.step->particles()) {
      if (fluids_move) row.emplace_back(step_report.particle_steps);
      row.emplace_back(particles->particleCount());
      for (double m : particles->materialMasses()) row.emplace_back(m);
      const auto p = particles->momentum();
      for (int d = 0; d < Dim; ++d) row.emplace_back(p[d]);
      row.emplace_back(particles->kineticEnergy());
    }
    return row;
  };

  // 3. Output. A new run: the directory (refused if it holds an earlier run, unless overwrite), the
  //    fields of step 0 and the diagnostics time series. A restart: the state, the solvers' own
  //    state and the run's clock from the checkpoint; what the first run wrote after it is removed,
  //    the time series and the CSV continue from it.
  StateOutput<Dim>::checkFields(scene);
  const std::string run_name =
      options.run_name.empty() ? std::filesystem::path(scene.path).stem().string() : options.run_name;
  RunClock clock;
  std::vector<WrittenStep> written_before;
  if (restarting) {
    clock = readCheckpoint(options.restart_checkpoint, run_state, written_before);
  } else {
    prepareOutputDirectory(mpi, scene.output.directory, options.overwrite || scene.output.overwrite);
  }
  StateOutput<Dim> output(scene, *run_state.layout, run_name);
  std::vector<std::string> columns{"step", "time", "dt", "dt_limiter", "retries"};
  if (moves)
    columns.insert(columns.end(), physics_columns.begin(), physics_columns.end());
  else
    for (const std::string& c : conservedColumns<Dim>(scene)) columns.push_back(c);
  const int rebalance_interval = scene.domain.rebalance_interval;
  if (moves && rebalance_interval > 0) columns.insert(columns.end(), {"imbalance_before", "imbalance_after", "patches_moved"});
  const std::string csv_path = scene.output.directory + "/" + run_name + ".csv";
  const auto diagnostics = restarting ? std::make_unique<CsvTimeSeries>(mpi, csv_path, columns, clock.step)
                                      : std::make_unique<CsvTimeSeries>(mpi, csv_path, columns);
  if (restarting) prepareRestartDirectory(mpi, scene.output.directory, run_name, clock.step);
  // The rebalance made before the step a row reports, if any.
  std::optional<RebalanceReport> rebalanced;
  auto report = [&](long long step, double time, double dt, const std::string& limiter, int retries) {
    std::vector<CsvValue> row{step, time, dt, limiter, retries};
    if (moves) {
      for (CsvValue& v : physicsRow()) row.push_back(v);
    } else {
      for (double q : conservedQuantities(*run_state.cells)) row.emplace_back(q);
    }
    if (moves && rebalance_interval > 0) {
      if (rebalanced)
        row.insert(row.end(), {rebalanced->imbalance_before, rebalanced->imbalance_after, rebalanced->patches_moved});
      else
        row.insert(row.end(), {"", "", ""});
    }
    diagnostics->append(row);
  };

  installStopSignalHandlers();
  RunSummary summary;
  summary.output_directory = scene.output.directory;
  summary.diagnostics = csv_path;
  auto writeOutput = [&](long long step, double time) {
    if (!run_state.step->particles()) return output.write(step, time, *run_state.cells);
    const mpm::ParticleOutput out = run_state.step->particles()->output();
    return output.write(step, time, *run_state.cells, &out);
  };
  summary.time_series = output.seriesPath();
  if (restarting) {
    output.restoreSteps(written_before);
    if (root)
      std::cout << "  restarted from " << options.restart_checkpoint << ": step " << clock.step << ", t = "
                << showNumber(clock.time) << " s\n";
  } else {
    const std::string first = writeOutput(0, 0.0);
    report(0, 0.0, 0.0, "initial", 0);
    if (root) std::cout << "  wrote initial state: " << first << "\n";
  }
  if (!moves) {
    if (root) std::cout << "  ice.enabled is false and the scene has no solids: nothing moves; stopping\n";
    return summary;
  }

  // 4. Checkpoints, every output.checkpoint_interval of simulated time or checkpoint_wall_interval
  //    of wall time (rank 0's clock decides for all), and when the run stops.
  const double checkpoint_interval = scene.output.checkpoint_interval;
  const double checkpoint_wall = scene.output.checkpoint_wall_interval;
  std::unique_ptr<CheckpointWriter<Dim>> checkpoints;
  if (checkpoint_interval > 0 || checkpoint_wall > 0)
    checkpoints = std::make_unique<CheckpointWriter<Dim>>(scene, *run_state.layout, run_name, scene.output.directory);
  auto last_checkpoint_wall = std::chrono::steady_clock::now();
  long long last_checkpoint_step = restarting ? clock.step : -1;
  auto writeCheckpoint = [&] {
    const std::string path = checkpoints->write(clock, *run_state.cells, *run_state.step, output.writtenSteps());
    last_checkpoint_step = clock.step;
    last_checkpoint_wall = std::chrono::steady_clock::now();
    if (root) std::cout << "  checkpoint: " << path << "\n";
  };
  auto wallCheckpointDue = [&] {
    int due = 0;
    if (root)
      due = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint_wall).count() >=
            checkpoint_wall;
    MPI_Bcast(&due, 1, MPI_INT, 0, mpi);
    return due != 0;
  };

  // 5. The time loop: Δt from the solver's limits, clipped to land on output times and the end.
  //    output_mark is the next output time before clipping to the end, so that a restart with a
  //    later end time continues the same schedule.
  const double end = scene.time.end_time;
  const double interval = scene.output.interval;
  const double output_period = interval > 0 ? interval : end;
  if (!restarting) {
    clock.output_mark = output_period;
    clock.checkpoint_mark = checkpoint_interval;
  }
  double next_output = restarting ? std::min(end, clock.output_mark) : clock.output_mark;
  double& t = clock.time;
  long long& step = clock.step;
  ProgressReporter progress(mpi, t, end, scene.output.progress_interval);
  const double eps = 1e-12 * end;

  // A failed step (mpmice_step.hpp: StepFailure, or a pressure outer iteration that did not reach
  // its tolerance) is undone and retried with half its Δt, up to time.step_retries times and not
  // below time.dt_min. An outer iteration that still has not converged then is accepted with a
  // warning (column pressure_converged); any other failure ends the run: the state from before the
  // step is written as a step file and a checkpoint, and StepFailure names the step, the cell or
  // particle, the material and the quantity. CFDMPM_TEST_UNDO_STEP=<n>, for tests only: step n is
  // undone once after it succeeded and run again with the same Δt (the run must not change).
  const char* undo_hook = std::getenv("CFDMPM_TEST_UNDO_STEP");
  const long long test_undo_step = undo_hook ? std::atoll(undo_hook) : -1;
  auto outerIterationFailure = [&] {
    std::ostringstream text;
    text << "the pressure's outer iteration stopped at residual " << step_report.ice.outer_residual << " after "
         << step_report.ice.outer_iterations << " iterations (ice.outer_tolerance "
         << run_state.step->fluids()->settings().outer_tolerance << ", ice.max_outer_iterations "
         << run_state.step->fluids()->settings().max_outer_iterations << ")";
    return text.str();
  };
  // One attempt at the step; the failure, the same text on every rank, or empty.
  auto attempt = [&](double dt) {
    std::string failure;
    try {
      step_report = run_state.step->step(*run_state.cells, dt);
    } catch (const StepFailure& e) {
      failure = e.what();
    }
    return agreedFailure(mpi, failure);
  };
  auto giveUp = [&](const std::string& failure, int retries, double dt) {
    // The state is the one before the failed step: the last good one.
    const std::vector<WrittenStep>& written = output.writtenSteps();
    const std::string file = written.empty() || written.back().step != step
                                 ? writeOutput(step, t)
                                 : scene.output.directory + "/" + written.back().file;
    if (!checkpoints)
      checkpoints = std::make_unique<CheckpointWriter<Dim>>(scene, *run_state.layout, run_name, scene.output.directory);
    if (last_checkpoint_step != step) writeCheckpoint();
    std::ostringstream message;
    message << "step " << step + 1 << " from t = " << showNumber(t) << " s failed";
    if (retries > 0) message << " " << retries + 1 << " times, the last with dt = " << showNumber(dt) << " s";
    message << ": " << failure << ". ";
    // retries < 0: the step was not tried (its stable time step is below time.dt_min).
    if (retries >= 0)
      message << (retries < scene.time.step_retries
                      ? "Half that time step would be below time.dt_min (" + showNumber(scene.time.dt_min) + " s)"
                      : "time.step_retries is " + std::to_string(scene.time.step_retries))
              << ". ";
    message << "The last good state, step " << step << " at t = " << showNumber(t) << " s, is in " << file
            << " and its checkpoint in "
            << checkpointDirectory(scene.output.directory) << "/ (cfdmpm --restart " << scene.output.directory
            << " [scene.yaml] continues from it, e.g. with a smaller "
            << (retries < 0 ? "time.dt_min" : "time.cfl or time.dt_max") << ")";
    throw StepFailure(message.str());
  };

  // Every domain.rebalance_interval steps, the patches are divided again with METIS so that the
  // cells' work and the particles' work (patchWork) are balanced each on its own, as the phases
  // that do them wait for their own slowest rank; the run moves to the new division (redistribute:
  // the way a restart builds a run, with the state of this one) when its estimated imbalance is
  // lower by more than kRebalanceGain. Every rank computes the same weights and the same division.
  int rebalance_messages = 0;
  const Teuchos::RCP<Teuchos::Time> rebalance_timer = Teuchos::TimeMonitor::getNewCounter("cfdmpm: rebalance");
  auto rebalance = [&] {
    Teuchos::TimeMonitor timed(*rebalance_timer);
    RebalanceReport result;
    const Decomposition& current = run_state.layout->decomposition();
    const Redivision division = divisionWithParticles(run_state, kRebalanceGain);
    result.imbalance_before = division.imbalance_before;
    result.imbalance_after = division.imbalance_after;
    const Decomposition& balanced = division.decomposition;
    for (int p = 0; p < grid.patchCount(); ++p) result.patches_moved += balanced.patch_owner[p] != current.patch_owner[p];
    if (result.patches_moved == 0) return result;
    run_state = redistribute(scene, run_state, balanced);
    output.moveTo(*run_state.layout);
    if (checkpoints)
      checkpoints = std::make_unique<CheckpointWriter<Dim>>(scene, *run_state.layout, run_name, scene.output.directory);
    if (root && ++rebalance_messages <= 10) {
      std::ostringstream line;
      line.precision(3);
      line << "  step " << step << ": patches divided again by their cells and particles, imbalance "
           << result.imbalance_before << " -> " << result.imbalance_after << ", " << result.patches_moved
           << " of " << grid.patchCount() << " patches moved"
           << (rebalance_messages == 10 ? " (further rebalances in the CSV only)" : "") << "\n";
      std::cout << line.str();
    }
    return result;
  };

  while (t < end - eps && (scene.time.max_steps < 0 || step < scene.time.max_steps)) {
    rebalanced.reset();
    if (rebalance_interval > 0 && (step % rebalance_interval == 0 || rebalance_first)) {
      rebalanced = rebalance();
      rebalance_first = false;
    }
    TimeStepLimit limit = run_state.step->stableTimeStep(*run_state.cells, clock.dt_previous);
    if (limit.dt < scene.time.dt_min) {
      // Run on at dt_min, such a state would take its steps without end (and unstably).
      std::ostringstream reason;
      reason << "its stable time step is " << showNumber(limit.dt) << " s (" << limit.limiter
             << (limit.where.empty() ? "" : ", " + limit.where) << "), below time.dt_min ("
             << showNumber(scene.time.dt_min) << " s)";
      giveUp(reason.str(), -1, limit.dt);
    }
    if (step == 0 && scene.time.dt_initial < limit.dt) limit = {scene.time.dt_initial, "dt_initial"};
    clock.dt_previous = limit.dt;
    double dt = limit.dt;
    if (t + dt > next_output - eps) {
      dt = next_output - t;
      limit.limiter += "+output";
    } else if (t + 2 * dt > next_output - eps) {
      // Two equal steps to the output time instead of a full one and a sliver: the pressure
      // equation's residual becomes a velocity error of order tolerance h / Δt, large for a sliver.
      dt = 0.5 * (next_output - t);
      limit.limiter += "+output";
    }
    run_state.step->saveState(*run_state.cells);
    int retries = 0;
    double unconverged_residual = INFINITY;  // of the previous attempt, when its outer iteration stopped short
    for (;;) {
      std::string failure = attempt(dt);
      const bool unconverged = failure.empty() && fluids_move && !step_report.ice.converged;
      if (unconverged) failure = outerIterationFailure();
      const bool test_undo = failure.empty() && retries == 0 && step + 1 == test_undo_step;
      if (test_undo) failure = "undone by CFDMPM_TEST_UNDO_STEP (a test)";
      if (failure.empty()) {
        if (retries > 0 && !test_undo) clock.dt_previous = dt;  // the next step grows from the Δt that worked
        break;
      }
      const double retry_dt = test_undo ? dt : 0.5 * dt;
      // An outer iteration that stops no lower with half the Δt has stalled (a floor of round-off or
      // of the upwinded fluxes) rather than diverged: a smaller step does not cure it. It is then
      // accepted as it is when the retries run out, and the next step grows from the Δt limit as
      // if no retry had been made, so that a scene where this is common does not shrink its Δt.
      const bool stalled = unconverged && step_report.ice.outer_residual >= unconverged_residual;
      if (unconverged) unconverged_residual = step_report.ice.outer_residual;
      const bool exhausted = retries >= scene.time.step_retries || retry_dt < scene.time.dt_min;
      if (unconverged && (exhausted || stalled)) {
        // Counted on every rank (the report is the same on all): a checkpoint stores the count.
        if (++clock.unconverged_warnings <= 10 && root)
          std::cout << "  warning: step " << step + 1 << ": " << failure
                    << "; column pressure_converged of the CSV marks such steps"
                    << (clock.unconverged_warnings == 10 ? " (further warnings suppressed)" : "") << "\n";
        break;
      }
      run_state.step->restoreState(*run_state.cells);
      if (exhausted) giveUp(failure, retries, dt);
      ++retries;
      if (root)
        std::cout << "  step " << step + 1 << " undone: " << failure << "; retry " << retries << " of "
                  << scene.time.step_retries << " with dt = " << showNumber(retry_dt) << " s\n";
      dt = retry_dt;
    }
    if (retries > 0) {
      limit.limiter += "+retry";
      ++summary.retried_steps;
      summary.undone_attempts += retries;
    }
    t = (t + dt > next_output - eps) ? next_output : t + dt;
    const bool output_time = t >= next_output - eps;
    ++step;
    report(step, t, dt, limit.limiter, retries);
    const bool stop = stopRequested(mpi);
    const bool last = t >= end - eps || stop || (scene.time.max_steps >= 0 && step >= scene.time.max_steps);
    if (output_time || last) writeOutput(step, t);
    if (output_time) {
      clock.output_mark += output_period;
      next_output = std::min(end, clock.output_mark);
    }
    if (checkpoints) {
      bool due = checkpoint_interval > 0 && t >= clock.checkpoint_mark - eps;
      while (checkpoint_interval > 0 && t >= clock.checkpoint_mark - eps) clock.checkpoint_mark += checkpoint_interval;
      if (checkpoint_wall > 0 && wallCheckpointDue()) due = true;
      if (due || (last && last_checkpoint_step != step)) writeCheckpoint();
    }
    progress.update(step, t, dt, last);
    if (stop) {
      summary.stopped_by_signal = true;
      break;
    }
  }
  summary.steps = step;
  summary.time = t;
  return summary;
}

}  // namespace

RunSummary runScene(const Scene& scene, const RunOptions& options, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  return scene.domain.dimension == 3 ? run<3>(scene, options, comm) : run<2>(scene, options, comm);
}

}  // namespace cfdmpm
