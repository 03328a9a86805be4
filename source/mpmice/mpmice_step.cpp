#include "mpmice/mpmice_step.hpp"

#include "mpmice/initial_state.hpp"

#include "common/error.hpp"

#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_TimeMonitor.hpp>

#include <algorithm>
#include <climits>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cfdmpm {

namespace {

bool hasSolids(const Scene& scene)
{
  for (const MaterialSpec& m : scene.materials)
    if (m.kind == "solid") return true;
  return false;
}

}  // namespace

template <int Dim>
MpmIceStep<Dim>::MpmIceStep(const Scene& scene, std::shared_ptr<const Layout<Dim>> layout, CellState<Dim>& state)
    : scene_(scene), layout_(std::move(layout))
{
  for (const char* phase : kPhases) timers_[phase] = Teuchos::TimeMonitor::getNewCounter(std::string("mpmice: ") + phase);
  if (hasSolids(scene)) mpm_ = std::make_unique<mpm::MpmSolver<Dim>>(scene, layout_, mpm::optionsFromScene(scene));
  if (IceSettings::fromScene(scene).enabled) {
    std::vector<SolidProperties> solids;
    if (mpm_)
      for (const mpm::SolidMaterial& s : mpm_->materials())
        solids.push_back(SolidProperties{s.scene_index, s.bulk_modulus, s.density, s.rigid, s.reference_pressure_inside});
    ice_ = std::make_unique<IceSolver<Dim>>(scene, layout_, solids);
    ice_->setSolidReferencePressure(state.pressure);
    ice_->setKinematicSolids(scene.mpm.coupling == "staggered");
  }
  if (ice_ && mpm_) {
    // The solids' share of every cell is that of their particles' GIMP domains; the fluids fill the
    // rest, so that the first equilibration starts from full cells.
    const int columns = mpm::MpmSolver<Dim>::cellColumns(int(mpm_->materials().size()));
    cell_sums_ = std::make_unique<Field<Dim>>(layout_, Location::Cell, columns, "solid cell sums");
    stationary_rows_ = Kokkos::View<unsigned char*, MemorySpace>("cells of the solids at rest alone", cell_sums_->overlapCount());
    cell_change_ = std::make_unique<Field<Dim>>(layout_, Location::Cell, columns, "solid velocity change");
    solid_velocity_ = std::make_unique<Field<Dim>>(layout_, Location::Cell, int(mpm_->materials().size()) * Dim,
                                                   "solid cell velocity");
    mpm_->particlesToGrid();
    mpm_->integrateGrid(0.0);  // v* = v: the particles' velocities on the grid, walls applied
    cellsFromParticles(state, 0.0);
    substeps_ = scene.mpm.substeps;  // after the first cell sums, which take v* (integrateGrid(0))
    fillAroundSolids(scene, densityFunctions(scene), state);
  }
  if (ice_ && mpm_ && scene.mpm.solid_volume == "particles") {
    predicted_volume_ = std::make_unique<Field<Dim>>(layout_, Location::Cell, int(mpm_->materials().size()),
                                                     "solid volume of a predicted step");
    trial_state_ = std::make_unique<CellState<Dim>>(layout_, state.materials);
    ice_->setSolidVolumePredictor([this](CellState<Dim>& s, double dt) { predictSolidVolumes(s, dt); });
  }
  if (ice_) {
    const int failures = ice_->equilibrate(state);
    if (failures > 0)
      throw std::runtime_error("initial equilibration pressure failed in " + std::to_string(failures) + " cells");
    ice_->markClosedCells(state);  // for the decomposition's weights; every step marks them again
  }
}

template <int Dim>
MpmIceStep<Dim>::~MpmIceStep() = default;

template <int Dim>
CoupledStepReport MpmIceStep<Dim>::step(CellState<Dim>& state, double dt)
{
  CoupledStepReport report;
  Teuchos::TimeMonitor whole(*timers_.at("step"));
  // With mpm.substeps > 1 the particles take as many steps inside this one as their own stable
  // step needs (stableTimeStep allowed the fluids' step to be up to `substeps` of them long).
  if (substeps_ > 1) {
    const double particle_dt = mpm_->stableTimeStep().dt;
    if (std::isfinite(particle_dt) && particle_dt > 0)
      report.particle_steps = std::max(1, int(std::ceil(dt / particle_dt * (1.0 - 1e-12))));
  }
  const int particle_steps = report.particle_steps;

  // 1. Particles to nodes: mass, momentum, the skeleton stress's force and gravity; v* with contact
  //    between solids and the walls: the solids' velocity at the end of the step before the fluids
  //    act, from which the fluids' phases take the solids' velocity and volume change. With particle
  //    steps inside this one (mpm.substeps > 1) a grid update over the whole step would overshoot
  //    the particles' elastic wave; that forecast is each particle's velocity plus Δt times its own
  //    acceleration of the last step instead (2.), and the particle steps (9.) move the particles.
  if (mpm_) {
    Teuchos::TimeMonitor phase(*timers_.at("1 particles to grid"));
    mpm_->particlesToGrid();
    if (substeps_ == 1) mpm_->integrateGrid(dt);
  }
  // 2. The solids' mass, volume and velocity v* in every cell.
  if (ice_ && mpm_) {
    Teuchos::TimeMonitor phase(*timers_.at("2 particles to cells"));
    cellsFromParticles(state, dt);
  }
  if (ice_) {
    // 3-6. Equilibration pressure, face velocities and face exchange, implicit pressure, momentum
    //      sources: every material, solids included.
    {
      Teuchos::TimeMonitor phase(*timers_.at("3-6 fluid pressure"));
      ice_->equilibrationPhase(state, report.ice);
      if (report.ice.equilibration_failures > 0) {
        std::ostringstream message;
        message << "coupled step: the equilibration pressure did not converge in " << report.ice.equilibration_failures
                << " cell(s), the first at " << layout_->grid().cellName(report.ice.first_failed_equilibration)
                << "; its materials' densities admit no common pressure (a material compressed beyond what its "
                   "equation of state represents; reduce the time step or check the materials' parameters)";
        throw StepFailure(message.str());
      }
      ice_->faceVelocityPhase(state, dt);
      ice_->pressurePhase(state, dt, report.ice);
      if (!std::isfinite(report.ice.outer_residual)) {
        // The pressure equation met a value that is not finite. Its cell inputs (densities, volume
        // fractions, specific volumes, velocities) are as the phase found them: the first one that
        // is not finite names the cell and material; otherwise a face velocity or a solid's volume
        // change is (left to spread, the solve makes every cell's pressure NaN, and the exchange
        // then reported every cell, the first at (0, 0)).
        checkFinite(state, false);
        std::ostringstream message;
        message << "coupled step: the pressure equation's right-hand side is not finite";
        if (report.ice.first_nonfinite_pressure_cell >= 0)
          message << " at " << layout_->grid().cellName(report.ice.first_nonfinite_pressure_cell) << " (the lowest such cell)";
        message << ", while every cell's density, volume fraction, specific volume and velocity is: a face "
                   "velocity or a solid's volume change from its particles there is not (reduce the time step)";
        throw StepFailure(message.str());
      }
      ice_->momentumSourcePhase(state, dt);
    }
    // 8. Cell-centred exchange between all materials.
    {
      Teuchos::TimeMonitor phase(*timers_.at("8 exchange"));
      ice_->exchangePhase(state, dt, report.ice);
    }
    if (report.ice.exchange_failures > 0) {
      const long long cell = report.ice.first_failed_cell;
      std::ostringstream message;
      message << "coupled step: the momentum exchange gave values that are not finite in " << report.ice.exchange_failures
              << " cell(s), the first at " << layout_->grid().cellName(cell) << "; a material's density, volume fraction or velocity there is not finite (reduce the time step "
                 "or check the materials' parameters)";
      throw StepFailure(message.str());
    }
  }
  // 9. The solids' velocity change from the pressure force and the exchange back to the nodes;
  //    grid to particles; stress update; particles to their ranks. With n particle steps in this
  //    one, each takes its own grid velocity from its particles and 1/n of the nodes' momentum
  //    change: the fluids' force on the solids is held over the step, and the particles take in
  //    all what the fluids gave up (doc/mpmice.md, "Particle steps inside a fluid step").
  if (mpm_) {
    Teuchos::TimeMonitor phase(*timers_.at("9 grid to particles"));
    if (ice_) {
      velocityChange(state);
      mpm_->cellVelocityChangeToParticles(*cell_change_);
    }
    if (substeps_ > 1) mpm_->startOwnMotion();
    const double particle_dt = dt / particle_steps;
    for (int k = 0; k < particle_steps; ++k) {
      if (k > 0) mpm_->particlesToGrid();
      if (substeps_ > 1) mpm_->integrateGrid(particle_dt);  // else step 1's, Δt long
      if (ice_) mpm_->addParticleVelocityChange(1.0 / particle_steps);
      mpm_->gridToParticles(particle_dt);
      mpm_->updateStress(particle_dt);
      mpm_->relocateParticles();
    }
    if (substeps_ > 1) mpm_->recordOwnAcceleration(dt);
  }
  // 10. Advection of the fluids.
  if (ice_) {
    Teuchos::TimeMonitor phase(*timers_.at("10 advection"));
    ice_->advectionPhase(state, dt, report.ice);
  }
  // 12. Every value of the new state is finite (the phases check what they can cure; this catches
  //     the rest, such as a stress update that overflowed).
  {
    Teuchos::TimeMonitor phase(*timers_.at("12 finite"));
    checkFinite(state);
  }
  return report;
}

template <int Dim>
void MpmIceStep<Dim>::saveState(const CellState<Dim>& state)
{
  if (!saved_state_) saved_state_ = std::make_unique<CellState<Dim>>(layout_, state.materials);
  saved_state_->assign(state);
  if (mpm_) {
    mpm_->saveParticles(saved_particles_);
    saved_particle_count_ = mpm_->particles().count;
  }
}

template <int Dim>
void MpmIceStep<Dim>::restoreState(CellState<Dim>& state)
{
  if (!saved_state_) throw std::logic_error("MpmIceStep::restoreState without saveState");
  state.assign(*saved_state_);
  if (mpm_) mpm_->restoreParticles(saved_particles_, saved_particle_count_);
  // The undone step's pressure matrices may have refreshed a reused preconditioner: build anew.
  if (ice_) ice_->restartPreconditionerSchedule();
}

template <int Dim>
void MpmIceStep<Dim>::checkFinite(const CellState<Dim>& state, bool with_pressure) const
{
  // The lowest (global cell id, field, column) with a value that is not finite, as one key.
  constexpr long long kKeysPerCell = 256;  // 6 fields x at most 32 columns (8 materials x 3 components)
  const auto ijk = layout_->cellIndex();
  const long long nx = layout_->grid().cells()[0], ny = layout_->grid().cells()[1];
  const auto fields = state.fields();
  long long first = LLONG_MAX;
  for (std::size_t f = 0; f < fields.size(); ++f) {
    if (!with_pressure && fields[f] == &state.pressure) continue;
    const auto v = fields[f]->view();
    const int columns = fields[f]->columns();
    const long long field_key = 32 * static_cast<long long>(f);
    long long found = LLONG_MAX;
    Kokkos::parallel_reduce(
        "mpmice::checkFinite", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c, long long& lowest) {
          for (int k = 0; k < columns; ++k)
            if (!Kokkos::Experimental::isfinite(v(c, k))) {
              const long long gid = ijk(c, 0) + nx * (ijk(c, 1) + (Dim == 3 ? ny * ijk(c, 2) : 0));
              const long long key = gid * kKeysPerCell + field_key + k;
              if (key < lowest) lowest = key;
              return;
            }
        },
        Kokkos::Min<long long>(found));
    first = std::min(first, found);
  }
  long long global_first = LLONG_MAX;
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_MIN, first, Teuchos::outArg(global_first));
  if (global_first != LLONG_MAX) {
    const long long gid = global_first / kKeysPerCell;
    const int f = int(global_first % kKeysPerCell) / 32, column = int(global_first % 32);
    std::ostringstream message;
    message << "coupled step: " << layout_->grid().cellName(gid) << ": ";
    const std::string& field = fields[f]->name();
    if (fields[f] == &state.pressure) {
      message << "the pressure";
    } else if (fields[f] == &state.velocity) {
      message << "the velocity (" << "xyz"[column % Dim] << ") of " << scene_.materials[column / Dim].name;
    } else {
      message << "the " << field << " of " << scene_.materials[column].name;
    }
    message << " is not finite";
    throw StepFailure(message.str());
  }
  if (mpm_) {
    const std::string particle = mpm_->nonFiniteParticle();
    if (!particle.empty()) throw StepFailure(particle);
  }
}

template <int Dim>
Kokkos::Array<int, ice::kMaxMaterials> MpmIceStep<Dim>::solidSceneIndices() const
{
  Kokkos::Array<int, ice::kMaxMaterials> scene_index{};
  for (std::size_t a = 0; a < mpm_->materials().size(); ++a) scene_index[a] = mpm_->materials()[a].scene_index;
  return scene_index;
}

template <int Dim>
void MpmIceStep<Dim>::cellsFromParticles(CellState<Dim>& state, double dt)
{
  mpm_->particlesToCells(*cell_sums_, dt, substeps_ > 1);
  const int nm = int(mpm_->materials().size());
  const auto scene_index = solidSceneIndices();
  const double volume = layout_->grid().cellVolume();
  const auto sums = cell_sums_->view();
  auto rho = state.density.view();
  auto theta = state.volume_fraction.view();
  auto u = state.velocity.view();
  auto solid_u = solid_velocity_->view();
  auto change = ice_->solidVolumeChange().view();
  typename Field<Dim>::View face_share[3];
  typename Field<Dim>::View face_cover[3];
  for (int d = 0; d < Dim; ++d) {
    face_share[d] = ice_->solidFaceShares().direction(d).view();
    face_cover[d] = ice_->solidFaceCovers().direction(d).view();
  }
  // The cells where a solid is or reaches, marked as their columns are set (IceSolver::solidCellsToMark).
  // A cell unmarked since the last call holds zeros in the solids' face shares, covers and velocities
  // (only this function writes them); if no particle reached it now either (touchColumn), it is left
  // so and only the state's solid columns are set (to zero). Most cells of a slide are such: the pass
  // over all ~27 columns of the sums and ~20 of face fields was most of this phase's time.
  auto marked = ice_->solidCellsToMark();
  const int touch = mpm::MpmSolver<Dim>::touchColumn(nm);
  // A cell that only the particles at rest reach (a bed's) has the same row of sums at every step
  // (MpmSolver::stationaryCellSums): where it had at the last call too, its face shares and covers
  // are those it holds, and only the state's solid columns, which the fluids' phases change, are
  // set again. On the seed scene they are most of the cells that particles reach (its bed).
  const auto stationary = mpm_->stationaryCellSums();
  const bool any_stationary = stationary.extent(0) > 0;
  auto rows = stationary_rows_;
  // The state's columns of every solid from its sums; returns whether a solid is in the cell. The
  // particles' domains of two solids can overlap in a cell where their particles do not (each fills
  // its own GIMP box): the solids then share the cell in proportion.
  const auto setStateColumns = KOKKOS_LAMBDA(const LocalOrdinal c)->bool
  {
    double solid_volume = 0;
    for (int a = 0; a < nm; ++a) solid_volume += sums(c, nm + a);
    const double scale = solid_volume > volume ? volume / solid_volume : 1.0;
    bool solid = false;  // (a NaN is not zero: the phases' general path reports it)
    for (int a = 0; a < nm; ++a) {
      const int m = scene_index[a];
      change(c, m) = (sums(c, mpm::MpmSolver<Dim>::predictedVolumeColumn(nm, a)) - sums(c, nm + a)) / volume;
      const double mass = sums(c, a);
      rho(c, m) = mass / volume;
      theta(c, m) = scale * sums(c, nm + a) / volume;
      solid = solid || rho(c, m) != 0.0 || theta(c, m) != 0.0;
      for (int d = 0; d < Dim; ++d) {
        const double velocity = mass > 0 ? sums(c, 2 * nm + a * Dim + d) / mass : 0.0;
        u(c, m * Dim + d) = velocity;
        solid_u(c, a * Dim + d) = velocity;
      }
    }
    return solid;
  };
  // The sums are complete on the ghosts as well, so every local cell is set without a halo exchange.
  Kokkos::parallel_for(
      "mpmice::cellsFromParticles", Kokkos::RangePolicy<ExecutionSpace>(0, state.density.overlapCount()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        const bool at_rest_alone =
            any_stationary && stationary(c, touch) > 0.0 && sums(c, touch) == stationary(c, touch);
        if (at_rest_alone && (rows(c) & 1)) {
          setStateColumns(c);
          marked(c) = (rows(c) >> 1) & 1;
          return;
        }
        if (!marked(c) && sums(c, touch) == 0.0) {
          // What the full path below sets here: the exchange gives a massless material the
          // mixture's velocity, so the state's columns are written again.
          for (int a = 0; a < nm; ++a) {
            const int m = scene_index[a];
            change(c, m) = 0.0;
            rho(c, m) = 0.0;
            theta(c, m) = 0.0;
            for (int d = 0; d < Dim; ++d) u(c, m * Dim + d) = 0.0;
          }
          return;
        }
        bool solid = setStateColumns(c);
        for (int a = 0; a < nm; ++a) {
          const int m = scene_index[a];
          for (int d = 0; d < Dim; ++d)
            for (int side = 0; side < 2; ++side) {
              const double share = sums(c, mpm::MpmSolver<Dim>::faceColumn(nm, a, d, side));
              const double cover = sums(c, mpm::MpmSolver<Dim>::roomColumn(nm, a, d, side));
              face_share[d](c, 2 * m + side) = share;
              face_cover[d](c, 2 * m + side) = cover;
              solid = solid || share != 0.0 || cover != 0.0;
            }
        }
        marked(c) = solid ? 1 : 0;
        rows(c) = static_cast<unsigned char>((at_rest_alone ? 1 : 0) | (solid ? 2 : 0));
      });
}

template <int Dim>
void MpmIceStep<Dim>::predictSolidVolumes(const CellState<Dim>& state, double dt)
{
  trial_state_->assign(state);
  IceStepReport ignored;  // the step's own exchange reports its failures
  ice_->momentumSourcePhase(*trial_state_, dt);
  ice_->exchangePhase(*trial_state_, dt, ignored);
  velocityChange(*trial_state_);
  mpm_->predictCellVolumes(*cell_change_, dt, *predicted_volume_);
  const int nm = int(mpm_->materials().size());
  const auto scene_index = solidSceneIndices();
  const double volume = layout_->grid().cellVolume();
  const auto sums = cell_sums_->view();
  const auto predicted = predicted_volume_->view();
  auto change = ice_->solidVolumeChange().view();
  Kokkos::parallel_for(
      "mpmice::predictSolidVolumes", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        for (int a = 0; a < nm; ++a) change(c, scene_index[a]) = (predicted(c, a) - sums(c, nm + a)) / volume;
      });
}

template <int Dim>
void MpmIceStep<Dim>::velocityChange(const CellState<Dim>& state)
{
  const int nm = int(mpm_->materials().size());
  const auto scene_index = solidSceneIndices();
  const auto u = state.velocity.view();
  const auto solid_u = solid_velocity_->view();
  auto change = cell_change_->view();
  Kokkos::parallel_for(
      "mpmice::velocityChange", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        for (int a = 0; a < nm; ++a)
          for (int d = 0; d < Dim; ++d)
            change(c, 2 * nm + a * Dim + d) = u(c, scene_index[a] * Dim + d) - solid_u(c, a * Dim + d);
      });
  cell_change_->exchangeHalo();  // particles in owned cells reach into ghost cells
}

template <int Dim>
TimeStepLimit MpmIceStep<Dim>::stableTimeStep(const CellState<Dim>& state, double previous_dt) const
{
  TimeStepLimit limit{scene_.time.dt_max, "dt_max"};
  if (ice_) limit = ice_->stableTimeStep(state, previous_dt);
  if (mpm_) {
    // With particle steps inside the fluids' step, the step may be `substeps` particle steps long.
    const mpm::MpmTimeStep particles = mpm_->stableTimeStep();
    if (substeps_ * particles.dt < limit.dt)
      limit = {substeps_ * particles.dt,
               (substeps_ > 1 ? std::to_string(substeps_) + " x " : std::string()) + "wave_speed(" + particles.material + ")"};
  }
  return limit;
}

template class MpmIceStep<2>;
template class MpmIceStep<3>;

}  // namespace cfdmpm
