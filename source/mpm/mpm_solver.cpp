#include "mpm/mpm_solver.hpp"

#include "common/mpi_comm.hpp"
#include "mpm/shape_functions.hpp"

#include <Teuchos_CommHelpers.hpp>

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace cfdmpm::mpm {

namespace {

/// Kernels keep per-material values on the stack; a scene has a handful of solids.
constexpr int kMaxMaterials = 8;

/// Below this fraction of its material's particle mass a node counts as empty (v = 0): GIMP
/// weights near the edge of a particle's support are arbitrarily small.
constexpr double kEmptyNodeMassFraction = 1e-12;
// A solid's cover of a face over the step (particlesToCells, roomColumn; the fluids' room) is
// measured in a band just below or just above the face. At rest the band is kFaceBandAtRest cells
// wide, so that the cover of a face on which a surface rests does not jump between 0 and 1 as the
// surface bulges past the face and back; in motion it narrows as w0² / (w0 + kFaceBandNarrowing |Δx|)
// with the box's displacement Δx in the step (cells), so that the step's motion, not the band, times
// a surface's crossing. Measured with this cover alone as the fluids' room (not kept; doc/mpmice.md):
// 1e-5 cells wide at rest, the resting block of `ParticleVolumesKeepTheBlocksBuoyantWeight` carried
// 1.066 of its buoyant weight (1.03 allowed; 0.990 at 1e-3); 1e-3 cells wide in motion too, the air
// beside a block falling through air (0.5-0.8 m/s, Δx = 2-4e-3 cells) reached 75-330 times
// potential flow's kinetic energy at each face crossing, 3-5 times with the band narrowed.
constexpr double kFaceBandAtRest = 1e-3;
constexpr double kFaceBandNarrowing = 40.0;

/// Columns of the node sums: mass, momentum, force and (for contact) mass gradient per material.
struct NodeColumns {
  int materials = 1;
  int dim = 2;
  KOKKOS_INLINE_FUNCTION int mass(int m) const { return m; }
  KOKKOS_INLINE_FUNCTION int momentum(int m, int d) const { return materials + m * dim + d; }
  KOKKOS_INLINE_FUNCTION int force(int m, int d) const { return materials * (1 + dim) + m * dim + d; }
  KOKKOS_INLINE_FUNCTION int massGradient(int m, int d) const { return materials * (1 + 2 * dim) + m * dim + d; }
  int count(bool with_gradients) const { return materials * (1 + (with_gradients ? 3 : 2) * dim); }
};

/// What the grid kernels need to know of the materials, by value.
struct MaterialTable {
  int count = 0;
  int rigid[kMaxMaterials] = {};
  double rigid_velocity[kMaxMaterials][3] = {};
  int rigid_moving[kMaxMaterials] = {};  // a rigid material with a velocity other than zero
  /// A rigid material at rest: its particles never change.
  KOKKOS_INLINE_FUNCTION bool stationary(int m) const { return rigid[m] && !rigid_moving[m]; }
};

MaterialTable materialTable(const std::vector<SolidMaterial>& materials)
{
  MaterialTable table;
  table.count = int(materials.size());
  for (int m = 0; m < table.count; ++m)
    if (const Rigid* rigid = materials[m].model.getIf<Rigid>()) {
      table.rigid[m] = 1;
      for (int d = 0; d < 3; ++d) {
        table.rigid_velocity[m][d] = rigid->velocity(d);
        if (rigid->velocity(d) != 0.0) table.rigid_moving[m] = 1;
      }
    }
  return table;
}

/// Coulomb friction with free separation (Bardenhagen et al. 2001, eqs. 8-10): a body whose
/// velocity v, relative to a reference velocity v_ref, moves along the outward normal n loses that
/// normal part, and its tangential part shrinks by at most mu times the normal part (sticks when
/// friction suffices). Moving apart (normal part <= 0) it is left free. Used between materials
/// (v_ref the centre-of-mass velocity) and against walls (v_ref = 0). True when it acted.
template <int Dim>
KOKKOS_INLINE_FUNCTION bool frictionalContact(double v[Dim], const double v_ref[Dim], const double n[Dim], double mu)
{
  double dv[Dim], normal = 0.0;
  for (int d = 0; d < Dim; ++d) {
    dv[d] = v[d] - v_ref[d];
    normal += dv[d] * n[d];
  }
  if (!(normal > 0.0)) return false;
  double tangent[Dim], tangent_norm2 = 0.0;
  for (int d = 0; d < Dim; ++d) {
    tangent[d] = dv[d] - normal * n[d];
    tangent_norm2 += tangent[d] * tangent[d];
  }
  const double tangent_norm = math::sqrt(tangent_norm2);
  // Tangential reduction min(mu dv_n, |dv_t|): sticking when the friction cone holds it.
  const double scale = tangent_norm > 0.0 ? math::min(mu * normal, tangent_norm) / tangent_norm : 0.0;
  for (int d = 0; d < Dim; ++d) v[d] -= normal * n[d] + scale * tangent[d];
  return true;
}

/// How a material's node velocity was constrained by GridConditions::apply (stored per node and
/// material by integrateGrid for the MUSL re-map, MpmSolver::gridToParticlesWith).
enum ConstraintKind : int {
  kFree = 0,     ///< no contact, or moving apart: the material moves freely
  kContact = 1,  ///< in contact with other non-rigid materials (relative to their centre of mass)
  kFixed = 2     ///< against a wall or a rigid material (relative to a prescribed velocity)
};

/// What a node velocity must satisfy after the grid update: contact between materials
/// (Bardenhagen et al. 2001) where two or more have mass, then the walls of the domain. Applied to
/// v* by integrateGrid and addCellVelocityChange; the MUSL re-map takes its decisions from there.
template <int Dim>
struct GridConditions {
  int materials = 0;
  NodeColumns col;
  MaterialTable table;
  double empty = 0.0;  // node mass below which a material is absent (kg)
  bool contact = false;
  double mu_contact = 0.0, mu_wall = 0.0;
  int no_slip[2 * Dim] = {};
  long long last_node[Dim] = {};
  typename Layout<Dim>::IjkTable ijk;

  /// Corrects v (per material) at node i; `kind[a]` (ConstraintKind) tells how material a was
  /// held, kFree where the conditions left it alone.
  template <class Sums>
  KOKKOS_INLINE_FUNCTION void apply(int i, const Sums& sums, const double m[], double v[][Dim], int kind[]) const
  {
    for (int a = 0; a < materials; ++a) kind[a] = kFree;
    // Contact where two or more materials meet: each approaching material loses its normal
    // velocity relative to the centre of mass (a rigid material's velocity when one is there).
    // Only v* is corrected: the FLIP increment v* - v then carries the contact impulse to the
    // particles, as it carries the walls' (a corrected v would let FLIP particles keep their
    // approach velocity).
    int occupied = 0, rigid = -1;
    for (int a = 0; a < materials; ++a)
      if (m[a] > empty) {
        ++occupied;
        if (table.rigid[a] && rigid < 0) rigid = a;
      }
    if (contact && occupied > 1) {
      double cm[Dim];
      for (int d = 0; d < Dim; ++d) {
        if (rigid >= 0) {
          cm[d] = table.rigid_velocity[rigid][d];
        } else {
          double momentum = 0.0, total = 0.0;
          for (int a = 0; a < materials; ++a)
            if (m[a] > empty) momentum += m[a] * v[a][d], total += m[a];
          cm[d] = momentum / total;
        }
      }
      // The contact normal of material a, pointing out of a towards what it touches. A material's
      // own mass gradient is a poor normal where its surface turns: at the corner of a block it
      // points 45 degrees down, so on a flat plate the block's front corner node "approaches"
      // the plate whenever the block moves along it, loses that motion as a normal velocity (no
      // friction limit) and pins the block: a block set on a plate stayed put at 30 degrees with
      // mu = 0.2. So a rigid body, whose surface is given, sets the normal of everything touching
      // it: n_a = grad m_rigid / |grad m_rigid| (its mass grows into it). Between non-rigid
      // materials the normal is the average of a's outward normal and the others' inward one,
      // grad(m_others - m_a), the same line for both sides of a pair (n_b = -n_a), so that the
      // corrections of a pair are equal and opposite and conserve momentum (Nairn 2013). Deep
      // inside a rigid body its mass gradient vanishes; there the averaged normal serves.
      for (int a = 0; a < materials; ++a) {
        if (!(m[a] > empty) || table.rigid[a]) continue;
        double n[Dim], n_rigid[Dim], norm2 = 0.0, rigid_norm2 = 0.0;
        for (int d = 0; d < Dim; ++d) {
          n[d] = -sums(i, col.massGradient(a, d));
          for (int b = 0; b < materials; ++b)
            if (b != a && m[b] > empty) n[d] += sums(i, col.massGradient(b, d));
          norm2 += n[d] * n[d];
          n_rigid[d] = rigid >= 0 ? sums(i, col.massGradient(rigid, d)) : 0.0;
          rigid_norm2 += n_rigid[d] * n_rigid[d];
        }
        if (rigid_norm2 > 1e-6 * norm2) {
          for (int d = 0; d < Dim; ++d) n[d] = n_rigid[d];
          norm2 = rigid_norm2;
        }
        if (!(norm2 > 0.0)) continue;
        const double inv = 1.0 / math::sqrt(norm2);
        for (int d = 0; d < Dim; ++d) n[d] *= inv;
        if (frictionalContact<Dim>(v[a], cm, n, mu_contact)) kind[a] = rigid >= 0 ? kFixed : kContact;
      }
    }

    // Walls: nodes on a domain face.
    for (int d = 0; d < Dim; ++d) {
      for (int side = 0; side < 2; ++side) {
        if (ijk(i, d) != (side == 0 ? 0 : last_node[d])) continue;
        const int face = 2 * d + side;
        double n[Dim], zero[Dim];
        for (int e = 0; e < Dim; ++e) n[e] = 0.0, zero[e] = 0.0;
        n[d] = side == 0 ? -1.0 : 1.0;  // outward normal of the domain
        for (int a = 0; a < materials; ++a) {
          if (table.rigid[a]) continue;
          if (no_slip[face]) {
            for (int e = 0; e < Dim; ++e) v[a][e] = 0.0;
            if (m[a] > empty) kind[a] = kFixed;
          } else if (frictionalContact<Dim>(v[a], zero, n, mu_wall)) {
            kind[a] = kFixed;
          }
        }
      }
    }
  }
};

template <int Dim>
GridConditions<Dim> gridConditions(const Layout<Dim>& layout, const std::vector<SolidMaterial>& materials,
                                   const MpmOptions& options, double empty_node_mass,
                                   const std::array<int, 2 * Dim>& wall_no_slip)
{
  GridConditions<Dim> c;
  c.materials = int(materials.size());
  c.col = NodeColumns{std::max(1, c.materials), Dim};
  c.table = materialTable(materials);
  c.empty = empty_node_mass;
  c.contact = options.contact && c.materials > 1;
  c.mu_contact = options.contact_friction;
  c.mu_wall = options.wall_friction;
  for (int f = 0; f < 2 * Dim; ++f) c.no_slip[f] = wall_no_slip[f];
  for (int d = 0; d < Dim; ++d) c.last_node[d] = layout.grid().nodes()[d] - 1;
  c.ijk = layout.nodeIndex();
  return c;
}

}  // namespace

template <int Dim>
MpmSolver<Dim>::MpmSolver(const Scene& scene, std::shared_ptr<const Layout<Dim>> layout, const MpmOptions& options)
    : layout_(std::move(layout)), options_(options), materials_(solidMaterials(scene))
{
  if (scene.domain.dimension != Dim)
    throw std::invalid_argument("MpmSolver<" + std::to_string(Dim) + ">: the scene is " +
                                std::to_string(scene.domain.dimension) + "-D");
  if (layout_->ghostWidth() < 1) throw std::invalid_argument("MpmSolver: the layout needs ghost_width >= 1");
  if (int(materials_.size()) > kMaxMaterials)
    throw InputError("cfdmpm.materials: " + std::to_string(materials_.size()) + " solid materials; MPM handles at most " +
                     std::to_string(kMaxMaterials));
  if (!(options_.flip_fraction >= 0.0 && options_.flip_fraction <= 1.0))
    throw std::invalid_argument("MpmOptions::flip_fraction must lie in [0, 1], got " + std::to_string(options_.flip_fraction));
  if (!(options_.wall_friction >= 0.0) || !(options_.contact_friction >= 0.0))
    throw std::invalid_argument("MpmOptions: friction coefficients must be >= 0");
  if (!(options_.velocity_damping >= 0.0)) throw std::invalid_argument("MpmOptions::velocity_damping must be >= 0");
  cfl_ = options_.cfl > 0.0 ? options_.cfl : scene.time.cfl;
  gravity_ = scene.domain.gravity;

  for (int f = 0; f < 2 * Dim; ++f) wall_no_slip_[f] = 1;  // a face not given is a no-slip wall
  for (const BoundarySpec& b : scene.boundaries)
    for (int f = 0; f < 2 * Dim; ++f)
      if (b.face == faceName(f)) wall_no_slip_[f] = b.velocity == "free_slip" ? 0 : 1;

  double smallest_particle = std::numeric_limits<double>::max();
  for (const SolidMaterial& s : materials_)
    smallest_particle = std::min(smallest_particle, s.density * layout_->grid().cellVolume() /
                                                        std::pow(double(s.particles_per_cell), Dim));
  empty_node_mass_ = kEmptyNodeMassFraction * smallest_particle;

  particles_ = seedParticles(scene, *layout_, materials_);
  const MaterialTable table = materialTable(materials_);
  for (int m = 0; m < table.count; ++m) any_stationary_ = any_stationary_ || table.stationary(m);
  allocateNodeFields();
  migration_ = std::make_unique<ParticleMigration<Dim>>(*layout_);
}

template <int Dim>
void MpmSolver<Dim>::allocateNodeFields()
{
  const int nm = std::max(1, int(materials_.size()));
  const NodeColumns columns{nm, Dim};
  const bool gradients = options_.contact && materials_.size() > 1;
  node_sums_ = std::make_unique<Field<Dim>>(layout_, Location::Node, columns.count(gradients), "mpm node sums");
  node_velocity_ = std::make_unique<Field<Dim>>(layout_, Location::Node, nm * Dim, "mpm node velocity");
  node_velocity_star_ = std::make_unique<Field<Dim>>(layout_, Location::Node, nm * Dim, "mpm node velocity star");
  if (options_.stress_update == StressUpdate::ModifiedLast) {
    node_velocity_new_ = std::make_unique<Field<Dim>>(layout_, Location::Node, nm * Dim, "mpm node velocity new");
    node_constraint_ = std::make_unique<Field<Dim>>(layout_, Location::Node, nm, "mpm node constraint");
  }
}

template <int Dim>
void MpmSolver<Dim>::repartition(std::shared_ptr<const Layout<Dim>> layout)
{
  layout_ = std::move(layout);
  particlesChanged();
  allocateNodeFields();
  migration_ = std::make_unique<ParticleMigration<Dim>>(*layout_);
  relocateParticles();
}

template <int Dim>
void MpmSolver<Dim>::setGravity(const std::array<double, 3>& gravity)
{
  gravity_ = gravity;
  stationary_nodes_.valid = false;  // their weight is in the node forces
}

// ---------------------------------------------------------------------------------------------
// The step
// ---------------------------------------------------------------------------------------------

template <int Dim>
void MpmSolver<Dim>::step(double dt)
{
  particlesToGrid();
  integrateGrid(dt);
  gridToParticles(dt);
  updateStress(dt);
  relocateParticles();
}

template <int Dim>
void MpmSolver<Dim>::particlesToGrid()
{
  withShapeFunction([&](auto kernel) {
    using K = decltype(kernel);
    particlesToGridWith<K>();
  });
}

template <int Dim>
void MpmSolver<Dim>::gridToParticles(double dt)
{
  withShapeFunction([&](auto kernel) {
    using K = decltype(kernel);
    gridToParticlesWith<K>(dt);
  });
}

template <int Dim>
void MpmSolver<Dim>::particlesChanged()
{
  changing_current_ = false;
  stationary_placed_ = false;
  bins_current_ = false;
  stationary_nodes_.valid = stationary_cells_.valid = false;
}

template <int Dim>
void MpmSolver<Dim>::refreshChangingList() const
{
  if (changing_current_ || everyParticleChanges()) return;
  const int n = particles_.count;
  if (int(changing_.extent(0)) < n)
    changing_ = Kokkos::View<int*, MemorySpace>(Kokkos::view_alloc(Kokkos::WithoutInitializing, "changing particles"),
                                                std::size_t(n) * 3 / 2 + 16);
  const MaterialTable table = materialTable(materials_);
  const auto material = particles_.material;
  const auto list = changing_;
  int count = 0;
  Kokkos::parallel_scan(
      "mpm::changing_particles", Kokkos::RangePolicy<ExecutionSpace>(0, n),
      KOKKOS_LAMBDA(const int p, int& offset, const bool final) {
        if (table.stationary(material(p))) return;
        if (final) list(offset) = p;
        ++offset;
      },
      count);
  changing_count_ = count;
  changing_current_ = true;
}

template <int Dim>
template <class F>
void MpmSolver<Dim>::forEachParticle(const char* label, ParticleSet set, const F& f) const
{
  if (set == ParticleSet::All || everyParticleChanges()) {
    Kokkos::parallel_for(label, Kokkos::RangePolicy<ExecutionSpace>(0, particles_.count), f);
    return;
  }
  refreshChangingList();
  const auto list = changing_;
  Kokkos::parallel_for(
      label, Kokkos::RangePolicy<ExecutionSpace>(0, changing_count_), KOKKOS_LAMBDA(const int i) { f(list(i)); });
}

template <int Dim>
template <class F, class Reducer>
void MpmSolver<Dim>::reduceOverParticles(const char* label, ParticleSet set, const F& f, const Reducer& reducer) const
{
  if (set == ParticleSet::All || everyParticleChanges()) {
    Kokkos::parallel_reduce(label, Kokkos::RangePolicy<ExecutionSpace>(0, particles_.count), f, reducer);
    return;
  }
  refreshChangingList();
  const auto list = changing_;
  Kokkos::parallel_reduce(
      label, Kokkos::RangePolicy<ExecutionSpace>(0, changing_count_),
      KOKKOS_LAMBDA(const int i, typename Reducer::value_type& value) { f(list(i), value); }, reducer);
}

template <int Dim>
template <class F>
void MpmSolver<Dim>::forEachParticleScattering(const char* label, const BoxLookup& lookup, ParticleSet set,
                                               const F& f)
{
  if (everyParticleChanges()) set = ParticleSet::All;
  // One thread adds particle by particle; more threads go tile colour by tile colour, so that no
  // two threads add into the same node (ParticleBins; no atomics, no per-thread copies).
  const int threads = ExecutionSpace().concurrency();
  if (threads > 1) {
    if (!bins_current_ || bins_set_ != set) {
      if (set == ParticleSet::All) {
        bins_.build(particles_, layout_->grid(), lookup, threads);
      } else {
        refreshChangingList();
        bins_.build(particles_, layout_->grid(), lookup, threads, changing_, changing_count_);
      }
      bins_set_ = set;
    }
    bins_current_ = true;
    bins_.forEachParticle(f);
  } else {
    forEachParticle(label, set, f);
  }
}

template <int Dim>
template <class F>
void MpmSolver<Dim>::scatterWithStationarySums(const char* label, const BoxLookup& lookup, Field<Dim>& sums,
                                               StationarySums& stationary, const F& f, int count_column)
{
  const MaterialTable table = materialTable(materials_);
  if (!options_.stationary_sums_once || everyParticleChanges()) {
    sums.fill(0.0);
    forEachParticleScattering(label, lookup, ParticleSet::All, f);
    return;
  }
  // A bed at rest holds most of a slide's particles (91 % at 5 mm) and adds the same at every
  // step. Its particles are summed once, in the order of their ids: a run restarted from a
  // checkpoint, whose particles may lie in another order, then adds the same digits.
  const auto values = sums.view();
  if (!stationary.valid || stationary.values.extent(0) != values.extent(0) ||
      stationary.values.extent(1) != values.extent(1)) {
    const auto material_host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.material);
    const auto id_host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.id);
    std::vector<int> in_order;
    for (int p = 0; p < particles_.count; ++p)
      if (table.stationary(material_host(p))) in_order.push_back(p);
    std::sort(in_order.begin(), in_order.end(), [&](int a, int b) { return id_host(a) < id_host(b); });
    Kokkos::View<int*, MemorySpace> order("stationary particles in id order", in_order.size());
    Kokkos::deep_copy(order, Kokkos::View<const int*, Kokkos::HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>>(
                                 in_order.data(), in_order.size()));
    sums.fill(0.0);
    const int count = int(in_order.size());
    // One thread, in order (threads would add into the same nodes); once per run.
    Kokkos::parallel_for(
        "mpm::stationary_sums", Kokkos::RangePolicy<ExecutionSpace>(0, 1), KOKKOS_LAMBDA(const int) {
          for (int k = 0; k < count; ++k) f(order(k));
        });
    stationary.values = typename Field<Dim>::View(
        Kokkos::view_alloc(Kokkos::WithoutInitializing, "stationary particles' sums"), values.extent(0), values.extent(1));
    Kokkos::deep_copy(stationary.values, values);
    stationary.valid = true;
  } else if (count_column < 0) {
    Kokkos::deep_copy(values, stationary.values);
  } else {
    // A row whose count of contributions is the stationary one got nothing else since it was last
    // copied (every addition, here or from another rank, counts), so it holds the stationary row:
    // on the seed scene most rows are the bed's or empty, and the copy of every row was ~1 % of
    // the coupled step.
    const auto rows = stationary.values;
    const int columns = int(values.extent(1));
    Kokkos::parallel_for(
        "mpm::stationary_rows", Kokkos::RangePolicy<ExecutionSpace>(0, values.extent(0)), KOKKOS_LAMBDA(const int i) {
          if (values(i, count_column) == rows(i, count_column)) return;
          for (int k = 0; k < columns; ++k) values(i, k) = rows(i, k);
        });
  }
  forEachParticleScattering(label, lookup, ParticleSet::Changing, f);
}

/// P2G: m_i = sum_p w_ip m_p, (mv)_i = sum_p w_ip m_p v_p,
///      f_i = sum_p (-V_p sigma_p grad w_ip + w_ip m_p g)   (internal + external force),
///      grad m_i = sum_p m_p grad w_ip                       (material normals for contact),
/// per material, scattered race-free on threads (ParticleBins), then summed across ranks.
template <int Dim>
template <class Kernel>
void MpmSolver<Dim>::particlesToGridWith()
{
  const Grid<Dim>& grid = layout_->grid();
  const NodeColumns col{std::max(1, int(materials_.size())), Dim};
  const bool gradients = options_.contact && materials_.size() > 1;
  const auto x = particles_.position;
  const auto v = particles_.velocity;
  const auto mass = particles_.mass;
  const auto volume = particles_.volume;
  const auto sigma = particles_.stress;
  const auto half_width = particles_.half_width;
  const auto material = particles_.material;
  const BoxLookup lookup = layout_->nodeLookup();
  double origin[Dim], spacing[Dim], g[Dim];
  long long nodes[Dim];
  for (int d = 0; d < Dim; ++d) {
    origin[d] = grid.lower()[d], spacing[d] = grid.spacing()[d], g[d] = gravity_[d];
    nodes[d] = grid.nodes()[d];
  }
  Kokkos::View<int, MemorySpace> missing("nodes missing from the overlap");
  const auto sums = node_sums_->view();
  const auto scatter = KOKKOS_LAMBDA(const int p)
  {
    double xp[Dim], lp[Dim];
    for (int d = 0; d < Dim; ++d) xp[d] = x(p, d), lp[d] = half_width(p, d);
    ShapeStencil<Dim, Kernel> s;
    evaluateShape(xp, origin, spacing, lp, s);
    const int m = material(p);
    const double mp = mass(p), Vp = volume(p);
    for (int k = 0; k < s.size; ++k) {
      long long node[3] = {0, 0, 0};
      s.node(k, node);
      const LocalOrdinal lid = lookup(node[0], node[1], node[2]);
      if (lid < 0) {
        bool inside = true;
        for (int d = 0; d < Dim; ++d) inside = inside && node[d] >= 0 && node[d] < nodes[d];
        if (inside && s.weight[k] > 0.0) Kokkos::atomic_add(&missing(), 1);
        continue;  // outside the grid: the part of the particle beyond the wall
      }
      const double w = s.weight[k];
      sums(lid, col.mass(m)) += w * mp;
      for (int d = 0; d < Dim; ++d) {
        double internal = 0.0;
        for (int e = 0; e < Dim; ++e) internal -= sigma(p, d, e) * s.gradient[k][e];
        sums(lid, col.momentum(m, d)) += w * mp * v(p, d);
        sums(lid, col.force(m, d)) += Vp * internal + w * mp * g[d];
        // grad m(x_i) = sum_p m_p dS(x_i - x_p)/dx_i = -sum_p m_p dw_ip/dx_p
        if (gradients) sums(lid, col.massGradient(m, d)) += -mp * s.gradient[k][d];
      }
    }
  };
  // P2G starts from particles that may have been moved or replaced since the last bins were built.
  bins_current_ = false;
  scatterWithStationarySums("mpm::particles_to_grid", lookup, *node_sums_, stationary_nodes_, scatter);
  int missing_host = 0;
  Kokkos::deep_copy(missing_host, missing);
  if (missing_host > 0 && pending_error_.empty())  // raised on every rank by relocateParticles
    pending_error_ = "MPM particles-to-grid: " + std::to_string(missing_host) +
                     " particle-node pairs reach nodes beyond rank " + std::to_string(layout_->comm()->getRank()) +
                     "'s ghost nodes; particles must lie in owned cells (relocateParticles) and ghost_width must "
                     "be >= 1";
  node_sums_->sumToOwners();
}

/// Grid update on every local node (the node sums are complete on ghosts too):
///   v_i = (mv)_i / m_i,   v*_i = v_i + dt (f_i / m_i - alpha v_i),
/// rigid materials take their prescribed velocity; then contact between materials on v*
/// (Bardenhagen et al. 2001), then the walls on v* (no_slip: v* = 0; free_slip: Coulomb friction
/// with free separation, coefficient MpmOptions::wall_friction).
template <int Dim>
void MpmSolver<Dim>::integrateGrid(double dt)
{
  const int nm = int(materials_.size());
  const NodeColumns col{std::max(1, nm), Dim};
  const MaterialTable table = materialTable(materials_);
  const double empty = empty_node_mass_;
  const double alpha = options_.velocity_damping;
  const GridConditions<Dim> conditions = gridConditions<Dim>(*layout_, materials_, options_, empty_node_mass_, wall_no_slip_);
  const auto sums = node_sums_->view();
  auto velocity = node_velocity_->view();
  auto velocity_star = node_velocity_star_->view();
  // Only the MUSL re-map reads how v* was held.
  const bool record = node_constraint_ != nullptr;
  auto constraint = record ? node_constraint_->view() : typename Field<Dim>::View();

  Kokkos::parallel_for(
      "mpm::integrate_grid", Kokkos::RangePolicy<ExecutionSpace>(0, node_sums_->overlapCount()),
      KOKKOS_LAMBDA(const int i) {
        double v[kMaxMaterials][Dim], vs[kMaxMaterials][Dim], m[kMaxMaterials] = {};
        for (int a = 0; a < nm; ++a) {
          m[a] = sums(i, col.mass(a));
          for (int d = 0; d < Dim; ++d) {
            if (!(m[a] > empty)) {
              v[a][d] = vs[a][d] = 0.0;
            } else if (table.rigid[a]) {
              v[a][d] = vs[a][d] = table.rigid_velocity[a][d];
            } else {
              v[a][d] = sums(i, col.momentum(a, d)) / m[a];
              vs[a][d] = v[a][d] + dt * (sums(i, col.force(a, d)) / m[a] - alpha * v[a][d]);
            }
          }
        }
        int kind[kMaxMaterials];
        conditions.apply(i, sums, m, vs, kind);
        for (int a = 0; a < nm; ++a) {
          if (record) constraint(i, a) = kind[a];
          for (int d = 0; d < Dim; ++d) {
            velocity(i, a * Dim + d) = v[a][d];
            velocity_star(i, a * Dim + d) = vs[a][d];
          }
        }
      });
}

/// G2P: v_p <- f (v_p + sum_i w_ip (v*_i - v_i)) + (1 - f) sum_i w_ip v*_i   (FLIP share f),
///      x_p <- x_p + dt sum_i w_ip v*_i,   L_p = sum_i u_i (x) grad w_ip,
///      F_p <- (I + dt L_p) F_p,   V_p = det(F_p) V_p0,
/// with u = v* (USL) or, for MUSL, u = the updated particle momenta mapped back to the nodes,
/// u_i = sum_p w_ip m_p v_p / m_i, held where v* was held (contact and walls, decided on v*). All weights
/// are those of the positions at the start of the step. Each particle reads its own material's
/// node velocities. Rigid particles move with their prescribed velocity and keep F = I.
template <int Dim>
template <class Kernel>
void MpmSolver<Dim>::gridToParticlesWith(double dt)
{
  const Grid<Dim>& grid = layout_->grid();
  const int nm = int(materials_.size());
  const NodeColumns col{std::max(1, nm), Dim};
  const MaterialTable table = materialTable(materials_);
  const double flip = options_.flip_fraction;
  const bool remap = options_.stress_update == StressUpdate::ModifiedLast;
  const auto x = particles_.position;
  const auto v = particles_.velocity;
  const auto mass = particles_.mass;
  const auto volume = particles_.volume;
  const auto initial_volume = particles_.initial_volume;
  const auto F = particles_.deformation_gradient;
  const auto L = particles_.velocity_gradient;
  const auto half_width = particles_.half_width;
  const auto material = particles_.material;
  const BoxLookup lookup = layout_->nodeLookup();
  const auto node_v = node_velocity_->view();
  const auto node_vs = node_velocity_star_->view();
  double origin[Dim], spacing[Dim];
  for (int d = 0; d < Dim; ++d) origin[d] = grid.lower()[d], spacing[d] = grid.spacing()[d];

  // MUSL: the velocity update and the momentum it maps back, then the grid velocity u.
  if (remap) {
    node_velocity_new_->fill(0.0);
    const auto momentum = node_velocity_new_->view();
    const auto update = KOKKOS_LAMBDA(const int p)
    {
      const int m = material(p);
      if (table.rigid[m]) return;
      double xp[Dim], lp[Dim];
      for (int d = 0; d < Dim; ++d) xp[d] = x(p, d), lp[d] = half_width(p, d);
      ShapeStencil<Dim, Kernel> s;
      evaluateShape(xp, origin, spacing, lp, s);
      LocalOrdinal lids[ShapeStencil<Dim, Kernel>::size];
      double v_grid[Dim] = {}, dv[Dim] = {}, vp[Dim];
      for (int k = 0; k < s.size; ++k) {
        long long node[3] = {0, 0, 0};
        s.node(k, node);
        lids[k] = lookup(node[0], node[1], node[2]);
        if (lids[k] < 0) continue;
        const double w = s.weight[k];
        for (int d = 0; d < Dim; ++d) {
          const double vs = node_vs(lids[k], m * Dim + d);
          v_grid[d] += w * vs;
          dv[d] += w * (vs - node_v(lids[k], m * Dim + d));
        }
      }
      for (int d = 0; d < Dim; ++d) vp[d] = v(p, d) = flip * (v(p, d) + dv[d]) + (1.0 - flip) * v_grid[d];
      const double mp = mass(p);
      for (int k = 0; k < s.size; ++k) {
        if (lids[k] < 0) continue;
        for (int d = 0; d < Dim; ++d) momentum(lids[k], m * Dim + d) += s.weight[k] * mp * vp[d];
      }
    };
    // The same scatter order as in particlesToGridWith (its bins still hold: no particle moved).
    forEachParticleScattering("mpm::grid_to_particles_velocity", lookup, ParticleSet::Changing, update);
    node_velocity_new_->sumToOwners();
    // The contact and wall conditions on u. They were decided once, on v*, in this step: the
    // particles move with v*, so a node that v* held against a wall, a rigid body or another
    // material is held for u too, and one that v* let go stays free. u differs from v* by the
    // smoothing of the re-map (u = v + M_L^-1 M_c (v* - v) without contact), and at a held node
    // that difference is motion across the interface that did not happen: a block's bottom node,
    // held on a plate while the block above rebounds, gets an upward u from the particles above
    // it; judged again on u it counts as separating and is left free, and the strain rate then
    // compresses the block's bottom layer although its particles did not move - the stress pushes
    // the block off the plate harder than it hit (0.673 against 0.605 m/s), and friction pressed
    // by that stress let a block slide 16-21 % ahead of g (sin theta - mu cos theta). Deciding the
    // conditions on u afresh fails the other way too: the approach a held node had in v is
    // removed from u a second time. So a held material's u takes v*'s motion relative to what
    // holds it: against a wall or a rigid body (kFixed), u_a = v*_a; against other materials
    // (kContact), u_a = v*_a + (u_cm - v*_cm), which keeps the re-map's centre-of-mass velocity
    // of the node and v*'s relative motion across the interface.
    const auto sums = node_sums_->view();
    const auto constraint = node_constraint_->view();
    const double empty = empty_node_mass_;
    Kokkos::parallel_for(
        "mpm::remapped_grid_velocity", Kokkos::RangePolicy<ExecutionSpace>(0, node_sums_->overlapCount()),
        KOKKOS_LAMBDA(const int i) {
          double u[kMaxMaterials][Dim] = {}, m[kMaxMaterials] = {}, u_cm[Dim] = {}, vs_cm[Dim] = {}, total = 0.0;
          for (int a = 0; a < nm; ++a) {
            m[a] = sums(i, col.mass(a));
            for (int d = 0; d < Dim; ++d)
              u[a][d] = !(m[a] > empty) ? 0.0
                        : table.rigid[a] ? table.rigid_velocity[a][d]
                                         : momentum(i, a * Dim + d) / m[a];
            if (m[a] > empty && !table.rigid[a]) {
              total += m[a];
              for (int d = 0; d < Dim; ++d) u_cm[d] += m[a] * u[a][d], vs_cm[d] += m[a] * node_vs(i, a * Dim + d);
            }
          }
          for (int a = 0; a < nm; ++a) {
            const int kind = int(constraint(i, a));
            for (int d = 0; d < Dim; ++d) {
              if (kind == kFixed) u[a][d] = node_vs(i, a * Dim + d);
              if (kind == kContact) u[a][d] = node_vs(i, a * Dim + d) + (u_cm[d] - vs_cm[d]) / total;
              momentum(i, a * Dim + d) = u[a][d];
            }
          }
        });
  }
  const auto node_u = remap ? node_velocity_new_->view() : node_vs;
  // The velocity the particles move with: v*, or with the staggered coupling v* before the coupled
  // step's change (the motion the fluids' pressure equation was given), gathered only then.
  const bool moved_apart = options_.move_before_coupling && node_velocity_moved_;
  const auto node_moved = moved_apart ? node_velocity_moved_->view() : node_vs;

  forEachParticle(
      "mpm::grid_to_particles", ParticleSet::Changing, KOKKOS_LAMBDA(const int p) {
        const int m = material(p);
        if (table.rigid[m]) {
          for (int d = 0; d < Dim; ++d) {
            v(p, d) = table.rigid_velocity[m][d];
            x(p, d) += dt * v(p, d);
            for (int e = 0; e < Dim; ++e) L(p, d, e) = 0.0;
          }
          return;
        }
        double xp[Dim], lp[Dim];
        for (int d = 0; d < Dim; ++d) xp[d] = x(p, d), lp[d] = half_width(p, d);
        ShapeStencil<Dim, Kernel> s;
        evaluateShape(xp, origin, spacing, lp, s);
        double v_grid[Dim] = {}, dv[Dim] = {}, v_moved[Dim] = {};
        Mat<Dim> grad_v;
        for (int k = 0; k < s.size; ++k) {
          long long node[3] = {0, 0, 0};
          s.node(k, node);
          const LocalOrdinal lid = lookup(node[0], node[1], node[2]);
          if (lid < 0) continue;
          const double w = s.weight[k];
          for (int d = 0; d < Dim; ++d) {
            const double vs = node_vs(lid, m * Dim + d);
            v_grid[d] += w * vs;
            if (moved_apart) v_moved[d] += w * node_moved(lid, m * Dim + d);
            dv[d] += w * (vs - node_v(lid, m * Dim + d));
            const double u = node_u(lid, m * Dim + d);
            for (int e = 0; e < Dim; ++e) grad_v(d, e) += u * s.gradient[k][e];
          }
        }
        Mat<Dim> Fp;
        for (int d = 0; d < Dim; ++d) {
          if (!remap) v(p, d) = flip * (v(p, d) + dv[d]) + (1.0 - flip) * v_grid[d];
          x(p, d) += dt * (moved_apart ? v_moved[d] : v_grid[d]);
          for (int e = 0; e < Dim; ++e) {
            L(p, d, e) = grad_v(d, e);
            Fp(d, e) = F(p, d, e);
          }
        }
        const Mat<Dim> F_new = (Mat<Dim>::identity() + dt * grad_v) * Fp;
        for (int d = 0; d < Dim; ++d)
          for (int e = 0; e < Dim; ++e) F(p, d, e) = F_new(d, e);
        volume(p) = determinant(F_new) * initial_volume(p);
      });
  bins_current_ = false;  // the particles moved
}

namespace {

/// The cells that the GIMP domain of a particle (the box [x_p - l_p, x_p + l_p] per direction)
/// overlaps, and the share of the box in each: at most two cells per direction (l_p <= h/2). The
/// part of the box beyond a domain face is given to the boundary cell, so the shares sum to one.
template <int Dim>
struct CellOverlap {
  static constexpr int kMaxCells = 1 << Dim;
  int count = 0;
  long long cell[kMaxCells][3];
  double share[kMaxCells];

  KOKKOS_INLINE_FUNCTION CellOverlap(const double x[Dim], const double l[Dim], const double origin[Dim],
                                     const double spacing[Dim], const long long cells[Dim])
  {
    long long first[Dim];
    double lower_share[Dim];
    int span[Dim];
    for (int d = 0; d < Dim; ++d) {
      const double lo = (x[d] - l[d] - origin[d]) / spacing[d];
      const double hi = (x[d] + l[d] - origin[d]) / spacing[d];
      long long a = (long long)math::floor(lo), b = (long long)math::floor(hi);
      a = a < 0 ? 0 : (a > cells[d] - 1 ? cells[d] - 1 : a);
      b = b < 0 ? 0 : (b > cells[d] - 1 ? cells[d] - 1 : b);
      first[d] = a;
      if (b == a) {
        span[d] = 1, lower_share[d] = 1.0;
      } else {
        span[d] = 2;
        const double s = (double(a + 1) - lo) / (hi - lo);  // share below the face between a and a + 1
        lower_share[d] = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
      }
    }
    for (int corner = 0; corner < kMaxCells; ++corner) {
      double w = 1.0;
      bool used = true;
      long long ijk[3] = {0, 0, 0};
      for (int d = 0; d < Dim; ++d) {
        const int upper = (corner >> d) & 1;
        if (upper && span[d] == 1) used = false;
        ijk[d] = first[d] + upper;
        w *= upper ? 1.0 - lower_share[d] : lower_share[d];
      }
      if (!used) continue;
      for (int d = 0; d < 3; ++d) cell[count][d] = ijk[d];
      share[count++] = w;
    }
    for (int d = 0; d < Dim; ++d) first_[d] = first[d], span_[d] = span[d], lower_share_[d] = lower_share[d];
  }

  /// The cells of the box's overlap that share one index (`along`) in direction d: the other
  /// directions' cells and shares, as for the whole box. Visits f(ijk, share) with ijk[d] unset.
  template <class F>
  KOKKOS_INLINE_FUNCTION void acrossDirection(int d, F&& f) const
  {
    for (int corner = 0; corner < kMaxCells; ++corner) {
      if ((corner >> d) & 1) continue;
      double w = 1.0;
      bool used = true;
      long long ijk[3] = {0, 0, 0};
      for (int e = 0; e < Dim; ++e) {
        if (e == d) continue;
        const int upper = (corner >> e) & 1;
        if (upper && span_[e] == 1) used = false;
        ijk[e] = first_[e] + upper;
        w *= upper ? 1.0 - lower_share_[e] : lower_share_[e];
      }
      if (used) f(ijk, w);
    }
  }

 private:
  long long first_[Dim];
  int span_[Dim];
  double lower_share_[Dim];
};

/// The velocity a particle moves with in G2P, Σ_i w_ip u_i over the node velocities u (its own
/// material's columns), or a rigid particle's prescribed velocity.
template <int Dim, class Kernel, class NodeView>
KOKKOS_INLINE_FUNCTION void particleGridVelocity(const double xp[Dim], const double lp[Dim], int m,
                                                 const MaterialTable& table, const double origin[Dim],
                                                 const double spacing[Dim], const BoxLookup& nodes, const NodeView& u,
                                                 double velocity[Dim])
{
  for (int d = 0; d < Dim; ++d) velocity[d] = 0.0;
  if (table.rigid[m]) {
    for (int d = 0; d < Dim; ++d) velocity[d] = table.rigid_velocity[m][d];
    return;
  }
  ShapeStencil<Dim, Kernel> s;
  evaluateShape(xp, origin, spacing, lp, s);
  for (int k = 0; k < s.size; ++k) {
    long long node[3] = {0, 0, 0};
    s.node(k, node);
    const LocalOrdinal lid = nodes(node[0], node[1], node[2]);
    if (lid < 0) continue;
    for (int d = 0; d < Dim; ++d) velocity[d] += s.weight[k] * u(lid, m * Dim + d);
  }
}

/// The share of the band [a, b] (in cells) that the interval [lo, hi] covers, averaged over a
/// step in which the interval moves by `s`. The overlap of the sliding interval with the band is a
/// trapezoid in the offset u, a sum of four ramps R(u − c) = max(u − c, 0) with signs + − − + at
/// the corners c; each ramp's mean over the step is taken in a form without cancellation, exact
/// for s = 0 too.
KOKKOS_INLINE_FUNCTION double bandCoverOverStep(double lo, double hi, double s, double a, double b)
{
  const auto ramp_mean = [s](double c) {
    if (c < math::min(0.0, s)) return 0.5 * s - c;  // on the ramp through the whole step
    if (s > 0 && c < s) return 0.5 * (s - c) * (s - c) / s;
    if (s < 0 && c < 0) return -0.5 * c * c / s;
    return 0.0;
  };
  const double overlap = ramp_mean(a - hi) - ramp_mean(b - hi) - ramp_mean(a - lo) + ramp_mean(b - lo);
  return math::min(1.0, math::max(0.0, overlap / (b - a)));
}

/// Adds V_p times the shares of the box of half-width l about x + Δt v (the particle moved by
/// G2P) to column `column` of the cells it overlaps.
template <int Dim, class CellView>
KOKKOS_INLINE_FUNCTION void addMovedBox(const double x[Dim], const double l[Dim], const double velocity[Dim], double dt,
                                        double Vp, const double origin[Dim], const double spacing[Dim],
                                        const long long count[Dim], const BoxLookup& cells, const CellView& out,
                                        int column, int touch_column = -1)
{
  double moved[Dim];
  for (int d = 0; d < Dim; ++d) moved[d] = x[d] + dt * velocity[d];
  const CellOverlap<Dim> predicted(moved, l, origin, spacing, count);
  for (int k = 0; k < predicted.count; ++k) {
    const LocalOrdinal c = cells(predicted.cell[k][0], predicted.cell[k][1], predicted.cell[k][2]);
    if (c < 0) continue;
    out(c, column) += predicted.share[k] * Vp;
    if (touch_column >= 0) out(c, touch_column) += 1.0;
  }
}

}  // namespace

template <int Dim>
void MpmSolver<Dim>::particlesToCells(Field<Dim>& sums, double dt, bool forecast)
{
  withShapeFunction([&](auto kernel) {
    using K = decltype(kernel);
    particlesToCellsWith<K>(sums, dt, forecast);
  });
}

template <int Dim>
void MpmSolver<Dim>::startOwnMotion()
{
  const auto v = particles_.velocity;
  const auto change = particles_.velocity_change;
  const auto mark = particles_.own_acceleration;  // holds the mark until recordOwnAcceleration
  forEachParticle(
      "mpm::start_own_motion", ParticleSet::Changing, KOKKOS_LAMBDA(const int p) {
        for (int d = 0; d < Dim; ++d) mark(p, d) = v(p, d) + change(p, d);
      });
}

template <int Dim>
void MpmSolver<Dim>::recordOwnAcceleration(double dt)
{
  const auto v = particles_.velocity;
  const auto a = particles_.own_acceleration;
  forEachParticle(
      "mpm::record_own_acceleration", ParticleSet::Changing, KOKKOS_LAMBDA(const int p) {
        for (int d = 0; d < Dim; ++d) a(p, d) = (v(p, d) - a(p, d)) / dt;
      });
}

template <int Dim>
void MpmSolver<Dim>::addCellVelocityChange(const Field<Dim>& change)
{
  withShapeFunction([&](auto kernel) {
    using K = decltype(kernel);
    addCellVelocityChangeWith<K>(change, *node_velocity_star_, true);
  });
}

template <int Dim>
void MpmSolver<Dim>::cellVelocityChangeToParticles(const Field<Dim>& change)
{
  const int nm = int(materials_.size());
  const Grid<Dim>& grid = layout_->grid();
  const MaterialTable table = materialTable(materials_);
  const auto x = particles_.position;
  const auto half_width = particles_.half_width;
  const auto material = particles_.material;
  const auto dv = particles_.velocity_change;
  const BoxLookup cells = layout_->cellLookup();
  const auto du = change.view();
  double origin[Dim], spacing[Dim];
  long long count[Dim];
  for (int d = 0; d < Dim; ++d)
    origin[d] = grid.lower()[d], spacing[d] = grid.spacing()[d], count[d] = grid.cells()[d];
  forEachParticle(
      "mpm::cell_velocity_change_to_particles", ParticleSet::Changing, KOKKOS_LAMBDA(const int p) {
        const int m = material(p);
        double xp[Dim], lp[Dim], change_p[Dim] = {};
        for (int d = 0; d < Dim; ++d) xp[d] = x(p, d), lp[d] = half_width(p, d);
        if (!table.rigid[m]) {
          const CellOverlap<Dim> overlap(xp, lp, origin, spacing, count);
          for (int k = 0; k < overlap.count; ++k) {
            const LocalOrdinal c = cells(overlap.cell[k][0], overlap.cell[k][1], overlap.cell[k][2]);
            if (c < 0) continue;
            for (int d = 0; d < Dim; ++d) change_p[d] += overlap.share[k] * du(c, 2 * nm + m * Dim + d);
          }
        }
        for (int d = 0; d < Dim; ++d) dv(p, d) = change_p[d];
      });
}

template <int Dim>
void MpmSolver<Dim>::addParticleVelocityChange(double fraction)
{
  withShapeFunction([&](auto kernel) {
    using K = decltype(kernel);
    particleVelocityChangeToNodesWith<K>(fraction);
  });
  applyNodeMomentumChange(*node_velocity_star_, true);
}

template <int Dim>
template <class Kernel>
void MpmSolver<Dim>::particleVelocityChangeToNodesWith(double fraction)
{
  const int nm = int(materials_.size());
  if (!node_momentum_change_)
    node_momentum_change_ =
        std::make_unique<Field<Dim>>(layout_, Location::Node, std::max(1, nm) * Dim, "mpm node momentum change");
  node_momentum_change_->fill(0.0);
  const Grid<Dim>& grid = layout_->grid();
  const MaterialTable table = materialTable(materials_);
  const auto x = particles_.position;
  const auto mass = particles_.mass;
  const auto half_width = particles_.half_width;
  const auto material = particles_.material;
  const auto change = particles_.velocity_change;
  const BoxLookup nodes = layout_->nodeLookup();
  const auto dmv = node_momentum_change_->view();
  double origin[Dim], spacing[Dim];
  for (int d = 0; d < Dim; ++d) origin[d] = grid.lower()[d], spacing[d] = grid.spacing()[d];
  const auto scatter = KOKKOS_LAMBDA(const int p)
  {
    const int m = material(p);
    if (table.rigid[m]) return;
    double xp[Dim], lp[Dim], dv[Dim];
    for (int d = 0; d < Dim; ++d) xp[d] = x(p, d), lp[d] = half_width(p, d), dv[d] = fraction * change(p, d);
    ShapeStencil<Dim, Kernel> s;
    evaluateShape(xp, origin, spacing, lp, s);
    const double mp = mass(p);
    for (int k = 0; k < s.size; ++k) {
      long long node[3] = {0, 0, 0};
      s.node(k, node);
      const LocalOrdinal lid = nodes(node[0], node[1], node[2]);
      if (lid < 0) continue;
      for (int d = 0; d < Dim; ++d) dmv(lid, m * Dim + d) += s.weight[k] * mp * dv[d];
    }
  };
  forEachParticleScattering("mpm::particle_velocity_change", nodes, ParticleSet::Changing, scatter);
  node_momentum_change_->sumToOwners();
}

template <int Dim>
void MpmSolver<Dim>::predictCellVolumes(const Field<Dim>& change, double dt, Field<Dim>& volumes)
{
  withShapeFunction([&](auto kernel) {
    using K = decltype(kernel);
    predictCellVolumesWith<K>(change, dt, volumes);
  });
}

namespace {

// The volume of a particle that the fluids see: V_p without its plastic dilation, V_p exp(−ε^p_v),
// i.e. V_p0 times its elastic volume change. A granular solid that dilates plastically (a
// Drucker-Prager sand at its apex, where its grains part, or with a dilatancy angle) opens pores
// that the fluid around it fills: the solid is drained, and its grains with the pore fluid they held
// before take no more of the cell than that. Counted as solid, the dilation pushed the fluid out of
// the cells instead: a Drucker-Prager column collapsing under water swelled by 49 % in 0.4 s, single
// particles at its surface to 23 times their volume (doc/mpmice.md, "A granular solid's plastic
// dilation is the fluids' volume"). Every other model keeps ε^p_v = 0: the fluids see its V_p.
KOKKOS_INLINE_FUNCTION double fluidsVolume(double volume, const MaterialState& state)
{
  return state.volumetric_plastic_strain == 0.0 ? volume : volume * math::exp(-state.volumetric_plastic_strain);
}

}  // namespace

template <int Dim>
template <class Kernel>
void MpmSolver<Dim>::particlesToCellsWith(Field<Dim>& sums, double dt, bool forecast)
{
  const int nm = int(materials_.size());
  if (sums.columns() != cellColumns(nm))
    throw std::invalid_argument("MpmSolver::particlesToCells: the cell field needs " + std::to_string(cellColumns(nm)) +
                                " columns");
  const Grid<Dim>& grid = layout_->grid();
  const MaterialTable table = materialTable(materials_);
  const auto x = particles_.position;
  const auto mass = particles_.mass;
  const auto volume = particles_.volume;
  const auto v = particles_.velocity;
  const auto own_acceleration = particles_.own_acceleration;
  const auto half_width = particles_.half_width;
  const auto material = particles_.material;
  const auto history = particles_.state;
  const BoxLookup nodes = layout_->nodeLookup();
  const BoxLookup cells = layout_->cellLookup();
  const auto node_vs = node_velocity_star_->view();
  const auto out = sums.view();
  double origin[Dim], spacing[Dim];
  long long count[Dim];
  for (int d = 0; d < Dim; ++d)
    origin[d] = grid.lower()[d], spacing[d] = grid.spacing()[d], count[d] = grid.cells()[d];
  const double cell_volume = grid.cellVolume();
  const double layer = options_.face_layer;
  const int touch = touchColumn(nm);  // +1 with every contribution to a cell (touchColumn)
  const auto scatter = KOKKOS_LAMBDA(const int p)
  {
    const int m = material(p);
    double xp[Dim], lp[Dim], velocity[Dim];
    for (int d = 0; d < Dim; ++d) xp[d] = x(p, d), lp[d] = half_width(p, d);
    if (forecast && !table.rigid[m]) {
      for (int d = 0; d < Dim; ++d) velocity[d] = v(p, d) + dt * own_acceleration(p, d);
    } else {
      particleGridVelocity<Dim, Kernel>(xp, lp, m, table, origin, spacing, nodes, node_vs, velocity);
    }
    const CellOverlap<Dim> overlap(xp, lp, origin, spacing, count);
    const double mp = mass(p), Vp = fluidsVolume(volume(p), history(p));
    for (int k = 0; k < overlap.count; ++k) {
      const LocalOrdinal c = cells(overlap.cell[k][0], overlap.cell[k][1], overlap.cell[k][2]);
      if (c < 0) continue;  // cannot happen for a particle in an owned cell (ghost_width >= 1)
      const double w = overlap.share[k];
      out(c, touch) += 1.0;
      out(c, m) += w * mp;
      out(c, nm + m) += w * Vp;
      for (int d = 0; d < Dim; ++d) out(c, 2 * nm + m * Dim + d) += w * mp * velocity[d];
    }
    addMovedBox<Dim>(xp, lp, velocity, dt, Vp, origin, spacing, count, cells, out, predictedVolumeColumn(nm, m), touch);
    // Adds scale × (below, above) to the pair of columns from `column` (a face's sides) of the cells
    // at face f of direction d, in proportion to the particle's overlap w with each of them across d.
    const auto addToFace = [&](int column, int d, long long f, double scale, double below, double above) {
      overlap.acrossDirection(d, [&](long long ijk[3], double w) {
        ijk[d] = f;
        const LocalOrdinal c = cells(ijk[0], ijk[1], ijk[2]);
        if (c < 0) return;
        out(c, column) += w * scale * below;
        out(c, column + 1) += w * scale * above;
        out(c, touch) += 1.0;
      });
    };
    // The cover over the step, per side: the share of the face that the box covers in the step as
    // the solid would cross it from that side. Below the face (side 0): the box's cover of the band
    // just below the face as it moves up by |Δx| = Δt |ṽ_p| / h; above it (side 1): of the band just
    // above the face as it moves down by |Δx|. Inside a body both are 1; on a surface at rest on the
    // face, 1 on the body's side and 0 on the other; where a body's top leaves the face within the
    // step (a falling block), the side it leaves from holds the share of the step before it leaves;
    // where a surface reaches the face within the step, the share after it arrives. Where the solid
    // moves across the face the fluids' room on the donor's side is at least what this leaves open
    // (IceSolver::fluidFaceFractions).
    for (int d = 0; d < Dim; ++d) {
      const double lo = (xp[d] - lp[d] - origin[d]) / spacing[d], hi = (xp[d] + lp[d] - origin[d]) / spacing[d];
      const double reach = math::abs(dt * velocity[d] / spacing[d]);  // |Δx|, in cells
      const double band = kFaceBandAtRest * kFaceBandAtRest / (kFaceBandAtRest + kFaceBandNarrowing * reach);
      const double per_cover = Vp / ((hi - lo) * cell_volume);  // share of a face per lateral share w
      const long long first_face = (long long)math::floor(lo - reach - band);
      const long long last_face = (long long)math::floor(hi + reach + band) + 1;
      for (long long f = first_face; f <= last_face; ++f) {
        if (f < 1 || f > count[d] - 1) continue;  // domain faces are walls
        const double below = bandCoverOverStep(lo, hi, reach, f - band, double(f));
        const double above = bandCoverOverStep(lo, hi, -reach, double(f), f + band);
        if (below > 0 || above > 0) addToFace(roomColumn(nm, m, d, 0), d, f, per_cover, below, above);
      }
    }
    // Face shares: the particle's volume in the layers of width `layer` cells
    // (MpmOptions::face_layer) just below and just above each interior face its box reaches, per
    // volume of the layer. A moving rigid body's instead (both sides alike): the share of the face
    // itself that its box covers, averaged over the step as the box moves by Δt v. The layers count
    // a surface within a layer of a face as a partial cover, which is wrong both ways for a
    // prescribed motion: behind a body that leaves a face (the top of a plunger moving down) the
    // face stayed closed until the body was a layer past it, so the room it left had no way in;
    // ahead of a body that comes at a face, the fluid between them had to leave through the layer's
    // open part, ever faster as the gap closed. Averaged over the step, the open part is the time
    // the face is open, and the fluid crosses it at the body's speed either way.
    if (table.rigid[m] && table.rigid_moving[m]) {
      for (int d = 0; d < Dim; ++d) {
        const double lo = (xp[d] - lp[d] - origin[d]) / spacing[d], hi = (xp[d] + lp[d] - origin[d]) / spacing[d];
        const double shift = dt * velocity[d] / spacing[d];  // the box's displacement in the step, in cells
        const double per_cover = Vp / ((hi - lo) * cell_volume);  // share of a face per lateral share w
        const long long first_face = (long long)math::floor(math::min(lo, lo + shift));
        const long long last_face = (long long)math::floor(math::max(hi, hi + shift)) + 1;
        for (long long f = first_face; f <= last_face; ++f) {
          if (f < 1 || f > count[d] - 1) continue;  // domain faces are walls
          // Share of the step during which lo + shift τ <= f <= hi + shift τ (τ in [0, 1]).
          double time = 0;
          if (shift == 0.0) {
            time = lo <= f && f <= hi ? 1.0 : 0.0;
          } else {
            const double a = (f - hi) / shift, b = (f - lo) / shift;
            time = math::max(0.0, math::min(1.0, math::max(a, b)) - math::max(0.0, math::min(a, b)));
          }
          if (time > 0) addToFace(faceColumn(nm, m, d, 0), d, f, per_cover, time, time);
        }
      }
      return;
    }
    for (int d = 0; d < Dim; ++d) {
      const double lo = (xp[d] - lp[d] - origin[d]) / spacing[d], hi = (xp[d] + lp[d] - origin[d]) / spacing[d];
      const double per_length = Vp / ((hi - lo) * layer * cell_volume);
      const long long first_face = -(long long)math::floor(layer - lo), last_face = (long long)math::floor(hi + layer);
      for (long long f = first_face; f <= last_face; ++f) {
        if (f < 1 || f > count[d] - 1) continue;  // domain faces are walls
        const double below = math::max(0.0, math::min(hi, double(f)) - math::max(lo, f - layer));
        const double above = math::max(0.0, math::min(hi, f + layer) - math::max(lo, double(f)));
        if (below > 0 || above > 0) addToFace(faceColumn(nm, m, d, 0), d, f, per_length, below, above);
      }
    }
  };
  // Each particle adds into the cells around its own, within the reach of its node stencil: the
  // tile colouring of the particle-to-grid scatter keeps threads apart here too.
  scatterWithStationarySums("mpm::particles_to_cells", nodes, sums, stationary_cells_, scatter, touch);
  sums.sumToOwners();
}

template <int Dim>
template <class Kernel>
void MpmSolver<Dim>::addCellVelocityChangeWith(const Field<Dim>& change, Field<Dim>& target, bool commit)
{
  cellVelocityChangeToParticles(change);
  particleVelocityChangeToNodesWith<Kernel>(1.0);
  applyNodeMomentumChange(target, commit);
}

template <int Dim>
void MpmSolver<Dim>::applyNodeMomentumChange(Field<Dim>& target, bool commit)
{
  if (!node_momentum_change_) throw std::logic_error("MpmSolver: a node momentum change applied before it was made");
  if (commit && options_.move_before_coupling) {
    if (!node_velocity_moved_)
      node_velocity_moved_ = std::make_unique<Field<Dim>>(layout_, Location::Node, node_velocity_star_->columns(),
                                                          "mpm node velocity the particles move with");
    Kokkos::deep_copy(node_velocity_moved_->view(), node_velocity_star_->view());
  }
  const int nm = int(materials_.size());
  const MaterialTable table = materialTable(materials_);
  const NodeColumns col{std::max(1, nm), Dim};
  const auto dmv = node_momentum_change_->view();
  const GridConditions<Dim> conditions = gridConditions<Dim>(*layout_, materials_, options_, empty_node_mass_, wall_no_slip_);
  const auto sums = node_sums_->view();
  const auto velocity_star = node_velocity_star_->view();
  auto velocity_out = target.view();
  const bool record = commit && node_constraint_ != nullptr;  // only the MUSL re-map reads it
  auto constraint = record ? node_constraint_->view() : typename Field<Dim>::View();
  const double empty = empty_node_mass_;
  Kokkos::parallel_for(
      "mpm::add_cell_velocity_change", Kokkos::RangePolicy<ExecutionSpace>(0, node_sums_->overlapCount()),
      KOKKOS_LAMBDA(const int i) {
        double vs[kMaxMaterials][Dim], m[kMaxMaterials] = {};
        for (int a = 0; a < nm; ++a) {
          m[a] = sums(i, col.mass(a));
          for (int d = 0; d < Dim; ++d) {
            vs[a][d] = velocity_star(i, a * Dim + d);
            if (m[a] > empty && !table.rigid[a]) vs[a][d] += dmv(i, a * Dim + d) / m[a];
          }
        }
        int kind[kMaxMaterials];
        conditions.apply(i, sums, m, vs, kind);
        // A material held by the first pass (integrateGrid) has no approach left to remove unless
        // the change pushes it in again, so it counts as held if either pass held it.
        for (int a = 0; a < nm; ++a) {
          if (record) constraint(i, a) = math::max(constraint(i, a), double(kind[a]));
          for (int d = 0; d < Dim; ++d) velocity_out(i, a * Dim + d) = vs[a][d];
        }
      });
}

template <int Dim>
template <class Kernel>
void MpmSolver<Dim>::predictCellVolumesWith(const Field<Dim>& change, double dt, Field<Dim>& volumes)
{
  const int nm = int(materials_.size());
  if (volumes.columns() != nm)
    throw std::invalid_argument("MpmSolver::predictCellVolumes: the cell field needs " + std::to_string(nm) + " columns");
  if (!node_velocity_predicted_)
    node_velocity_predicted_ = std::make_unique<Field<Dim>>(layout_, Location::Node, node_velocity_star_->columns(),
                                                            "mpm node velocity of a predicted step");
  addCellVelocityChangeWith<Kernel>(change, *node_velocity_predicted_, false);
  volumes.fill(0.0);
  const Grid<Dim>& grid = layout_->grid();
  const MaterialTable table = materialTable(materials_);
  const auto x = particles_.position;
  const auto volume = particles_.volume;
  const auto half_width = particles_.half_width;
  const auto material = particles_.material;
  const auto history = particles_.state;
  const BoxLookup nodes = layout_->nodeLookup();
  const BoxLookup cells = layout_->cellLookup();
  const auto node_u = node_velocity_predicted_->view();
  const auto out = volumes.view();
  double origin[Dim], spacing[Dim];
  long long count[Dim];
  for (int d = 0; d < Dim; ++d)
    origin[d] = grid.lower()[d], spacing[d] = grid.spacing()[d], count[d] = grid.cells()[d];
  // The same position update as gridToParticlesWith (x_p += Δt Σ_i w_ip v_i, a rigid particle by
  // its prescribed velocity), into the boxes of particlesToCellsWith.
  const auto scatter = KOKKOS_LAMBDA(const int p)
  {
    const int m = material(p);
    double xp[Dim], lp[Dim], velocity[Dim];
    for (int d = 0; d < Dim; ++d) xp[d] = x(p, d), lp[d] = half_width(p, d);
    particleGridVelocity<Dim, Kernel>(xp, lp, m, table, origin, spacing, nodes, node_u, velocity);
    addMovedBox<Dim>(xp, lp, velocity, dt, fluidsVolume(volume(p), history(p)), origin, spacing, count, cells, out, m);
  };
  forEachParticleScattering("mpm::predict_cell_volumes", nodes, ParticleSet::All, scatter);
  volumes.sumToOwners();
}

/// The constitutive update, last in the step (USL or MUSL), with the velocity gradient of G2P. Dispatch on
/// the model happens once per material (SolidModel::visit); the kernel holds the concrete model.
template <int Dim>
void MpmSolver<Dim>::updateStress(double dt)
{
  const auto L = particles_.velocity_gradient;
  const auto F = particles_.deformation_gradient;
  const auto sigma = particles_.stress;
  const auto state = particles_.state;
  const auto material = particles_.material;
  const int n = particles_.count;

  // An inverted particle (det F <= 0) means the step was too large or the mesh too coarse.
  int inverted = n;
  reduceOverParticles(
      "mpm::check_jacobian", ParticleSet::Changing,
      KOKKOS_LAMBDA(const int p, int& first) {
        Mat<Dim> Fp;
        for (int d = 0; d < Dim; ++d)
          for (int e = 0; e < Dim; ++e) Fp(d, e) = F(p, d, e);
        if (!(determinant(Fp) > 0.0) && p < first) first = p;
      },
      Kokkos::Min<int>(inverted));
  if (inverted < n) {
    // Raised on every rank by the next relocateParticles (no collective here).
    std::ostringstream message;
    message.precision(10);
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.position);
    auto id = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.id);
    auto m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.material);
    message << "MPM: particle " << id(inverted) << " of material " << materials_[m(inverted)].name
            << " is inverted (det F <= 0) at (";
    for (int d = 0; d < Dim; ++d) message << (d ? ", " : "") << x(inverted, d);
    message << ") m; reduce the time step (rank " << layout_->comm()->getRank() << ")";
    if (pending_error_.empty()) pending_error_ = message.str();
  }

  const MaterialTable table = materialTable(materials_);
  for (int a = 0; a < int(materials_.size()); ++a) {
    if (table.stationary(a)) continue;  // a rigid body at rest: nothing to update
    materials_[a].model.visit([&](const auto& model) {
      forEachParticle(
          "mpm::stress_update", ParticleSet::Changing, KOKKOS_LAMBDA(const int p) {
            if (material(p) != a) return;
            StepKinematics<Dim> kinematics;
            Mat<Dim> stress;
            for (int d = 0; d < Dim; ++d)
              for (int e = 0; e < Dim; ++e) {
                kinematics.velocity_gradient(d, e) = L(p, d, e);
                kinematics.deformation_gradient(d, e) = F(p, d, e);
                stress(d, e) = sigma(p, d, e);
              }
            kinematics.dt = dt;
            MaterialState s = state(p);
            model.update(kinematics, s, stress);
            state(p) = s;
            for (int d = 0; d < Dim; ++d)
              for (int e = 0; e < Dim; ++e) sigma(p, d, e) = stress(d, e);
          });
    });
  }
}

template <int Dim>
MigrationCounts MpmSolver<Dim>::relocateParticles()
{
  const std::string error = pending_error_;
  pending_error_.clear();
  bins_current_ = false;
  MigrationCounts counts;
  if (stationary_placed_ && !everyParticleChanges()) {
    refreshChangingList();  // the particles of rigid bodies at rest have not moved since
    counts = (*migration_)(particles_, error, changing_, changing_count_);
  } else {
    counts = (*migration_)(particles_, error);
  }
  stationary_placed_ = true;
  if (counts.sent > 0 || counts.received > 0) changing_current_ = false;  // particles left, came or moved
  return counts;
}

// ---------------------------------------------------------------------------------------------
// Undoing a step
// ---------------------------------------------------------------------------------------------

template <int Dim>
void MpmSolver<Dim>::saveParticles(ParticleSnapshot& snapshot) const
{
  const Particles<Dim> particles = particles_;
  const int n = particles.count;
  if (int(snapshot.extent(0)) < n)
    snapshot = ParticleSnapshot("particle snapshot", std::size_t(n + n / 2), Particles<Dim>::kPackedSize);
  const ParticleSnapshot rows = snapshot;
  Kokkos::parallel_for(
      "mpm::saveParticles", Kokkos::RangePolicy<ExecutionSpace>(0, n),
      KOKKOS_LAMBDA(const int p) { particles.pack(p, &rows(p, 0)); });
}

template <int Dim>
void MpmSolver<Dim>::restoreParticles(const ParticleSnapshot& snapshot, int count)
{
  particles_.resize(count);
  const Particles<Dim> particles = particles_;
  Kokkos::parallel_for(
      "mpm::restoreParticles", Kokkos::RangePolicy<ExecutionSpace>(0, count),
      KOKKOS_LAMBDA(const int p) { particles.unpack(&snapshot(p, 0), p); });
  Kokkos::fence();
  pending_error_.clear();
  particlesChanged();
}

namespace {

constexpr const char* kParticleQuantities[] = {"position", "velocity", "volume", "deformation gradient",
                                               "stress", "out-of-plane stress", "plastic strain"};

/// The first quantity of particle p (index in kParticleQuantities) that is not finite, or -1.
template <int Dim>
KOKKOS_INLINE_FUNCTION int nonFiniteQuantity(const Particles<Dim>& particles, int p)
{
  using Kokkos::Experimental::isfinite;
  for (int d = 0; d < Dim; ++d)
    if (!isfinite(particles.position(p, d))) return 0;
  for (int d = 0; d < Dim; ++d)
    if (!isfinite(particles.velocity(p, d))) return 1;
  if (!isfinite(particles.volume(p))) return 2;
  for (int d = 0; d < Dim; ++d)
    for (int e = 0; e < Dim; ++e)
      if (!isfinite(particles.deformation_gradient(p, d, e))) return 3;
  for (int d = 0; d < Dim; ++d)
    for (int e = 0; e < Dim; ++e)
      if (!isfinite(particles.stress(p, d, e))) return 4;
  const MaterialState state = particles.state(p);
  if (!isfinite(state.out_of_plane_stress)) return 5;
  if (!isfinite(state.equivalent_plastic_strain) || !isfinite(state.volumetric_plastic_strain)) return 6;
  return -1;
}

}  // namespace

template <int Dim>
std::string MpmSolver<Dim>::nonFiniteParticle() const
{
  const Particles<Dim> particles = particles_;
  const int n = particles.count;
  long long lowest = LLONG_MAX, global_lowest = LLONG_MAX;
  // A particle a step does not change stays as it was seeded (or restored, and then checked).
  reduceOverParticles(
      "mpm::nonFiniteParticle", ParticleSet::Changing,
      KOKKOS_LAMBDA(const int p, long long& found) {
        if (nonFiniteQuantity(particles, p) >= 0 && particles.id(p) < found) found = particles.id(p);
      },
      Kokkos::Min<long long>(lowest));
  const auto& comm = *layout_->comm();
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, lowest, Teuchos::outArg(global_lowest));
  if (global_lowest == LLONG_MAX) return "";
  const int ranks = comm.getSize();
  const int reporter = lowest == global_lowest ? comm.getRank() : ranks;
  int first_reporter = ranks;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, reporter, Teuchos::outArg(first_reporter));
  std::string message;
  if (reporter == first_reporter) {
    // The particle's packed row on the host, and the quantity found.
    Kokkos::View<double*, MemorySpace> row("non-finite particle", Particles<Dim>::kPackedSize);
    Kokkos::View<int, MemorySpace> quantity("non-finite quantity");
    Kokkos::parallel_for(
        "mpm::describeParticle", Kokkos::RangePolicy<ExecutionSpace>(0, n), KOKKOS_LAMBDA(const int p) {
          if (particles.id(p) != global_lowest) return;
          particles.pack(p, row.data());
          quantity() = nonFiniteQuantity(particles, p);
        });
    const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), row);
    int q = 0;
    Kokkos::deep_copy(q, quantity);
    const int material = int(host(Particles<Dim>::kPackedSize - 2));
    std::ostringstream text;
    text.precision(10);
    text << "MPM: particle " << global_lowest << " of material " << materials_[material].name << " at (";
    for (int d = 0; d < Dim; ++d) text << (d ? ", " : "") << host(d);
    text << ") m: its " << kParticleQuantities[q] << " is not finite";
    message = text.str();
  }
  return broadcastText(rawMpiComm(layout_->comm()), first_reporter, message);
}

// ---------------------------------------------------------------------------------------------
// Time step and diagnostics
// ---------------------------------------------------------------------------------------------

/// dt = cfl h_min / max_p (c_p + |v_p|), with c_p the material's dilatational wave speed at the
/// particle's current density m_p / V_p.
template <int Dim>
MpmTimeStep MpmSolver<Dim>::stableTimeStep() const
{
  const Grid<Dim>& grid = layout_->grid();
  double h_min = grid.spacing()[0];
  for (int d = 1; d < Dim; ++d) h_min = std::min(h_min, grid.spacing()[d]);
  const auto v = particles_.velocity;
  const auto mass = particles_.mass;
  const auto volume = particles_.volume;
  const auto material = particles_.material;
  const MaterialTable table = materialTable(materials_);

  using MaxLoc = Kokkos::MaxLoc<double, int>;
  // Largest signal speed c + |v| (>= 0) and its particle; the reducer starts from -DBL_MAX.
  double fastest_value = -1.0;
  int fastest_particle = -1, fastest_material = -1;
  for (int a = 0; a < int(materials_.size()); ++a) {
    if (table.stationary(a)) continue;  // a rigid body at rest has no signal speed
    typename MaxLoc::value_type found;
    materials_[a].model.visit([&](const auto& model) {
      reduceOverParticles(
          "mpm::signal_speed", ParticleSet::Changing,
          KOKKOS_LAMBDA(const int p, typename MaxLoc::value_type& best) {
            if (material(p) != a) return;
            double speed2 = 0.0;
            for (int d = 0; d < Dim; ++d) speed2 += v(p, d) * v(p, d);
            const double signal = model.waveSpeed(mass(p) / volume(p)) + math::sqrt(speed2);
            if (signal > best.val) best.val = signal, best.loc = p;
          },
          MaxLoc(found));
    });
    if (found.val >= 0.0 && found.val > fastest_value)
      fastest_value = found.val, fastest_particle = found.loc, fastest_material = a;
  }

  // The global maximum and the rank that holds it, which then tells the others what limits.
  struct {
    double value;
    int rank;
  } local{fastest_value, layout_->comm()->getRank()}, global{};
  const MPI_Comm comm = rawMpiComm(layout_->comm());
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm);
  double info[3] = {0.0, 0.0, -1.0};  // wave speed, speed, material
  if (global.rank == layout_->comm()->getRank() && fastest_particle >= 0) {
    const int p = fastest_particle;
    auto vh = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.velocity);
    double speed2 = 0.0;
    for (int d = 0; d < Dim; ++d) speed2 += vh(p, d) * vh(p, d);
    info[1] = std::sqrt(speed2);
    info[0] = fastest_value - info[1];
    info[2] = fastest_material;
  }
  MPI_Bcast(info, 3, MPI_DOUBLE, global.rank, comm);

  MpmTimeStep result;
  result.dt = global.value > 0.0 ? cfl_ * h_min / global.value : std::numeric_limits<double>::infinity();
  result.wave_speed = info[0];
  result.speed = info[1];
  if (info[2] >= 0) result.material = materials_[int(info[2])].name;
  return result;
}

template <int Dim>
long long MpmSolver<Dim>::particleCount() const
{
  long long local = particles_.count, total = 0;
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, local, Teuchos::outArg(total));
  return total;
}

template <int Dim>
std::vector<long long> MpmSolver<Dim>::particlesPerPatch() const
{
  const Grid<Dim>& grid = layout_->grid();
  const int patches = grid.patchCount();
  Kokkos::View<long long*, MemorySpace> counts("particles per patch", std::size_t(patches));
  const auto position = particles_.position;
  const Box first_patch = grid.patchCells(0);  // patches are full size except the last per direction
  double lower[Dim], spacing[Dim];
  long long cells[Dim], patch_cells[Dim], patch_counts[Dim];
  for (int d = 0; d < Dim; ++d) {
    lower[d] = grid.lower()[d], spacing[d] = grid.spacing()[d], cells[d] = grid.cells()[d];
    patch_cells[d] = first_patch.extent(d), patch_counts[d] = grid.patchCounts()[d];
  }
  // The particles of rigid materials at rest are passed over by the step's loops, and with
  // stationary_sums_once their sums are copied in: they are not counted then.
  const ParticleSet set = options_.stationary_sums_once ? ParticleSet::Changing : ParticleSet::All;
  forEachParticle("mpm::particlesPerPatch", set, KOKKOS_LAMBDA(const int p) {
        long long patch = 0, stride = 1;
        for (int d = 0; d < Dim; ++d) {
          // Between steps every particle is inside the domain (relocateParticles checked it).
          long long c = static_cast<long long>(math::floor((position(p, d) - lower[d]) / spacing[d]));
          c = c < 0 ? 0 : (c >= cells[d] ? cells[d] - 1 : c);
          patch += (c / patch_cells[d]) * stride;
          stride *= patch_counts[d];
        }
        Kokkos::atomic_add(&counts(patch), 1LL);
      });
  const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), counts);
  std::vector<long long> local(host.data(), host.data() + patches), total(std::size_t(patches), 0);
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, patches, local.data(), total.data());
  return total;
}

template <int Dim>
std::vector<double> MpmSolver<Dim>::materialMasses() const
{
  const int nm = int(materials_.size());
  std::vector<double> local(nm, 0.0), total(nm, 0.0);
  const auto mass = particles_.mass;
  const auto material = particles_.material;
  for (int a = 0; a < nm; ++a)
    Kokkos::parallel_reduce(
        "mpm::material_mass", Kokkos::RangePolicy<ExecutionSpace>(0, particles_.count),
        KOKKOS_LAMBDA(const int p, double& sum) {
          if (material(p) == a) sum += mass(p);
        },
        local[a]);
  if (nm > 0) Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, nm, local.data(), total.data());
  return total;
}

template <int Dim>
double MpmSolver<Dim>::kineticEnergy() const
{
  const auto mass = particles_.mass;
  const auto v = particles_.velocity;
  double local = 0.0, total = 0.0;
  Kokkos::parallel_reduce(
      "mpm::kinetic_energy", Kokkos::RangePolicy<ExecutionSpace>(0, particles_.count),
      KOKKOS_LAMBDA(const int p, double& sum) {
        double v2 = 0.0;
        for (int d = 0; d < Dim; ++d) v2 += v(p, d) * v(p, d);
        sum += 0.5 * mass(p) * v2;
      },
      local);
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, local, Teuchos::outArg(total));
  return total;
}

template <int Dim>
std::array<double, 3> MpmSolver<Dim>::momentum() const
{
  const auto mass = particles_.mass;
  const auto v = particles_.velocity;
  double local[3] = {0, 0, 0};
  std::array<double, 3> total{0, 0, 0};
  for (int d = 0; d < Dim; ++d)
    Kokkos::parallel_reduce(
        "mpm::momentum", Kokkos::RangePolicy<ExecutionSpace>(0, particles_.count),
        KOKKOS_LAMBDA(const int p, double& sum) { sum += mass(p) * v(p, d); }, local[d]);
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, 3, local, total.data());
  return total;
}

template <int Dim>
ParticleOutput MpmSolver<Dim>::output() const
{
  const int n = particles_.count;
  ParticleOutput out;
  out.dimension = Dim;
  out.count = std::size_t(n);
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.position);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.velocity);
  auto sigma = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.stress);
  auto state = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.state);
  auto mass = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.mass);
  auto volume = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.volume);
  auto material = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.material);
  auto id = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles_.id);
  out.position.reserve(n * Dim);
  out.velocity.reserve(n * Dim);
  out.stress.assign(std::size_t(n) * 9, 0.0);
  for (int p = 0; p < n; ++p) {
    for (int d = 0; d < Dim; ++d) {
      out.position.push_back(x(p, d));
      out.velocity.push_back(v(p, d));
      for (int e = 0; e < Dim; ++e) out.stress[p * 9 + 3 * d + e] = sigma(p, d, e);
    }
    if (Dim == 2) out.stress[p * 9 + 8] = state(p).out_of_plane_stress;
    out.plastic_strain.push_back(state(p).equivalent_plastic_strain);
    out.mass.push_back(mass(p));
    out.volume.push_back(volume(p));
    out.material.push_back(materials_[material(p)].scene_index);
    out.id.push_back(id(p));
  }
  return out;
}

MpmOptions optionsFromScene(const Scene& scene)
{
  MpmOptions options;
  options.shape_function = scene.mpm.shape_function == "linear" ? ShapeFunction::Linear : ShapeFunction::Gimp;
  options.flip_fraction = scene.mpm.flip_fraction;
  options.stress_update = scene.mpm.stress_update == "musl" ? StressUpdate::ModifiedLast : StressUpdate::Last;
  options.wall_friction = scene.mpm.wall_friction;
  options.contact = scene.mpm.contact;
  options.contact_friction = scene.mpm.contact_friction;
  options.velocity_damping = scene.mpm.velocity_damping;
  options.face_layer = scene.mpm.face_layer;
  options.move_before_coupling = scene.mpm.coupling == "staggered";
  return options;
}

template class MpmSolver<2>;
template class MpmSolver<3>;

}  // namespace cfdmpm::mpm
