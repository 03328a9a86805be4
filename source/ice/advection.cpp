// Advection kernels. One step, per material (doc/ice-advection.md), two passes over the cells:
//   1. the slabs, owned cells and the first ghost layer (so that every owned face has its donor):
//      each cell's limited linear mass profile gives the mass leaving through each face, then the
//      slab values of every mass-specific column of every field (the slab geometry and the
//      remaining mass are computed once per cell and material). The same pass is the outflow
//      check: Σ_faces V_out <= V_cell in every owned cell, or the step is refused (a reduction,
//      which also finds the cell of the maximum); it writes only work arrays, so a refused step
//      leaves the fields as they were;
//   2. one pass over the owned cells writes the new mass and the new q of every column in place
//      (it reads other cells only through the slab arrays); ghosts of the outputs refreshed.
#include "ice/advection.hpp"

#include <Teuchos_CommHelpers.hpp>

#include <cfloat>
#include <climits>
#include <sstream>
#include <stdexcept>

namespace cfdmpm {

namespace {

/// What a kernel needs of the grid around a cell: face neighbours, the 3^Dim block, spacing.
template <int Dim>
struct CellStencil {
  typename Layout<Dim>::IndexTable neighbours;  // (cell, face) -> local id, < 0 if none
  typename Layout<Dim>::IjkTable ijk;           // (cell, d) -> global index
  Kokkos::View<const LocalOrdinal**, MemorySpace> block;  // (cell, k) -> local id of the 3^Dim block
  double spacing[3] = {1, 1, 1};
  double inverse_spacing[3] = {1, 1, 1};
  long long cells[3] = {1, 1, 1};

  CellStencil(const Layout<Dim>& layout, const Kokkos::View<LocalOrdinal**, MemorySpace>& block_table)
      : neighbours(layout.cellNeighbours()), ijk(layout.cellIndex()), block(block_table)
  {
    for (int d = 0; d < 3; ++d) {
      spacing[d] = layout.grid().spacing()[d];
      inverse_spacing[d] = 1.0 / spacing[d];
      cells[d] = layout.grid().cells()[d];
    }
  }

  KOKKOS_INLINE_FUNCTION long long globalId(int c) const
  {
    const long long k = Dim == 3 ? ijk(c, Dim - 1) : 0;
    return ijk(c, 0) + cells[0] * (ijk(c, 1) + cells[1] * k);
  }

  static constexpr int kBlock = Dim == 2 ? 9 : 27;

  /// The ids of cell c's neighbours (face f) and of its 3^Dim block, read once per cell by the
  /// kernels and passed to the functions below.
  struct Local {
    LocalOrdinal neighbour[2 * Dim];
    LocalOrdinal block[kBlock];
  };
  KOKKOS_INLINE_FUNCTION Local local(int c) const
  {
    Local l;
    for (int f = 0; f < 2 * Dim; ++f) l.neighbour[f] = neighbours(c, f);
    for (int k = 0; k < kBlock; ++k) l.block[k] = block(c, k);
    return l;
  }

  /// Minimum and maximum of column `col` over the cell and its 3^Dim - 1 neighbours (diagonals
  /// included) that are inside the domain and held by this rank (the block table names the cell
  /// itself in place of the others, which leaves the bounds as they are).
  template <class View>
  KOKKOS_INLINE_FUNCTION void blockBounds(const View& v, int c, const Local& l, int col, double& lo,
                                          double& hi) const
  {
    lo = hi = v(c, col);
    for (int k = 0; k < kBlock; ++k) {
      const double value = v(l.block[k], col);
      lo = value < lo ? value : lo;
      hi = value > hi ? value : hi;
    }
  }

  /// Unlimited gradient of column `col` in direction d: central difference, one-sided next to a
  /// wall (or the edge of the ghost layers), zero with no neighbour in d.
  template <class View>
  KOKKOS_INLINE_FUNCTION double gradient(const View& v, int c, const Local& l, int col, int d) const
  {
    const LocalOrdinal lower = l.neighbour[2 * d], upper = l.neighbour[2 * d + 1];
    if (lower >= 0 && upper >= 0) return (v(upper, col) - v(lower, col)) * (0.5 * inverse_spacing[d]);
    if (upper >= 0) return (v(upper, col) - v(c, col)) * inverse_spacing[d];
    if (lower >= 0) return (v(c, col) - v(lower, col)) * inverse_spacing[d];
    return 0.0;
  }
};

/// The face velocities of one step and the outflow slabs they cut from each cell.
template <int Dim>
struct Slabs {
  typename Field<Dim>::ConstView velocity[Dim];  // (cell, material): lower face of the cell
  double spacing[3] = {1, 1, 1};
  double dt = 0;
  bool transverse = true;

  Slabs(const FaceField<Dim>& face_velocity, const Layout<Dim>& layout, double time_step, bool transverse_correction)
      : dt(time_step), transverse(transverse_correction)
  {
    for (int d = 0; d < Dim; ++d) velocity[d] = face_velocity.direction(d).view();
    for (int d = 0; d < 3; ++d) spacing[d] = layout.grid().spacing()[d];
  }

  /// Velocity through face f = 2 d + side of cell c, positive along +d; n: the neighbour across f.
  /// Domain faces are walls; a face beyond the ghost layers is unknown and treated as closed (such
  /// cells are never donors for an owned cell's faces).
  KOKKOS_INLINE_FUNCTION double normalVelocity(int c, int f, int m, LocalOrdinal n) const
  {
    const int d = f / 2;
    if (f % 2 == 0) return n == Layout<Dim>::kOutsideDomain ? 0.0 : velocity[d](c, m);
    return n >= 0 ? velocity[d](n, m) : 0.0;
  }

  /// Σ_faces V_out / V_cell: more than 1 empties the cell in one step. neighbour[f]: the cell's
  /// neighbour across face f.
  KOKKOS_INLINE_FUNCTION double totalOutflowFraction(int c, int m, const LocalOrdinal neighbour[2 * Dim]) const
  {
    double total = 0;
    for (int f = 0; f < 2 * Dim; ++f) {
      const double u = normalVelocity(c, f, m, neighbour[f]);
      const double outward = f % 2 == 0 ? -u : u;
      total += outward > 0 ? outward * dt / spacing[f / 2] : 0.0;
    }
    return total;
  }

  /// For every face f of cell c and material m: the outflow fraction V_out / V_cell and the
  /// offset r[f] from the cell centre to the centroid of the outflow slab. Normal to the face: the
  /// slab of thickness |u|Δt against the face. Along the face: the donor's mean transverse velocity
  /// times -Δt/2 (the swept region's centroid). The cell's 2 Dim face velocities are read once.
  /// neighbour[f]: the cell's neighbour across face f.
  KOKKOS_INLINE_FUNCTION void cellSlabs(int c, int m, const LocalOrdinal neighbour[2 * Dim], double fraction[2 * Dim],
                                        double r[2 * Dim][Dim]) const
  {
    double u[2 * Dim];
    for (int f = 0; f < 2 * Dim; ++f) u[f] = normalVelocity(c, f, m, neighbour[f]);
    for (int f = 0; f < 2 * Dim; ++f) {
      const int d = f / 2;
      const double outward = f % 2 == 0 ? -u[f] : u[f];
      fraction[f] = outward > 0 ? outward * dt / spacing[d] : 0.0;
      for (int e = 0; e < Dim; ++e) {
        if (e == d) r[f][e] = (f % 2 == 0 ? -0.5 : 0.5) * spacing[d] * (1.0 - fraction[f]);
        else if (transverse) r[f][e] = -0.5 * dt * (0.5 * (u[2 * e] + u[2 * e + 1]));
        else r[f][e] = 0.0;
      }
    }
  }
};

/// Kokkos reducer of LargestOutflow (the slab kernel is a parallel_reduce with it).
struct LargestOutflowReducer {
  using reducer = LargestOutflowReducer;
  using value_type = LargestOutflow;
  using result_view_type = Kokkos::View<value_type, Kokkos::HostSpace, Kokkos::MemoryUnmanaged>;

  explicit LargestOutflowReducer(value_type& result) : result_(&result) {}
  KOKKOS_INLINE_FUNCTION void join(volatile value_type& best, const volatile value_type& other) const
  {
    value_type joined{best.value, best.key};
    joined.include(other.value, other.key);
    best.value = joined.value, best.key = joined.key;
  }
  KOKKOS_INLINE_FUNCTION void init(value_type& best) const
  {
    best.value = -DBL_MAX;
    best.key = LLONG_MAX;
  }
  KOKKOS_INLINE_FUNCTION value_type& reference() const { return *result_; }
  result_view_type view() const { return result_view_type(result_); }
  KOKKOS_INLINE_FUNCTION bool references_scalar() const { return true; }

 private:
  value_type* result_;
};

/// The limiter factor in [0, 1] for a linear profile value + φ g·r in one cell.
/// 1. Barth–Jespersen: the profile stays within [lo, hi] (the cell's 3^Dim block) everywhere in the
///    cell; `spread` = Σ_d |g_d| Δx_d / 2 is the largest excursion from the centre value.
/// 2. Remainder bound: what stays in the cell after the outflow slabs leave has the mean
///    value - φ·S / remaining, which must also lie within [lo, hi]; S = Σ_out w_f g·r_f with the
///    slabs' weights w_f, and `remaining` = weight left in the cell (>= 0).
KOKKOS_INLINE_FUNCTION double limiter(double value, double lo, double hi, double spread, double remaining,
                                      double S)
{
  // The smallest of 1, room / spread and bound / |S|, with one division: each candidate is a
  // quotient a / b with b > 0, compared with the others by cross-multiplication.
  double a = 1.0, b = 1.0;
  if (spread > 0) {
    const double room = (hi - value < value - lo ? hi - value : value - lo);
    if (room < spread) a = room, b = spread;
  }
  if (S != 0) {
    const double bound = S > 0 ? remaining * (value - lo) : remaining * (hi - value);
    const double size = S > 0 ? S : -S;
    if (bound * b < a * size) a = bound, b = size;
  }
  return a > 0 ? a / b : 0.0;
}

}  // namespace

std::string AdvectionStatus::message() const
{
  std::ostringstream s;
  s << "advection: " << (ok ? "ok" : "refused") << ", largest outflux volume / cell volume "
    << max_outflux_fraction << " in cell " << cell << ", material " << material;
  if (!ok) s << " (must be <= 1: reduce the time step)";
  return s.str();
}

template <int Dim>
Advector<Dim>::Advector(std::shared_ptr<const Layout<Dim>> layout, int materials, Options options)
    : layout_(std::move(layout)), materials_(materials), options_(options)
{
  if (materials < 1) throw std::invalid_argument("Advector: needs at least one material");
  // An owned cell's face may have a ghost donor, whose gradient and limiter read one cell further.
  if (layout_->ghostWidth() < 2)
    throw std::invalid_argument("Advector: needs ghost width >= 2, the layout has " +
                                std::to_string(layout_->ghostWidth()));
  const LocalOrdinal cells = layout_->overlapCells();
  constexpr int kBlock = Dim == 2 ? 9 : 27;
  block_ = Kokkos::View<LocalOrdinal**, MemorySpace>("advection block", cells, kBlock);
  const auto block = block_;
  const auto ijk = layout_->cellIndex();
  const BoxLookup lookup = layout_->cellLookup();
  Kokkos::parallel_for(
      "advection block table", Kokkos::RangePolicy<ExecutionSpace>(0, cells), KOKKOS_LAMBDA(const LocalOrdinal c) {
        const long long i = ijk(c, 0), j = ijk(c, 1), k = Dim == 3 ? ijk(c, Dim - 1) : 0;
        const int kw = Dim == 3 ? 1 : 0;
        int slot = 0;
        for (int dk = -kw; dk <= kw; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const LocalOrdinal n = lookup(i + di, j + dj, k + dk);
              block(c, slot++) = n >= 0 ? n : c;  // none there: the cell itself (no branch in the bounds)
            }
      });
  outflow_mass_ = WorkView("advection outflow mass", cells, 2 * Dim, materials);
}

/// The status of a step whose slab pass found `local` on this rank: the maximum over all ranks, and
/// the lowest global key that attains it, so every rank count reports the same cell.
template <int Dim>
AdvectionStatus Advector<Dim>::outfluxStatus(const LargestOutflow& local) const
{
  AdvectionStatus status;
  const auto& comm = *layout_->comm();
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MAX, local.value, Teuchos::outArg(status.max_outflux_fraction));
  const long long local_first = local.value == status.max_outflux_fraction ? local.key : LLONG_MAX;
  long long first = LLONG_MAX;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, local_first, Teuchos::outArg(first));
  if (first != LLONG_MAX) {
    status.cell = first / materials_;
    status.material = int(first % materials_);
  }
  status.ok = status.max_outflux_fraction <= 1.0;
  return status;
}

template <int Dim>
AdvectionStatus Advector<Dim>::advect(FaceField<Dim>& face_velocity, double dt, Field<Dim>& mass,
                                      const std::vector<Field<Dim>*>& mass_specific, const CapView& outflow_share,
                                      const FractionView& volume_fraction)
{
  if (mass.columns() != materials_)
    throw std::invalid_argument("Advector: mass has " + std::to_string(mass.columns()) + " columns, expected " +
                                std::to_string(materials_));
  for (const Field<Dim>* q : mass_specific)
    if (q->columns() % materials_ != 0)
      throw std::invalid_argument("Advector: " + q->name() + " has " + std::to_string(q->columns()) +
                                  " columns, not a multiple of " + std::to_string(materials_) + " materials");
  if (int(mass_specific.size()) > kMaxFields)
    throw std::invalid_argument("Advector: at most " + std::to_string(kMaxFields) + " mass-specific fields, got " +
                                std::to_string(mass_specific.size()));

  // 1. Ghosts of every input are current: fluxes on an owned cell's faces may come from a ghost
  //    donor, whose reconstruction reads the ghosts beyond it.
  face_velocity.exchangeHalo();
  mass.exchangeHalo();
  for (Field<Dim>* q : mass_specific) q->exchangeHalo();

  // 2. Mass leaving each cell through each face, from the limited density profile of the donor,
  //    and the slab values of every mass-specific column, in one pass that also checks the outflow.
  const AdvectionStatus status =
      outfluxStatus(reconstruct(face_velocity, dt, mass, mass_specific, false, outflow_share, CellMask(), volume_fraction));
  if (!status.ok) return status;

  // 3. New mass and compatible update of every column, then the outputs' ghosts.
  update(mass, mass_specific);
  mass.exchangeHalo();
  for (Field<Dim>* q : mass_specific) q->exchangeHalo();
  return status;
}

namespace {

/// The mass-specific fields of one advect() call as the kernels see them: field i has `width[i]`
/// columns per material, and its column m·width + j is column `first[i] + m·width + j` of the
/// slab arrays.
template <int Dim, class View, int kMaxFields>
struct QuantityColumns {
  Kokkos::Array<View, kMaxFields> field;
  int width[kMaxFields] = {};
  int first[kMaxFields] = {};
  int fields = 0;
  int total = 0;  // columns of the slab arrays
};

template <int Dim, int kMaxFields, class View, class FieldPointer>
QuantityColumns<Dim, View, kMaxFields> quantityColumns(const std::vector<FieldPointer>& mass_specific, int materials)
{
  QuantityColumns<Dim, View, kMaxFields> q;
  for (const FieldPointer field : mass_specific) {
    q.field[q.fields] = field->view();
    q.width[q.fields] = field->columns() / materials;
    q.first[q.fields] = q.total;
    q.total += field->columns();
    ++q.fields;
  }
  return q;
}

}  // namespace

template <int Dim>
const typename Advector<Dim>::WorkView& Advector<Dim>::slabDensities(const FaceField<Dim>& face_velocity, double dt,
                                                                     const Field<Dim>& mass, const CellMask& skip)
{
  if (slab_density_.extent(0) == 0)
    slab_density_ = WorkView("advection slab density", layout_->overlapCells(), 2 * Dim, materials_);
  reconstruct(face_velocity, dt, mass, {}, true, CapView(), skip);
  return slab_density_;
}

template <int Dim>
LargestOutflow Advector<Dim>::reconstruct(const FaceField<Dim>& face_velocity, double dt, const Field<Dim>& mass,
                                          const std::vector<Field<Dim>*>& mass_specific, bool slab_densities,
                                          const CapView& outflow_share, const CellMask& skip,
                                          const FractionView& volume_fraction)
{
  const bool capped = outflow_share.extent(0) > 0;
  // Traces leave whole (advect): only where the slabs are capped, which keeps their mass >= 0.
  const bool traces = capped && volume_fraction.extent(0) > 0;
  const Slabs<Dim> slabs(face_velocity, *layout_, dt, options_.transverse_correction);
  const CellStencil<Dim> stencil(*layout_, block_);
  const auto M = mass.view();
  const auto q = quantityColumns<Dim, kMaxFields, typename Field<Dim>::ConstView>(
      std::vector<const Field<Dim>*>(mass_specific.begin(), mass_specific.end()), materials_);
  const LocalOrdinal cells = layout_->overlapCells();
  if (q.total > 0 &&
      (outflow_value_.extent(0) != std::size_t(cells) || outflow_value_.extent(2) < std::size_t(q.total))) {
    outflow_value_ = WorkView("advection outflow value", cells, 2 * Dim, q.total);
    bounds_ = WorkView("advection bounds", cells, q.total, 2);
  }
  const auto outflow_mass = outflow_mass_;
  const auto outflow_value = outflow_value_;
  const auto bounds = bounds_;
  const auto slab_density = slab_density_;
  const int materials = materials_;
  const unsigned held = options_.held_materials;
  const LocalOrdinal owned = layout_->ownedCells();
  const auto closed = options_.closed_cells;
  const bool any_closed = closed.extent(0) > 0;
  const bool skipping = skip.extent(0) > 0;
  constexpr double kTrace = kTraceFraction;

  // Per cell (owned and ghost, so that every owned face has its donor) and material, the slab
  // geometry from the cell's 2 Dim face velocities, then:
  // - the mass slabs: the linear profile M + φ g·r of the cell's mass (the density times V_cell);
  //   a slab of fraction w = V_out / V_cell carries F = w·(M + φ g·r_f) (Uintah's
  //   SecondOrderAdvector with compatible fluxes; the remainder bound keeps the mass left behind
  //   >= 0 at any outflow Courant number <= 1);
  // - the same for every column q, whose slabs weigh their mass F_f: the limited profile keeps q
  //   within its block bounds in the slabs and in the mass left behind, so the new q is a
  //   mass-weighted mean of values within bounds (compatible fluxes).
  // Both read the old mass and the cell's own slabs only. Owned cells also enter the largest
  // outflow fraction Σ_f V_out / V_cell of every material, with or without mass, but for a trace
  // (below kTraceFraction of the cell, where volume fractions are given).
  LargestOutflow largest;
  Kokkos::parallel_reduce(
      "advection slabs", Kokkos::RangePolicy<ExecutionSpace>(0, cells),
      KOKKOS_LAMBDA(int c, LargestOutflow& best) {
        if (skipping && skip(c)) return;  // (slabDensities: not read)
        if (any_closed && closed(c)) {
          // Nothing leaves; update() skips the cell. Its slabs are zero (its faces' velocities are).
          for (int m = 0; m < materials; ++m)
            for (int f = 0; f < 2 * Dim; ++f) {
              outflow_mass(c, f, m) = 0.0;
              if (slab_densities) slab_density(c, f, m) = 0.0;
            }
          return;
        }
        const auto local = stencil.local(c);
        for (int m = 0; m < materials; ++m) {
          // A held material: update() skips it and its slab densities keep their initial 0.
          if (held >> m & 1u) continue;
          // Whether its outflow enters the largest outflow fraction: an owned cell, not a trace.
          const bool counted = c < owned && !(traces && volume_fraction(c, m) < kTrace);
          if (!(M(c, m) > 0.0)) {
            if (counted)
              best.include(slabs.totalOutflowFraction(c, m, local.neighbour), stencil.globalId(c) * materials + m);
            // No mass of m here: nothing leaves (the block's lower bound is 0 and the limiter sets
            // the slope to 0: every slab would carry exactly 0). The slab values then weigh
            // nothing; only the block bounds of q are needed, to bound q where mass flows in,
            // which needs a face neighbour with mass (update() skips the rest).
            // A mass below zero (round-off where a donor gave all of it, ~1e-17 of a cell's water,
            // 1e-60 of its air) sends nothing either; inflow brings it back. Sent, it was negative
            // mass that the room beside a solid multiplied (outflow_share up to 1 / kFillMinimum
            // of the profile, and the bound below holds only for positive masses): the donor then
            // held positive mass out of nothing and its receiver more negative mass, which grew
            // step by step. In the slide with two particle steps per step (5 mm) a trace of air
            // went from -7e-16 to -0.07 of a cell between 0.6 and 0.68 s under 0.6 m of water,
            // and its outflux refused every retried step.
            bool inflow_possible = false;
            for (int f = 0; f < 2 * Dim; ++f) {
              outflow_mass(c, f, m) = 0.0;
              if (slab_densities) slab_density(c, f, m) = 0.0;
              const LocalOrdinal n = local.neighbour[f];
              inflow_possible = inflow_possible || (n >= 0 && M(n, m) > 0.0);
            }
            if (!inflow_possible) continue;
            for (int field = 0; field < q.fields; ++field)
              for (int j = 0; j < q.width[field]; ++j) {
                const int col = m * q.width[field] + j, slot = q.first[field] + col;
                stencil.blockBounds(q.field[field], c, local, col, bounds(c, slot, 0), bounds(c, slot, 1));
              }
            continue;
          }
          double fraction[2 * Dim], r[2 * Dim][Dim];
          slabs.cellSlabs(c, m, local.neighbour, fraction, r);
          if (counted) {
            double total = 0;
            for (int f = 0; f < 2 * Dim; ++f) total += fraction[f];
            best.include(total, stencil.globalId(c) * materials + m);
          }
          double g[Dim], spread = 0;
          for (int d = 0; d < Dim; ++d) {
            g[d] = stencil.gradient(M, c, local, m, d);
            spread += 0.5 * (g[d] < 0 ? -g[d] : g[d]) * stencil.spacing[d];
          }
          double slope[2 * Dim];  // g·r_f
          double remaining = 1.0, S = 0.0;
          for (int f = 0; f < 2 * Dim; ++f) {
            slope[f] = 0;
            for (int d = 0; d < Dim; ++d) slope[f] += g[d] * r[f][d];
            remaining -= fraction[f];
            S += fraction[f] * slope[f];
          }
          double lo, hi;
          stencil.blockBounds(M, c, local, m, lo, hi);
          const double value = M(c, m);
          // Slabs that together sweep more than the cell (a trace that leaves whole, advect()) take
          // the cell's mean, not its linear profile: evaluated beyond the cell the profile of a
          // trace next to more of it went below zero on one face and sent negative mass (a water
          // trace of a slide in air at 10 mm left -1.3e-5 kg/m^3 in its receiver and +1.3e-5 in
          // itself, which the face's density-weighted mean then divided by zero).
          const bool whole = remaining < 0;
          const double phi = whole ? 0.0 : limiter(value, lo, hi, spread, remaining > 0 ? remaining : 0.0, S);
          double slab_mass[2 * Dim];
          double left = value;  // the mass that stays in the cell
          double leaving = 0;
          for (int f = 0; f < 2 * Dim; ++f) {
            slab_mass[f] = fraction[f] * (value + phi * slope[f]) * (capped ? outflow_share(c, f) : 1.0);
            leaving += slab_mass[f];
          }
          // Next to a solid the fluids fill the room it leaves on a face (a share above 1), which
          // may ask for more than the cell holds: then all of it leaves, in proportion.
          const double bound = capped && leaving > value && leaving > 0 ? (value > 0 ? value : 0.0) / leaving : 1.0;
          for (int f = 0; f < 2 * Dim; ++f) {
            slab_mass[f] *= bound;
            outflow_mass(c, f, m) = slab_mass[f];
            if (slab_densities) slab_density(c, f, m) = value + phi * slope[f];
            left -= slab_mass[f];
          }
          if (!(left > 0)) left = 0.0;

          for (int field = 0; field < q.fields; ++field) {
            const auto& Q = q.field[field];
            for (int j = 0; j < q.width[field]; ++j) {
              const int col = m * q.width[field] + j, slot = q.first[field] + col;
              double gq[Dim], spread_q = 0;
              for (int d = 0; d < Dim; ++d) {
                gq[d] = stencil.gradient(Q, c, local, col, d);
                spread_q += 0.5 * (gq[d] < 0 ? -gq[d] : gq[d]) * stencil.spacing[d];
              }
              double slope_q[2 * Dim];
              double S_q = 0.0;
              for (int f = 0; f < 2 * Dim; ++f) {
                slope_q[f] = 0;
                for (int d = 0; d < Dim; ++d) slope_q[f] += gq[d] * r[f][d];
                S_q += slab_mass[f] * slope_q[f];
              }
              double lo_q, hi_q;
              stencil.blockBounds(Q, c, local, col, lo_q, hi_q);
              const double value_q = Q(c, col);
              const double phi_q = whole ? 0.0 : limiter(value_q, lo_q, hi_q, spread_q, left, S_q);
              for (int f = 0; f < 2 * Dim; ++f) outflow_value(c, f, slot) = value_q + phi_q * slope_q[f];
              bounds(c, slot, 0) = lo_q;
              bounds(c, slot, 1) = hi_q;
            }
          }
        }
      },
      LargestOutflowReducer(largest));
  return largest;
}

template <int Dim>
void Advector<Dim>::update(Field<Dim>& mass, const std::vector<Field<Dim>*>& mass_specific)
{
  const auto neighbours = layout_->cellNeighbours();
  const auto outflow_mass = outflow_mass_;
  const auto outflow_value = outflow_value_;
  const auto bounds = bounds_;
  const auto q = quantityColumns<Dim, kMaxFields, typename Field<Dim>::View>(mass_specific, materials_);
  auto M = mass.view();
  const int materials = materials_;
  const unsigned held = options_.held_materials;
  const auto closed = options_.closed_cells;
  const bool any_closed = closed.extent(0) > 0;

  // Each face's flux is one stored number, read by the donor (out) and by the receiver (in). Per
  // column, (M q)_new = M q - Σ_out F q_out + Σ_in F q_in, written as an increment of q so that zero
  // flux or a uniform q leaves q exactly unchanged:  q_new = q + Σ_f ±F_f (q_f - q) / M_new.
  // Cell c's entries are read and written by its own iteration only, so the update is in place.
  Kokkos::parallel_for(
      "advection update", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()), KOKKOS_LAMBDA(int c) {
        if (any_closed && closed(c)) return;  // nothing entered or left
        LocalOrdinal neighbour[2 * Dim];
        for (int f = 0; f < 2 * Dim; ++f) neighbour[f] = neighbours(c, f);
        for (int m = 0; m < materials; ++m) {
          if (held >> m & 1u) continue;  // mass and quantities as they are
          double mass_new = M(c, m);
          double out[2 * Dim], in[2 * Dim];  // the slab masses leaving and entering through each face
          for (int f = 0; f < 2 * Dim; ++f) {
            const LocalOrdinal n = neighbour[f];
            in[f] = n >= 0 ? outflow_mass(n, f ^ 1, m) : 0.0;
            out[f] = outflow_mass(c, f, m);
            mass_new += in[f] - out[f];
          }
          // Without mass before and without inflow the cell keeps no mass and its q as it is (the
          // clamp below would leave q unchanged too: the block bounds include the cell's own q);
          // reconstruct() computed no bounds for it.
          bool inflow = false;
          for (int f = 0; f < 2 * Dim; ++f) inflow = inflow || in[f] != 0.0;
          if (!(M(c, m) > 0.0) && !inflow) continue;
          for (int field = 0; field < q.fields; ++field) {
            const auto& Q = q.field[field];
            for (int j = 0; j < q.width[field]; ++j) {
              const int col = m * q.width[field] + j, slot = q.first[field] + col;
              const double value_old = Q(c, col);
              double lo = bounds(c, slot, 0), hi = bounds(c, slot, 1);
              double change = 0;
              for (int f = 0; f < 2 * Dim; ++f) {
                change -= out[f] * (outflow_value(c, f, slot) - value_old);
                const LocalOrdinal n = neighbour[f];
                if (n < 0 || in[f] == 0) continue;
                const double q_in = outflow_value(n, f ^ 1, slot);
                change += in[f] * (q_in - value_old);
                lo = q_in < lo ? q_in : lo;
                hi = q_in > hi ? q_in : hi;
              }
              double value = mass_new > 0 ? value_old + change / mass_new : value_old;
              // In exact arithmetic the new q is a mean of the remainder (within [lo, hi] of the
              // block) and the inflow values, so this only removes round-off, which is large relative
              // to q only where nearly all the mass has left (then M_new·q is tiny either way).
              Q(c, col) = value < lo ? lo : (value > hi ? hi : value);
            }
          }
          M(c, m) = mass_new;
        }
      });
}

template class Advector<2>;
template class Advector<3>;

}  // namespace cfdmpm
