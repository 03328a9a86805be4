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
// The state is the shared CellState of all materials. Solid (MPM) materials take part in the
// equilibration (an equation of state from their bulk modulus), the face velocities and face
// exchange, the pressure equation and the cell-centred exchange; they are not advected and get no
// gravity or viscosity here (their cell velocity comes from the MPM grid with those forces already
// in it; mpmice/mpmice_step.hpp). Isothermal by default (the scene key `ice.isothermal`).
#include "ice/advection.hpp"
#include "ice/eos.hpp"
#include "ice/face_field.hpp"
#include "ice/pressure_solver.hpp"
#include "input/scene.hpp"
#include "fields/cell_state.hpp"

#include <Teuchos_Time.hpp>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace cfdmpm {

/// Settings of the ICE step, from the scene's `ice` section (doc/input.md).
struct IceSettings {
  // The keys of `cfdmpm.ice`; their defaults and allowed values are in input/valid_parameters.cpp.
  bool enabled = false;                  // false: fluids are an inert background (dry scenes)
  bool isothermal = false;               // true: temperatures keep their values (no energy equation)
  double heat_exchange_coefficient = 0;  // H between every pair of materials (W/(m^3 K))
  std::string pressure;                  // "implicit" or "explicit" (for comparison)
  double exchange_coefficient = 0;       // momentum exchange K between every pair of fluids (kg/(m^3 s))
  double solid_exchange_coefficient = 0; // ... between a solid and a fluid
  int max_outer_iterations = 0;
  double outer_tolerance = 0;            // on the pressure equation's residual, a volume share (IceSolver::pressureRightHandSide)
  double solver_tolerance = 0;           // relative residual of each linear solve (when given)
  bool solver_tolerance_given = false;   // false: each solve goes as far as the outer test needs
  double dt_growth = 0;                  // largest ratio of successive time steps
  double odd_even_filter = 0;            // share of the fluids' odd-even mode removed per step
  Teuchos::ParameterList linear_solver;  // passed to PressureSolver

  static IceSettings fromScene(const Scene& scene);
};

/// What a step did, for the diagnostics time series.
struct IceStepReport {
  int outer_iterations = 0;
  int linear_iterations = 0;      // summed over the outer iterations
  double outer_residual = 0;      // max |rhs| / V at the end (a fraction of the cell volume)
  bool converged = true;          // the outer iteration reached outer_tolerance
  // With outer_residual not finite: global id of the lowest cell whose pressure equation's
  // right-hand side is not finite, or -1.
  long long first_nonfinite_pressure_cell = -1;
  int equilibration_failures = 0; // cells whose equilibration pressure did not converge
  long long first_failed_equilibration = -1;  // global id of the lowest of them, or -1
  // Largest |p_eq − p| over the cells (Pa): how far the equilibration moved the pressure that the
  // previous step ended with. The previous pressure equation made room for the volumes it foresaw;
  // a jump is a volume that arrived unforeseen (by advection or by the particles) divided by the
  // cell's compressibility Σθκ.
  double equilibration_jump = 0;
  // With solids: the fluids' uniform pressure change since the initial state that the solids'
  // reference pressure follows this step (Pa; IceSolver::updateReferenceShift).
  double reference_shift = 0;
  int exchange_failures = 0;      // cells or faces whose exchange gave a value that is not finite
  long long first_failed_cell = -1;  // global id of the lowest such cell (either kind), or -1
  double max_outflux_fraction = 0;
};

/// What the ICE step needs to know of each material: fluid (Eulerian, advected, gravity and
/// viscosity here) or solid (Lagrangian: MPM carries it), and whether a solid is rigid (moves at a
/// prescribed velocity whatever the forces: infinite inertia in the exchange).
struct MaterialRoles {
  ice::MaterialArray<int> lagrangian{};
  ice::MaterialArray<int> rigid{};
  ice::MaterialArray<int> reference_inside{};  // a solid that feels the reference pressure where it fills a cell
  bool any_solid = false;

  /// A solid, rigid or not (the particles' material); else a fluid.
  KOKKOS_INLINE_FUNCTION bool solid(int m) const { return lagrangian[m] || rigid[m]; }
  /// A solid that is not rigid: it deforms and answers the pressure.
  KOKKOS_INLINE_FUNCTION bool deformable(int m) const { return lagrangian[m] && !rigid[m]; }
};

/// The time-step limit and what set it.
struct TimeStepLimit {
  TimeStepLimit(double dt_ = 0, std::string limiter_ = {}, std::string where_ = {})
      : dt(dt_), limiter(std::move(limiter_)), where(std::move(where_))
  {
  }
  double dt;
  std::string limiter;  // e.g. "convection(water)", "viscosity(air)", "dt_max", "growth"
  std::string where;    // the cell that sets a fluid's limit, when that limit is below time.dt_min
};

/// A solid (MPM) material as the ICE phases see it (the coupled step fills these from the MPM
/// materials, so that ice/ needs nothing of mpm/).
struct SolidProperties {
  int material = 0;           // index in Scene::materials
  double bulk_modulus = 0.0;  // K of its equation of state (Pa)
  double density = 0.0;       // at rest (kg/m^3)
  bool rigid = false;
  bool reference_pressure_inside = false;  // `interior_pressure: reference`
};

template <int Dim>
class IceSolver {
 public:
  /// `solids` describes every `kind: solid` material of the scene; without it a scene with solids
  /// is refused (the fluid step alone runs fluids only).
  IceSolver(const Scene& scene, std::shared_ptr<const Layout<Dim>> layout,
            const std::vector<SolidProperties>& solids = {});
  ~IceSolver();

  /// Advances a state of fluids only by dt: the phases below in order. Throws std::runtime_error
  /// (on every rank) if the step fails in a way a smaller Δt cannot fix, naming the cell and
  /// material.
  IceStepReport step(CellState<Dim>& state, double dt);

  // --- the phases of the step, in order; the coupled step (mpmice/) calls them between its
  //     particle phases. Each is collective and leaves the ghosts it promises refreshed.
  /// [3] Equilibration pressure (see equilibrate below) and the pressure the correction starts from.
  void equilibrationPhase(CellState<Dim>& state, IceStepReport& report);
  /// [4] Face velocities and the implicit face exchange (needs the state's velocity and density).
  void faceVelocityPhase(CellState<Dim>& state, double dt);
  /// [5] Pressure correction: outer iterations of the implicit pressure equation (or one explicit
  /// update); faces corrected. Throws if a linear solve fails.
  void pressurePhase(CellState<Dim>& state, double dt, IceStepReport& report);
  /// [6] Momentum sources: face pressure, the pressure force on every material (θ V ∇p_f), and on
  /// fluids viscosity and gravity; gives the Lagrangian velocities, which exchangePhase takes.
  void momentumSourcePhase(CellState<Dim>& state, double dt);
  /// [8] Lagrangian specific volume, implicit cell-centred momentum exchange between all
  /// materials, and energy (unless isothermal); the exchanged velocities become the state's.
  void exchangePhase(CellState<Dim>& state, double dt, IceStepReport& report);
  void filterOddEven(const CellState<Dim>& state);
  /// [5] The pressure matrix's face coefficient with solids for the given outer iteration (from 1):
  /// the derivative of the fluxes that pressureRightHandSide takes at the current face velocities
  /// (see the definition).
  void carriedFaceBeta(const CellState<Dim>& state, int outer_iteration);
  /// [10] Advection of the fluids (solids are Lagrangian) and the cell closure θ = ρ v.
  void advectionPhase(CellState<Dim>& state, double dt, IceStepReport& report);

  const MaterialRoles& roles() const { return roles_; }

  /// Per local cell (owned and ghost): 1 where rigid bodies fill the cell (their volume fraction
  /// from the particles at least 1 − kClosedGap, no other solid in it), set at the start of each
  /// step's equilibration phase. Such a cell is a wall for the fluids: every face it has is closed
  /// to them, and the fluid phases leave it as it is (its traces of fluid, its pressure) instead of
  /// computing what would change nothing there; a third of the seed scene's cells lie inside its bed.
  using CellMask = typename PressureSolver<Dim>::CellMask;  // the mask type excludeCells() takes
  const CellMask& closedCells() const { return closed_; }
  /// The cells with 1 in closedCells over all ranks, at the last equilibration phase.
  long long closedCellCount() const { return closed_count_; }
  /// Fills closedCells from the state's volume fractions (owned and ghost cells; the rigid bodies'
  /// from the particles). The equilibration phase calls it at every step; the coupled step also
  /// after the initial state's equilibration, which takes every cell, so that each has a pressure
  /// and compressibility before it is closed. Collective.
  void markClosedCells(const CellState<Dim>& state);
  /// The closed cells of every patch of the grid, summed over the ranks (collective): the work of
  /// a patch for its decomposition (decomposition.hpp, patchWork).
  std::vector<long long> closedCellsPerPatch() const;
  static constexpr double kClosedGap = 1e-9;
  /// The cells that have no row in the pressure matrix (PressureSolver::excludeCells), a subset of
  /// the closed cells: see updatePressureRows().
  const CellMask& cellsWithoutPressureRow() const { return without_row_; }
  /// Rows of the pressure matrix over all ranks.
  long long pressureRows() const { return pressure_solver_->rows(); }
  /// The pressure matrix is built again with the closed cells whose face neighbours are all closed
  /// (or walls) left out once this share of the grid's cells are such cells and still have a row.
  static constexpr double kPressureRowsGain = 0.02;
  /// The pressure about which the solids' equation of state is taken in each cell (the pore pressure
  /// of still fluid there; default: initial_state.pressure everywhere). The coupled step sets it to
  /// the initial state's pressure, the hydrostatic pressure of the fluids that the solids displace;
  /// each step adds the fluids' uniform change since then (updateReferenceShift).
  void setSolidReferencePressure(const Field<Dim>& pressure);
  /// The solids' reference pressure per cell (Pa), set once at the start of a run; a checkpoint
  /// keeps it.
  const Field<Dim>& solidReferencePressure() const { return solid_reference_pressure_; }

  /// The next pressure solve builds a fresh preconditioner (MueLu hierarchy). A checkpoint calls
  /// it: the restarted run has no hierarchy to reuse, so the run that goes on builds one too, and
  /// both continue from the same schedule.
  void restartPreconditionerSchedule();

  /// Each solid's share of every cell face on its two sides (columns 2 m: the layer just below the
  /// lower face of a cell, 2 m + 1: just above it; owned and ghost cells), which the coupled step sets
  /// from the particles before the face velocities. A solid's volume crosses a face with the share
  /// upstream of it (not with the upstream cell's volume fraction: a front inside a cell has not
  /// reached its face), couples to the fluids on a face by its shares there, and a rigid solid closes
  /// the larger of its two shares. Fluids use their cells' volume fractions. Zero until set.
  FaceField<Dim>& solidFaceShares() { return solid_face_share_; }
  /// Per solid and side of each face, the face's cover as the solid would cross it from that side
  /// over the step (MpmSolver::roomColumn): where the solid moves across the face the fluids' room
  /// there is at least what it leaves open (fluidFaceFractions). Zero until set, which leaves every
  /// face open to the fluids: a caller that sets solidFaceShares sets these too (the coupled step
  /// does).
  FaceField<Dim>& solidFaceCovers() { return solid_face_cover_; }
  /// Each solid's change of volume fraction in every cell over the step if its particles moved with
  /// the velocity they have before the fluid pressure acts (columns: materials; owned cells), set by
  /// the coupled step. The pressure equation counts a solid's volume flux as this change plus, on
  /// each face, u_f s(u_f) − u_k s(u_k): the volume its face velocity u_f (after pressure and
  /// exchange) carries minus what the particles' own motion u_k carries, s(u) the share upwind of u.
  /// A solid's volume moves as its particles move, which near a contact or along a staircase
  /// surface is not the cell-averaged velocity times a face share.
  Field<Dim>& solidVolumeChange() { return solid_volume_change_; }
  /// The cells (owned and ghost) where a solid is or reaches, for the next equilibrationPhase and
  /// the phases after it in the step: a caller that sets the solids' columns (the coupled step, from
  /// the particles) marks them here as it sets them, with markSolidCells' rule (a solid's mass,
  /// volume fraction, share or cover of one of the cell's lower faces not zero), which spares the
  /// equilibration a pass over every solid column; otherwise the equilibration marks them itself.
  CellMask& solidCellsToMark()
  {
    if (solid_cells_.extent(0) != std::size_t(layout_->overlapCells()))
      solid_cells_ = CellMask("solid cells", layout_->overlapCells());
    solid_cells_given_ = true;
    return solid_cells_;
  }
  /// Kinematic solids (the staggered coupling, mpm.coupling: staggered): the deformable solids'
  /// motion over the step is fixed before the pressure (solidVolumeChange holds all of it), so on
  /// faces and in the pressure equation they are treated as a moving rigid body is: each closes
  /// its share of a face, the fluids flow through the rest, and it takes no pressure correction.
  /// The momentum sources and the cell-centred exchange still act on them, and their velocity
  /// change reaches the particles' velocities (their positions the next step). Off by default: the
  /// monolithic coupling, where the solids' response to the pressure is in the pressure equation.
  void setKinematicSolids(bool on) { kinematic_solids_ = on; }
  /// The solids' volume from their particles (mpm.solid_volume: particles): before the first
  /// pressure residual and after every correction, `predict(state, dt)` sets solidVolumeChange to
  /// each solid's change of volume fraction over the step as its particles would make it with the
  /// state's present pressure (its force, the exchange, the transfer to the particles), and the
  /// pressure equation's residual counts that change alone (no face terms for the solids). Its
  /// matrix leaves the deformable solids' faces out (their particles follow a pressure difference
  /// across a face by ~10 % of what the face form says). Unset: the face form in both.
  void setSolidVolumePredictor(std::function<void(CellState<Dim>&, double)> predict)
  {
    solid_volume_predictor_ = std::move(predict);
  }

  /// The largest stable Δt for the state (convective CFL and viscous limits), at most
  /// growth × previous_dt and dt_max. Below time.dt_min it names the cell that sets it (`where`)
  /// and the run stops there.
  TimeStepLimit stableTimeStep(const CellState<Dim>& state, double previous_dt) const;

  /// Brings the state's volume fractions, specific volumes and pressure to equilibrium (step [3]);
  /// returns the number of cells that did not converge.
  int equilibrate(CellState<Dim>& state);
  /// Global id of the lowest cell whose last equilibrate() did not converge, or -1.
  long long firstFailedEquilibration() const { return first_failed_equilibration_; }

  const IceSettings& settings() const { return settings_; }

  /// The phases timed by Teuchos timers named "ice: <phase>" ("step" is the whole step).
  static constexpr const char* kPhases[] = {"step",     "equilibration", "face velocities", "pressure",
                                            "momentum", "exchange",      "advection"};
  /// Wall seconds spent in a phase on this rank since the program started.
  double phaseSeconds(const std::string& phase) const { return timers_.at(phase)->totalElapsedTime(); }

 private:
  /// reference_shift_ from the state's pressure: the volume mean of p − p_ref over the cells that
  /// hold fluids alone (over all ranks).
  void updateReferenceShift(const CellState<Dim>& state);
  void faceVelocities(const CellState<Dim>& state, double dt);
  double pressureRightHandSide(CellState<Dim>& state, double dt, bool after_solve);
  /// "cell (i, j): ..." for the cell whose weighted volume residual (the outer test's) is the
  /// largest on any rank, with its materials' volume fractions; the same text on every rank.
  std::string largestResidualCell(const CellState<Dim>& state) const;
  /// "cell (i, j), where <material> fills ..." for the cell where material m sets stableTimeStep's
  /// limit of `kind` (0 convection, 1 viscosity, 2 conduction); the same text on every rank.
  std::string limitingCell(const CellState<Dim>& state, int m, int kind, double previous_dt) const;
  void applyPressureCorrection(CellState<Dim>& state, double dt);
  // Σ_m θ_m κ_m s'(κ_m Σδp) into mixture_compressibility_ where that is more than
  // kCompressibilityChange below it somewhere; returns whether it wrote (then reassemble).
  bool followCompressibility(const CellState<Dim>& state);
  void secantSlopeWhereBoiling(const CellState<Dim>& state);
  void updatePressureRows();
  void fluidFaceFractions(const CellState<Dim>& state, double dt);
  void markSolidCells(const CellState<Dim>& state);
  void markQuietCells();
  void energy(CellState<Dim>& state, const Field<Dim>& old_specific_volume, double dt);

  Scene scene_;
  IceSettings settings_;
  std::shared_ptr<const Layout<Dim>> layout_;
  int materials_;
  MaterialRoles roles_;
  bool kinematic_solids_ = false;
  bool any_rigid_ = false;  // some material is a rigid solid: cells may be closed
  CellMask closed_;         // closedCells()
  CellMask without_row_;    // cellsWithoutPressureRow()
  CellMask solid_cells_;    // markSolidCells(): a solid is or reaches here (owned and ghost cells)
  CellMask quiet_cells_;    // markQuietCells(): no solid reaches the cell or any of its faces (owned and ghost cells)
  bool solid_cells_given_ = false;  // solidCellsToMark() since the last equilibrationPhase
  long long closed_count_ = 0;
  std::function<void(CellState<Dim>&, double)> solid_volume_predictor_;  // setSolidVolumePredictor
  /// The roles of the face phases (face velocities and exchange, the pressure equation): roles_,
  /// with every solid rigid there when the solids are kinematic (setKinematicSolids).
  MaterialRoles faceRoles() const
  {
    MaterialRoles roles = roles_;
    if (kinematic_solids_)
      for (int m = 0; m < ice::kMaxMaterials; ++m) roles.rigid[m] = roles.rigid[m] || roles.lagrangian[m];
    return roles;
  }
  /// The roles as the momentum sources see them: with kinematic solids the pressure equation
  /// holds no response of theirs to the pressure, so the pressure inside a deformable solid is not
  /// the one that moves it, and every one takes the reference there (`interior_pressure:
  /// reference`), as the staggered coupling did before the key existed.
  MaterialRoles momentumRoles() const
  {
    MaterialRoles roles = roles_;
    if (kinematic_solids_)
      for (int m = 0; m < ice::kMaxMaterials; ++m)
        if (roles.deformable(m)) roles.reference_inside[m] = 1;
    return roles;
  }
  ice::MaterialArray<ice::Eos> eos_;
  ice::MaterialArray<double> bulk_modulus_;  // solids: K of their equation of state (Pa)
  // The stiffest fluid's compressibility and density at the initial pressure and temperature (1/Pa,
  // kg/m^3): the outer test weighs each cell's volume residual by how much softer than that the
  // cell is, and by how much lighter (pressureRightHandSide).
  double stiffest_compressibility_ = 0;
  double stiffest_density_ = 0;
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
  Field<Dim> outer_weight_;  // the outer test's weight of each cell's volume residual (pressureRightHandSide)
  FaceField<Dim> face_velocity_;        // per material
  FaceField<Dim> corrected_face_velocity_;  // work array of the pressure correction
  FaceField<Dim> face_specific_volume_; // per material, after the face exchange
  FaceField<Dim> face_beta_;            // Σ θ_f v_f
  FaceField<Dim> solid_face_share_;     // solidFaceShares()
  FaceField<Dim> solid_face_cover_;     // solidFaceCovers()
  long long first_failed_equilibration_ = -1;  // firstFailedEquilibration()
  Field<Dim> solid_volume_change_;      // solidVolumeChange()
  FaceField<Dim> solid_kinematic_velocity_;  // a solid's face velocity before pressure and exchange
  FaceField<Dim> fluid_face_fraction_;  // with solids: a fluid's volume fraction crossing a face that a solid is on (columns 2 m, 2 m + 1: donor below, above; solidOnFace)
  typename Advector<Dim>::CapView fluid_outflow_share_;  // with solids: (donor cell, face) share of the fluids' slabs that leaves
  CellMask fraction_faces_;  // fluidFaceFractions: bit d set where it set the outflow shares of the cell's lower face in direction d (a solid on it)
  Field<Dim> new_velocity_;             // Lagrangian velocities between sources and exchange
  Field<Dim> filter_laplacian_, filter_increment_;  // filterOddEven's work space (1 column when off)
  Field<Dim> old_specific_volume_;      // v before the Lagrangian update (for the p dv work)
  Field<Dim> solid_reference_pressure_; // p_ref of the solids' equation of state per cell (Pa)
  double reference_shift_ = 0;          // the fluids' uniform pressure change added to it (updateReferenceShift)
  Field<Dim> solid_particle_volume_;    // a solid's specific volume as its particles hold it (m^3/kg)
  std::unique_ptr<PressureSolver<Dim>> pressure_solver_;
  std::unique_ptr<Advector<Dim>> advector_;
  std::map<std::string, Teuchos::RCP<Teuchos::Time>> timers_;
};

extern template class IceSolver<2>;
extern template class IceSolver<3>;

}  // namespace cfdmpm
