#pragma once
// The Material Point Method on the scene's grid: the solid materials' particles, their node fields,
// and one explicit step with the stress updated last, in Uintah's order (doc/mpm.md):
//
//     particlesToGrid();        // P2G: mass, momentum, internal and external force, mass gradients
//     integrateGrid(dt);        // v* = (p + dt f) / m; contact between materials; walls
//     gridToParticles(dt);      // G2P: velocity (PIC/FLIP blend), position, L, F, volume;
//                               // MUSL maps the new momenta back to the nodes for L
//     updateStress(dt);         // constitutive update, once per material through SolidModel
//     relocateParticles();      // particles go to the rank that owns their cell (MPI)
//
// Every particle kernel is a Kokkos parallel_for / parallel_reduce over local views; the parallel
// parts are the node sum (Field::sumToOwners, a Tpetra Export with ADD) and the migration. The
// phases are public so that the coupled MPMICE step can call them between its fluid phases.
#include "fields/field.hpp"
#include "mpm/migration.hpp"
#include "mpm/particle_bins.hpp"
#include "mpm/particles.hpp"
#include "mpm/shape_functions.hpp"
#include "mpm/solid_material.hpp"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace cfdmpm::mpm {

enum class ShapeFunction {
  Gimp,   ///< uniform GIMP (Bardenhagen & Kober 2004): no cell-crossing noise; the default
  Linear  ///< linear hat: classic MPM, kept for comparison
};

/// Where the stress update takes its velocity gradient from (doc/mpm.md, section 2).
enum class StressUpdate {
  /// USL: L from the updated grid velocity v*. Loses (1/2) dv^T (M_lumped - M_consistent) dv of
  /// energy per step (doc/mpm.md, section 2).
  Last,
  /// MUSL (Sulsky, Zhou & Schreyer 1995): L from the updated particle momenta mapped back to the
  /// nodes; no systematic energy loss, one more particle pass and node sum (~1.45x the step cost).
  ModifiedLast
};

/// Solver settings; the scene's `mpm` section sets them (optionsFromScene), tests set them directly.
/// doc/mpm.md explains each.
struct MpmOptions {
  ShapeFunction shape_function = ShapeFunction::Gimp;
  /// Share of FLIP in the G2P velocity update: v_p <- f (v_p + dv_grid) + (1 - f) v_grid.
  /// 1 = pure FLIP (no numerical dissipation, can be noisy), 0 = pure PIC (very dissipative).
  double flip_fraction = 0.99;
  /// Velocity the strain rate is taken from: v* (USL) or the re-mapped particle momenta (MUSL).
  StressUpdate stress_update = StressUpdate::Last;
  /// Coulomb friction coefficient mu between particles and the free_slip walls of the domain
  /// (no_slip walls stick).
  double wall_friction = 0.0;
  /// Contact between MPM materials (Bardenhagen et al. 2001, Coulomb friction, free separation).
  /// Off: the materials do not see each other (each has its own node velocities) and pass through
  /// each other.
  bool contact = true;
  double contact_friction = 0.0;  ///< mu between MPM materials
  /// Mass-proportional damping alpha (1/s): the nodal acceleration gets -alpha v. For reaching
  /// static states (e.g. a column under self-weight); 0 for dynamics.
  double velocity_damping = 0.0;
  /// Courant number of the time step; <= 0 takes the scene's time.cfl.
  double cfl = 0.0;
  /// Width of the layers on either side of a cell face in which a solid's share of the face is
  /// measured, in cells (particlesToCells; doc/mpmice.md, "A solid's share of a face").
  double face_layer = 0.125;
  /// Staggered coupling (mpm.coupling: staggered): the particles move with their grid velocity
  /// before the coupled step's velocity change (addCellVelocityChange), which reaches only their
  /// velocities; their motion is then the one the fluids' pressure equation was given.
  bool move_before_coupling = false;
  /// A rigid material at rest (a bed) adds the same to the nodes and the cells at every step: its
  /// particles are summed once and their sums copied in (false: summed at every step like the rest,
  /// for comparison).
  bool stationary_sums_once = true;
};

/// The options the scene's `mpm` section asks for (its values were checked when it was read).
MpmOptions optionsFromScene(const Scene& scene);

/// What the time step is limited by on the whole domain.
struct MpmTimeStep {
  double dt = 0.0;         ///< cfl h_min / max_p (c_p + |v_p|) (s); +infinity with no particles
  double wave_speed = 0.0; ///< c_p of the limiting particle (m/s)
  double speed = 0.0;      ///< |v_p| of the limiting particle (m/s)
  std::string material;    ///< name of the limiting particle's material
};

/// The rank's particles as host arrays for output (HDF5/XDMF), in local order; interleaved
/// per particle where a quantity has components.
struct ParticleOutput {
  int dimension = 2;
  std::size_t count = 0;
  std::vector<double> position;        ///< count x dimension (m)
  std::vector<double> velocity;        ///< count x dimension (m/s)
  std::vector<double> stress;          ///< count x 9, full 3 x 3 Cauchy stress row by row (Pa)
  std::vector<double> plastic_strain;  ///< equivalent plastic strain (-)
  std::vector<double> mass;            ///< kg (kg/m in 2-D)
  std::vector<double> volume;          ///< m^3 (m^2 in 2-D)
  std::vector<int> material;           ///< index in Scene::materials
  std::vector<long long> id;           ///< particle id
};

template <int Dim>
class MpmSolver {
 public:
  /// Seeds the particles of every solid material of the scene in the layout's owned cells.
  /// Collective. The layout needs ghost_width >= 1 (GIMP reaches one cell beyond a particle's own).
  MpmSolver(const Scene& scene, std::shared_ptr<const Layout<Dim>> layout, const MpmOptions& options = {});

  // --- the step --------------------------------------------------------------------------------
  /// Largest stable time step over all ranks (collective).
  MpmTimeStep stableTimeStep() const;
  /// One step of length dt (collective): the five phases below in order.
  void step(double dt);

  void particlesToGrid();
  void integrateGrid(double dt);
  void gridToParticles(double dt);
  /// Stress update; an inverted particle (det F <= 0) is reported by the next relocateParticles.
  void updateStress(double dt);
  /// Particles to the ranks that own their cells; raises (on every rank) the errors found since
  /// the last call: a particle outside the domain, an inverted one, or a P2G that reached beyond
  /// the ghost nodes. Phases report errors here so that the step has no extra collective.
  MigrationCounts relocateParticles();

  // --- transfers of the coupled step (mpmice/): particles <-> cells ------------------------------
  /// Columns of a cell field for particlesToCells / addCellVelocityChange: per MPM material a,
  /// mass (column a), volume (materials + a) and momentum or velocity change (2 materials + a Dim + d),
  /// then the face shares of particlesToCells (faceColumn), the covers over the step (roomColumn)
  /// and the count of particle contributions (touchColumn).
  static int cellColumns(int materials) { return touchColumn(materials) + 1; }
  /// Column of the number of particle contributions particlesToCells added to a cell, every column
  /// alike: where it is 0 every other column is, so a caller can pass over the cells that no
  /// particle reaches reading one column instead of all of them.
  KOKKOS_INLINE_FUNCTION static int touchColumn(int materials) { return materials * (3 + 5 * Dim); }
  /// Column of material a's volume in a cell with every particle moved by Δt ṽ_p (particlesToCells).
  KOKKOS_INLINE_FUNCTION static int predictedVolumeColumn(int materials, int a) { return materials * (2 + 3 * Dim) + a; }
  /// Column of material a's share of the lower face of a cell in direction d, in the layer below the
  /// face (side 0) or above it (side 1).
  KOKKOS_INLINE_FUNCTION static int faceColumn(int materials, int a, int d, int side)
  {
    return materials * (2 + Dim) + 2 * (a * Dim + d) + side;
  }
  /// Column of material a's cover of the lower face of a cell in direction d as it would cross it
  /// from below (side 0) or from above (side 1) over the step: what it leaves the fluids there.
  KOKKOS_INLINE_FUNCTION static int roomColumn(int materials, int a, int d, int side)
  {
    return materials * (3 + 3 * Dim) + 2 * (a * Dim + d) + side;
  }
  /// Each particle's mass m_p, volume V_p and momentum m_p ṽ_p into the cells that its GIMP domain
  /// (the box of half-width l_p about it) overlaps, in proportion to the overlap (the part beyond a
  /// domain face goes to the boundary cell), so that a body aligned with the cells fills them exactly
  /// and the cell values change smoothly as particles cross cell faces. ṽ_p = Σ_i w_ip v*_i, the
  /// grid velocity after integrateGrid (a rigid particle's: its prescribed velocity). And each
  /// material's share of every interior cell face, on each side: its volume in the layer of width
  /// MpmOptions::face_layer just below (above) the face, per volume of the layer. A face inside a
  /// body is covered (1), the face on a body's surface is covered on the body's side only, and a
  /// face that a front has not reached is not covered, however full the cell behind it: what
  /// crosses a face in a step is the share of the layer upstream of it (times u Δt), not the
  /// upstream cell's volume fraction.
  /// Summed across ranks: the owned cells are complete, and so are the ghosts.
  /// With dt > 0 also the volume each material would have in every cell if each particle moved by
  /// Δt ṽ_p (predictedVolumeColumn): how the solids' volumes move in a step before the fluid
  /// pressure acts on them.
  /// With `forecast`, ṽ_p is instead the particle's own forecast v_p + Δt a_p (a_p its own
  /// acceleration of the last coupled step, recordOwnAcceleration; a rigid particle's: its prescribed
  /// velocity): particle steps inside the fluids' step cannot take a forecast from one grid update
  /// Δt long, which would be unstable for the particles' elastic wave.
  /// `sums` holds what the last call left in it, or zeros: with the sums of particles at rest made
  /// once, a row whose count (touchColumn) is theirs is taken to hold their row already.
  void particlesToCells(Field<Dim>& sums, double dt = 0.0, bool forecast = false);
  /// What particlesToCells adds to every local cell for the particles of rigid materials at rest,
  /// made once on this rank (before the sums across ranks), in its columns; empty where those are
  /// summed at every step (MpmOptions::stationary_sums_once off, or no material at rest). A cell
  /// whose contributions (touchColumn) after particlesToCells number as many as here got nothing
  /// else: its row of the sums is this row.
  typename Field<Dim>::ConstView stationaryCellSums() const
  {
    return stationary_cells_.valid ? typename Field<Dim>::ConstView(stationary_cells_.values)
                                   : typename Field<Dim>::ConstView();
  }
  /// Own motion over a coupled step with particle steps inside it: startOwnMotion before the
  /// particle steps marks each particle's velocity plus the velocity change the fluids give it in
  /// the step (Particles::velocity_change); recordOwnAcceleration after them makes
  /// Particles::own_acceleration (v_p - mark) / Δt.
  void startOwnMotion();
  void recordOwnAcceleration(double dt);
  /// Adds cell velocity changes Δu_c (columns 2 materials + a Dim + d; owned and ghost cells) to the
  /// grid velocity v*: a particle takes Δv_p = Σ_c φ_pc Δu_c with the overlap shares of
  /// particlesToCells, its momentum m_p Δv_p goes to the nodes by its weights, v*_i += Δ(mv)_i / m_i;
  /// then contact and the walls again. The momentum given to the nodes is Σ_c m_c Δu_c exactly (m_c
  /// the cell mass of particlesToCells). Rigid particles take no change.
  void addCellVelocityChange(const Field<Dim>& change);
  /// addCellVelocityChange in two parts, for particle steps inside one step of the fluids: each
  /// particle's velocity change Δv_p = Σ_c φ_pc Δu_c from the cells it overlaps now (kept with the
  /// particle, Particles::velocity_change; zero for rigid particles) ...
  void cellVelocityChangeToParticles(const Field<Dim>& change);
  /// ... and `fraction` of it added to the grid velocity of the latest integrateGrid: its momentum
  /// fraction m_p Δv_p goes to the nodes by the weights of the particle's present position,
  /// v*_i += Δ(mv)_i / m_i, then contact and the walls again. Called in each of n particle steps
  /// with fraction 1/n, the particles take Σ_c m_c Δu_c in all, what the fluids gave up, as a force
  /// held over the fluids' step; with fraction 1 right after cellVelocityChangeToParticles it is
  /// addCellVelocityChange.
  void addParticleVelocityChange(double fraction);
  /// Each material's volume in every cell (columns: materials; owned and ghost cells) after a G2P
  /// with the grid velocity v* plus the cell velocity changes `change` (addCellVelocityChange's
  /// columns and rules, walls and contact included), without moving the particles or changing v*
  /// (it leaves the change in Particles::velocity_change, which the step's own
  /// cellVelocityChangeToParticles replaces): the boxes of particlesToCells at
  /// x_p + Δt Σ_i w_ip v_i, with the particles' present volumes.
  void predictCellVolumes(const Field<Dim>& change, double dt, Field<Dim>& volumes);

  // --- undoing a step (the driver retries a failed step with a smaller Δt) ------------------------
  /// The rank's particles, each row a particle's whole state in the order of Particles::pack.
  using ParticleSnapshot = Kokkos::View<double**, Kokkos::LayoutRight, MemorySpace>;
  /// Copies the rank's particles into `snapshot` (resized as needed).
  void saveParticles(ParticleSnapshot& snapshot) const;
  /// Makes the rank's particles those of `snapshot`, in its order, and forgets what the undone step
  /// left behind (its pending errors, its particle bins). Collective only in that every rank must
  /// restore its own snapshot of the same step.
  void restoreParticles(const ParticleSnapshot& snapshot, int count);
  /// The particle with the lowest id, over all ranks, one of whose quantities (position, velocity,
  /// volume, deformation gradient, stress, plastic state) is not finite, described with its id,
  /// material, position and the quantity; empty when every particle is finite. Collective; the
  /// same text on every rank.
  std::string nonFiniteParticle() const;

  /// Moves to a new decomposition of the same grid (dynamic load balancing): new node fields, and
  /// the particles go to their new owners. Collective.
  void repartition(std::shared_ptr<const Layout<Dim>> layout);

  /// Gravity (m/s^2; entries beyond Dim ignored); starts as the scene's domain.gravity.
  void setGravity(const std::array<double, 3>& gravity);
  const std::array<double, 3>& gravity() const { return gravity_; }

  // --- diagnostics (collective) ------------------------------------------------------------------
  long long particleCount() const;
  /// Particles in every patch of the grid (indexed by patch id), over all ranks: the particles'
  /// share of the work when the decomposition is redone. Those of rigid materials at rest (a bed)
  /// count only without MpmOptions::stationary_sums_once: the step passes over them otherwise.
  std::vector<long long> particlesPerPatch() const;
  std::vector<double> materialMasses() const;   ///< per MPM material (kg, or kg/m in 2-D)
  double kineticEnergy() const;                 ///< sum of m |v|^2 / 2 (J, or J/m in 2-D)
  std::array<double, 3> momentum() const;       ///< sum of m v (entries beyond Dim zero)

  // --- access ------------------------------------------------------------------------------------
  const std::vector<SolidMaterial>& materials() const { return materials_; }
  const MpmOptions& options() const { return options_; }
  /// The particles, to read or to set their state between steps; a caller that adds, removes or
  /// reorders particles, or changes those of a rigid material at rest, calls particlesChanged().
  Particles<Dim>& particles() { return particles_; }
  const Particles<Dim>& particles() const { return particles_; }
  /// Forgets what the solver keeps of the particles between steps (the list of those a step
  /// changes, the sums of the rigid bodies at rest, the particle bins); the next relocateParticles
  /// looks at every particle.
  void particlesChanged();
  const Layout<Dim>& layout() const { return *layout_; }
  /// Host copies of the rank's particles for output.
  ParticleOutput output() const;

  /// Node fields of the last P2G / grid update: mass per material, and the velocities before (v)
  /// and after (v*) the grid update, material m component d in column m * Dim + d.
  const Field<Dim>& nodeSums() const { return *node_sums_; }
  const Field<Dim>& nodeVelocity() const { return *node_velocity_; }
  const Field<Dim>& nodeVelocityStar() const { return *node_velocity_star_; }

 private:
  // The sums of the particles of rigid materials at rest (before the sum across ranks): into the
  // nodes (particlesToGrid) and into the cells (particlesToCells). Empty until first needed, and
  // again after anything that may change them (a new division, restored particles, gravity).
  struct StationarySums {
    typename Field<Dim>::View values;
    bool valid = false;
  };

  /// f(UniformGimp()) or f(LinearHat()), as the options choose: each phase's kernel is a template
  /// on the shape function.
  template <class F>
  void withShapeFunction(F&& f) const
  {
    if (options_.shape_function == ShapeFunction::Gimp)
      f(UniformGimp());
    else
      f(LinearHat());
  }
  template <class Kernel>
  void particlesToGridWith();
  template <class Kernel>
  void gridToParticlesWith(double dt);
  template <class Kernel>
  void particlesToCellsWith(Field<Dim>& sums, double dt, bool forecast);
  // Writes v* + the change into `target` (node velocities); `commit`: the step's own change (the
  // staggered coupling's copy of v* and MUSL's constraint record follow it), not a prediction.
  template <class Kernel>
  void addCellVelocityChangeWith(const Field<Dim>& change, Field<Dim>& target, bool commit);
  template <class Kernel>
  void particleVelocityChangeToNodesWith(double fraction);
  /// v_i += Δ(mv)_i / m_i (node_momentum_change_) into target, then contact and the walls.
  void applyNodeMomentumChange(Field<Dim>& target, bool commit);
  template <class Kernel>
  void predictCellVolumesWith(const Field<Dim>& change, double dt, Field<Dim>& volumes);
  /// Which particles a loop visits: every one, or those a step can change: all but the particles
  /// of rigid materials at rest, whose position, velocity, stress and velocity change stay as
  /// seeded (a slide's bed holds 91 % of its particles at 5 mm).
  enum class ParticleSet { All, Changing };
  /// f(p) for every particle of the set, in ascending index order (a parallel_for).
  template <class F>
  void forEachParticle(const char* label, ParticleSet set, const F& f) const;
  /// The reduction of f(p, value) over the particles of the set (a parallel_reduce).
  template <class F, class Reducer>
  void reduceOverParticles(const char* label, ParticleSet set, const F& f, const Reducer& reducer) const;
  /// f(p) for every particle of the set, for kernels that add into node arrays: in index order on
  /// one thread; on more, tile colour by tile colour (bins_, rebuilt when stale), so no two threads
  /// add into the same node.
  template <class F>
  void forEachParticleScattering(const char* label, const BoxLookup& lookup, ParticleSet set, const F& f);
  /// The indices of the set's particles, ascending, and their number; the set Changing is listed
  /// in changing_ (rebuilt when stale) when some material is at rest, else it is every particle.
  bool everyParticleChanges() const { return !any_stationary_; }
  void refreshChangingList() const;
  /// The scatter `f` of every particle into `sums` (zeroed first), the particles of rigid
  /// materials at rest summed once into `stationary` and copied in (MpmOptions::stationary_sums_once).
  /// With a `count_column` (particlesToCells' touchColumn), only the rows whose count differs from
  /// the stationary one are copied: the others got nothing since and hold the stationary row.
  template <class F>
  void scatterWithStationarySums(const char* label, const BoxLookup& lookup, Field<Dim>& sums,
                                 StationarySums& stationary, const F& f, int count_column = -1);
  void allocateNodeFields();

  std::shared_ptr<const Layout<Dim>> layout_;
  MpmOptions options_;
  double cfl_;
  std::vector<SolidMaterial> materials_;
  std::array<double, 3> gravity_{0, 0, 0};
  std::array<int, 2 * Dim> wall_no_slip_{};  // per face: 1 no_slip, 0 free_slip
  double empty_node_mass_ = 0.0;             // below this a node holds no material (kg)
  std::string pending_error_;                // found by a phase, raised collectively by relocateParticles

  Particles<Dim> particles_;
  std::unique_ptr<ParticleMigration<Dim>> migration_;
  std::unique_ptr<Field<Dim>> node_sums_;           // mass, momentum, force, mass gradient
  std::unique_ptr<Field<Dim>> node_velocity_;       // v = p / m
  std::unique_ptr<Field<Dim>> node_velocity_star_;  // v* after forces, contact and walls
  std::unique_ptr<Field<Dim>> node_velocity_new_;   // MUSL: updated particle momenta mapped back
  std::unique_ptr<Field<Dim>> node_constraint_;     // MUSL: per material, how v* was held (ConstraintKind)
  std::unique_ptr<Field<Dim>> node_momentum_change_;  // coupled step: Σ_p w_ip m_p Δv_p
  std::unique_ptr<Field<Dim>> node_velocity_moved_;   // staggered coupling: v* before the coupled change
  std::unique_ptr<Field<Dim>> node_velocity_predicted_;  // predictCellVolumes: v* + a trial change
  // With more than one thread, the particle-to-node scatters run tile colour by tile colour
  // (ParticleBins); the bins of P2G hold until G2P moves the particles.
  StationarySums stationary_nodes_, stationary_cells_;
  ParticleBins<Dim> bins_;
  bool bins_current_ = false;
  ParticleSet bins_set_ = ParticleSet::All;  // the set the bins hold
  // The particles a step changes (ParticleSet::Changing), ascending; stale after particles moved
  // between ranks or were replaced.
  bool any_stationary_ = false;  // some material is rigid and at rest
  mutable Kokkos::View<int*, MemorySpace> changing_;  // a cache: rebuilt by const methods too
  mutable int changing_count_ = 0;
  mutable bool changing_current_ = false;
  // Every particle of a rigid material at rest is on the rank that owns its cell: relocateParticles
  // then looks at the changing particles alone. False after a new division or restored particles.
  bool stationary_placed_ = false;
};

extern template class MpmSolver<2>;
extern template class MpmSolver<3>;

}  // namespace cfdmpm::mpm
