#pragma once
// One ICE time step for any number of fluid materials sharing a cell (Kashiwa's multi-material
// cell-centred ICE, in the order of Uintah's MPMICE step; design step numbers in brackets):
//
//   [3]  equilibration pressure per cell: Σθ = 1 over all materials' equations of state
//   [4]  face velocities (density-weighted average, pressure gradient, gravity), face exchange
//   [5]  implicit pressure correction δp (Belos CG + MueLu) with outer iterations; faces corrected
//   [6]  face pressure; momentum sources (pressure force by volume fraction, viscosity, gravity)
//   [8]  Lagrangian values; implicit cell-centred momentum exchange; energy (unless isothermal)
//   [10] conservative second-order advection
//   [11] next Δt from convective CFL, viscosity and conduction
//
// The state is the shared CellState, so solid (MPM) materials can join the same equilibration,
// pressure and exchange later. Isothermal by default (the scene key `ice.isothermal`).
#include "ice/advection.hpp"
#include "ice/eos.hpp"
#include "ice/face_field.hpp"
#include "ice/pressure_solver.hpp"
#include "input/scene.hpp"
#include "mpmice/cell_state.hpp"

#include <Teuchos_Time.hpp>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace cfdmpm {

/// Settings of the ICE step, from the scene's `ice` section (doc/input.md).
struct IceSettings {
  // The keys of `cfdmpm.ice`; their defaults and allowed values are in input/valid_parameters.cpp.
  bool enabled = false;                  // false: fluids are an inert background (dry scenes)
  bool isothermal = false;               // true: temperatures keep their values (no energy equation)
  double heat_exchange_coefficient = 0;  // H between every pair of materials (W/(m^3 K))
  std::string pressure;                  // "implicit" or "explicit" (for comparison)
  double exchange_coefficient = 0;       // momentum exchange K between every pair (kg/(m^3 s))
  int max_outer_iterations = 0;
  double outer_tolerance = 0;            // on max |rhs| / V_cell of the pressure equation (dimensionless)
  double solver_tolerance = 0;           // relative residual of each linear solve (when given)
  bool solver_tolerance_given = false;   // false: each solve goes as far as the outer test needs
  double dt_growth = 0;                  // largest ratio of successive time steps
  Teuchos::ParameterList linear_solver;  // passed to PressureSolver

  static IceSettings fromScene(const Scene& scene);
};

/// What a step did, for the diagnostics time series.
struct IceStepReport {
  int outer_iterations = 0;
  int linear_iterations = 0;      // summed over the outer iterations
  double outer_residual = 0;      // max |rhs| / V at the end (a fraction of the cell volume)
  bool converged = true;
  int equilibration_failures = 0;
  double max_outflux_fraction = 0;
};

/// The time-step limit and what set it.
struct TimeStepLimit {
  double dt = 0;
  std::string limiter;  // e.g. "convection(water)", "viscosity(air)", "dt_max", "growth"
};

template <int Dim>
class IceSolver {
 public:
  IceSolver(const Scene& scene, std::shared_ptr<const Layout<Dim>> layout);
  ~IceSolver();

  /// Advances the state by dt. Throws std::runtime_error (on every rank) if the step fails in a
  /// way a smaller Δt cannot fix, naming the cell and material.
  IceStepReport step(CellState<Dim>& state, double dt);

  /// The largest stable Δt for the state (convective CFL and viscous limits), at most
  /// growth × previous_dt and within [dt_min, dt_max].
  TimeStepLimit stableTimeStep(const CellState<Dim>& state, double previous_dt) const;

  /// Brings the state's volume fractions, specific volumes and pressure to equilibrium (step [3]);
  /// returns the number of cells that did not converge.
  int equilibrate(CellState<Dim>& state);

  const IceSettings& settings() const { return settings_; }

  /// The phases timed by Teuchos timers named "ice: <phase>" ("step" is the whole step).
  static constexpr const char* kPhases[] = {"step", "equilibration", "face velocities", "pressure",
                                            "momentum and exchange", "advection"};
  /// Wall seconds spent in a phase on this rank since the program started.
  double phaseSeconds(const std::string& phase) const { return timers_.at(phase)->totalElapsedTime(); }

 private:
  void faceVelocities(const CellState<Dim>& state, double dt);
  double pressureRightHandSide(CellState<Dim>& state, double dt, bool after_solve);
  void momentumAndExchange(CellState<Dim>& state, double dt);
  void energy(CellState<Dim>& state, const Field<Dim>& old_specific_volume, double dt);

  Scene scene_;
  IceSettings settings_;
  std::shared_ptr<const Layout<Dim>> layout_;
  int materials_;
  ice::MaterialArray<ice::Eos> eos_;
  ice::MaterialArray<double> viscosity_;
  ice::MaterialArray<double> specific_heat_;
  ice::MaterialArray<double> conductivity_;
  double wall_temperature_[6];  // K; < 0: zero normal gradient
  std::vector<std::string> names_;
  double gravity_[3];
  int wall_no_slip_[6];

  Field<Dim> compressibility_;      // κ_m (1/Pa)
  Field<Dim> mixture_compressibility_;  // Σθκ (1/Pa)
  Field<Dim> equilibrium_pressure_;
  Field<Dim> delta_p_, sum_delta_p_, rhs_;
  FaceField<Dim> face_velocity_;        // per material
  FaceField<Dim> corrected_face_velocity_;  // work array of the pressure correction
  FaceField<Dim> face_specific_volume_; // per material, after the face exchange
  FaceField<Dim> face_beta_;            // Σ θ_f v_f
  Field<Dim> new_velocity_;             // work array of the momentum update
  Field<Dim> old_specific_volume_;      // v before the Lagrangian update (for the p dv work)
  std::unique_ptr<PressureSolver<Dim>> pressure_solver_;
  std::unique_ptr<Advector<Dim>> advector_;
  std::map<std::string, Teuchos::RCP<Teuchos::Time>> timers_;
};

extern template class IceSolver<2>;
extern template class IceSolver<3>;

}  // namespace cfdmpm
