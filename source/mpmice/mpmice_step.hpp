#pragma once
// One time step of the coupled method (MPMICE, in the order of Uintah's MPMICE step; design.md,
// "One time step"): fluids (ICE) and solids (MPM) on one grid, one pressure, one exchange.
//
//    1. MPM: particles to grid nodes; the solids' stress and gravity, contact, walls: v*
//    2. particles to cells: the solids' mass, volume and velocity v* in every cell
//    3. equilibration pressure of all materials
//    4. face velocities of all materials and the implicit face exchange
//    5. implicit pressure with outer iterations
//    6. momentum sources: pressure force on every material; viscosity and gravity on fluids
//    7. (the pressure needs no separate way to the particles: it reaches the solids as the pressure
//       force of step 6, and their particle stress is the skeleton's, without the fluid pressure)
//    8. implicit cell-centred exchange between all materials
//    9. the solids' velocity change of steps 6 and 8 back to the nodes; grid to particles; stress
//   10. advection of the fluids (solids are Lagrangian)
//   11. the next Δt (stableTimeStep): the smaller of the fluid and the particle limits
//   12. the state is finite: a cell or particle value that is not fails the step
//
// A step that fails throws StepFailure on every rank; saveState before it and restoreState after it
// undo it (the driver then retries it with a smaller Δt).
//
// A scene without solids runs steps 3-6, 8 and 10; a dry scene (ice.enabled false) steps 1 and 9:
// the same step with one material set empty.
#include "fields/cell_state.hpp"
#include "ice/ice_solver.hpp"
#include "mpm/mpm_solver.hpp"

#include <Teuchos_Time.hpp>

#include <map>
#include <memory>
#include <string>

namespace cfdmpm {

/// What a coupled step did (the ICE part is zero when the fluids do not move).
struct CoupledStepReport {
  IceStepReport ice;
  /// Particle steps taken inside the step (mpm.substeps > 1 allows more than one).
  int particle_steps = 1;
};

template <int Dim>
class MpmIceStep {
 public:
  /// Builds the solvers the scene needs (fluids move unless ice.enabled is false; particles when it
  /// has solids) and, when both are present, makes the state's solid columns those of the particles
  /// and lets the fluids fill the rest of each cell. The state holds the initial state on entry.
  MpmIceStep(const Scene& scene, std::shared_ptr<const Layout<Dim>> layout, CellState<Dim>& state);
  ~MpmIceStep();

  /// One step of length dt (collective). Throws std::runtime_error (on every rank) naming what
  /// failed.
  CoupledStepReport step(CellState<Dim>& state, double dt);

  /// Keeps a copy of everything a step changes: the cell state and the particles.
  void saveState(const CellState<Dim>& state);
  /// Puts back the copy of saveState, so that the next step starts as the undone one did. The
  /// pressure solve after it builds a fresh preconditioner (nothing of the undone step is reused).
  void restoreState(CellState<Dim>& state);

  /// [11] The largest stable Δt: the fluid step's limits and the particles' wave speed, the
  /// smallest named in the limiter (e.g. "convection(water)", "wave_speed(sand)").
  TimeStepLimit stableTimeStep(const CellState<Dim>& state, double previous_dt) const;

  bool fluidsMove() const { return bool(ice_); }
  bool hasParticles() const { return bool(mpm_); }
  IceSolver<Dim>* fluids() { return ice_.get(); }
  mpm::MpmSolver<Dim>* particles() { return mpm_.get(); }
  const mpm::MpmSolver<Dim>* particles() const { return mpm_.get(); }
  /// The particles' sums per cell of the last step (MpmSolver::particlesToCells; null without
  /// fluids or particles): the face shares and covers the fluids hold are their columns.
  const Field<Dim>* cellSums() const { return cell_sums_.get(); }

  /// The phases, timed by Teuchos timers named "mpmice: <phase>" ("step" is the whole step).
  static constexpr const char* kPhases[] = {"step",     "1 particles to grid", "2 particles to cells",
                                            "3-6 fluid pressure", "8 exchange", "9 grid to particles",
                                            "10 advection", "12 finite"};
  double phaseSeconds(const std::string& phase) const { return timers_.at(phase)->totalElapsedTime(); }

 private:
  /// The solids' columns of the state (mass density, volume fraction, velocity) from the particles.
  void cellsFromParticles(CellState<Dim>& state, double dt);
  /// Material a of the particle solver is material scene_index[a] of the state.
  Kokkos::Array<int, ice::kMaxMaterials> solidSceneIndices() const;
  /// The solids' cell velocity change since cellsFromParticles, in the particle solver's columns.
  void velocityChange(const CellState<Dim>& state);
  /// The solids' volume change over the step as their particles make it with the state's present
  /// pressure (IceSolver::setSolidVolumePredictor): momentum sources and exchange on a copy of the
  /// state, their velocity change to the particles (MpmSolver::predictCellVolumes).
  void predictSolidVolumes(const CellState<Dim>& state, double dt);
  /// [12] Throws StepFailure naming the first cell (lowest global id) or particle (lowest id), its
  /// material and the quantity, if a value of the state or of a particle is not finite
  /// (with_pressure false: the pressure is not looked at).
  void checkFinite(const CellState<Dim>& state, bool with_pressure = true) const;

  Scene scene_;
  std::shared_ptr<const Layout<Dim>> layout_;
  std::unique_ptr<IceSolver<Dim>> ice_;
  std::unique_ptr<mpm::MpmSolver<Dim>> mpm_;
  std::unique_ptr<Field<Dim>> cell_sums_;       // particlesToCells: mass, volume, momentum per solid
  std::unique_ptr<Field<Dim>> cell_change_;     // velocity change of the solids' cells (same columns)
  std::unique_ptr<Field<Dim>> solid_velocity_;  // the solids' cell velocity from the particles
  /// cellsFromParticles, per local cell: bit 0 where its sums were the particles' at rest alone
  /// (MpmSolver::stationaryCellSums) and it set the face shares and covers from them, bit 1 where
  /// the cell then held a solid.
  Kokkos::View<unsigned char*, MemorySpace> stationary_rows_;
  /// Most particle steps in one step (mpm.substeps with fluids and particles, else 1). Above 1 the
  /// solids' velocity forecast for the fluids comes from each particle's own acceleration of the
  /// last step (MpmSolver::particlesToCells), not from one grid update.
  int substeps_ = 1;
  std::unique_ptr<Field<Dim>> predicted_volume_;  // predictSolidVolumes: each solid's volume per cell
  std::unique_ptr<CellState<Dim>> trial_state_;    // predictSolidVolumes: the state the trial phases change
  std::map<std::string, Teuchos::RCP<Teuchos::Time>> timers_;
  std::unique_ptr<CellState<Dim>> saved_state_;        // saveState's copy
  typename mpm::MpmSolver<Dim>::ParticleSnapshot saved_particles_;
  int saved_particle_count_ = 0;
};

extern template class MpmIceStep<2>;
extern template class MpmIceStep<3>;

}  // namespace cfdmpm
