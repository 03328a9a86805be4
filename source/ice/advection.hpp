#pragma once
// Advection of the fluid materials' conserved cell quantities by the face velocities: the last
// phase of the ICE step (Uintah's advectAndAdvanceInTime with the SecondOrder advector and
// compatible fluxes). Per material, the mass and any number of mass-specific quantities q (velocity,
// specific volume, internal energy per mass, ...) move through the cell faces with
//
//   mass flux   F_f   = V_f · ρ̃(x_f)            (V_f: outflow slab volume of the donor, ρ̃: limited
//                                                linear density of the donor, x_f: slab centroid)
//   flux of M q       = F_f · q̃(x_f)            (q̃: limited linear q of the donor)
//
// so that mass and every M q are conserved to round-off, the density stays >= 0 (and within its
// neighbours' bounds in a divergence-free flow), and each q stays within the bounds of the values
// it is mixed from, in any flow. The scheme, the limiter and the measured orders are in
// doc/ice-advection.md.
#include "fields/field.hpp"
#include "ice/face_field.hpp"

#include <memory>
#include <string>
#include <vector>

namespace cfdmpm {

/// The largest outflow fraction Σ_faces V_out / V_cell over cells and materials, and among the
/// entries that attain it the lowest key = global cell id · materials + material (so that every
/// decomposition names the same cell).
struct LargestOutflow {
  double value;
  long long key;

  KOKKOS_INLINE_FUNCTION void include(double candidate, long long candidate_key)
  {
    if (!(candidate >= value)) return;  // also skips a NaN
    if (candidate > value || candidate_key < key) value = candidate, key = candidate_key;
  }
};

/// Result of one advection step. The step is refused (fields unchanged) when some cell would send
/// out more than its volume in one step (Uintah's "bulletproofing"): the caller reduces Δt.
struct AdvectionStatus {
  bool ok = true;
  /// Largest Σ_faces V_out / V_cell over all cells and materials (the outflow Courant number), but
  /// for the traces that advect() lets leave whole (its volume_fraction).
  double max_outflux_fraction = 0.0;
  long long cell = -1;  // global id of the cell where the maximum occurs (lowest id on ties)
  int material = -1;    // and its material
  std::string message() const;
};

template <int Dim>
class Advector {
 public:
  struct Options {
    /// Evaluate each slab at the centroid of the region swept through the face in Δt, shifted by
    /// the donor's mean transverse velocity (corner transport). Off: the centroid of the
    /// rectangular slab, as Uintah; then diagonal flows are first order in time (see the doc).
    bool transverse_correction = true;
    /// Bit m set: material m does not move (the coupled step's solids, which their particles
    /// carry). advect() leaves its mass and quantities as they are and slabDensities() gives 0
    /// for it, without computing their profiles (a third of the cell-material pairs of the seed
    /// scene are its bed and sand).
    unsigned held_materials = 0;
    /// Per local cell (owned and ghost), 1 where nothing flows: every face of the cell has a zero
    /// velocity for every material that moves (the coupled step's cells inside a rigid body,
    /// IceSolver::closedCells). Such a cell keeps its mass and quantities and sends nothing, without
    /// computing its profiles. Empty: every cell is open. The advector reads the view's current
    /// contents at each call.
    Kokkos::View<const unsigned char*, MemorySpace> closed_cells;
  };

  /// Work arrays for `materials` materials on the layout's cells are allocated here, once.
  Advector(std::shared_ptr<const Layout<Dim>> layout, int materials, Options options);
  Advector(std::shared_ptr<const Layout<Dim>> layout, int materials)
      : Advector(std::move(layout), materials, Options{})
  {
  }

  /// Advances by dt (s):
  /// - face_velocity (m/s): one column per material, the convention of face_field.hpp; every domain
  ///   face is a wall (its flux is zero whatever the stored value). Its ghosts are refreshed here.
  /// - mass (kg per cell, one column per material), updated in place. The scheme is linear in the
  ///   mass, so a bulk density (mass / V_cell) may be passed instead and stays a bulk density.
  /// - mass_specific: quantities per unit mass, each with `materials × k` columns, column m·k + j
  ///   for component j of material m (k = 1 for scalars, k = Dim for a velocity as in CellState).
  ///   Updated in place so that (M q)_new = M q + Σ fluxes of M q.
  /// Input ghosts are refreshed before the step and output ghosts after it. If the status is not
  /// ok, nothing is changed.
  /// - outflow_share (optional, (local cell, face f = 2 d + side), owned and ghost cells): the share
  ///   of each slab's profile that leaves (1 where not given): with solids in the cells, the room
  ///   the solids leave the fluids on a face over what the profiles hold
  ///   (IceSolver::fluidFaceFractions); above 1 next to a solid, whose edge the profile cannot hold.
  ///   A cell never gives more than its mass: if the slabs ask for more, all of it leaves, in
  ///   proportion.
  /// - volume_fraction (optional, with outflow_share; owned cells): each material's volume fraction.
  ///   A material that holds less than kTraceFraction of a cell may leave it whole in one step: its
  ///   outflow does not refuse the step (nor enter max_outflux_fraction). Beside a solid such a
  ///   trace sits in the gaps of the particles' coverage, and its face velocity, which the
  ///   pressure correction sets for the face and not for it, may sweep several cells in a step
  ///   while all it holds is less than a thousandth of its cell.
  using CapView = Kokkos::View<double**, MemorySpace>;
  using FractionView = typename Field<Dim>::ConstView;
  AdvectionStatus advect(FaceField<Dim>& face_velocity, double dt, Field<Dim>& mass,
                         const std::vector<Field<Dim>*>& mass_specific, const CapView& outflow_share = CapView(),
                         const FractionView& volume_fraction = FractionView());

  /// A material below this volume fraction of a cell is a trace there (advect's volume_fraction).
  static constexpr double kTraceFraction = 1e-3;

  /// The limited mass profile of every cell (owned and ghost) evaluated in the outflow slab of each
  /// of its faces for these face velocities, i.e. the bulk density that advect() would move through
  /// the face per slab volume: (local cell, face f = 2 d + side, material); 0 in a cell without the
  /// material. Where nothing leaves through a face, the profile's value at the face. The pressure
  /// equation takes its volume fluxes from it when solids share the cells, so that the volume it
  /// makes room for is the volume the advection brings. Needs current ghosts of both inputs.
  /// skip (optional, owned and ghost cells): cells whose slabs the caller does not read; their
  /// entries are left as they were.
  using WorkView = Kokkos::View<double***, MemorySpace>;  // (local cell, face, material)
  using CellMask = Kokkos::View<unsigned char*, MemorySpace>;
  const WorkView& slabDensities(const FaceField<Dim>& face_velocity, double dt, const Field<Dim>& mass,
                                const CellMask& skip = CellMask());

  int materials() const { return materials_; }


 /// At most this many mass-specific fields per advect() call (each of any width).
  static constexpr int kMaxFields = 8;

 private:
  /// The slab pass; returns this rank's largest outflow fraction and where it occurs.
  LargestOutflow reconstruct(const FaceField<Dim>& face_velocity, double dt, const Field<Dim>& mass,
                             const std::vector<Field<Dim>*>& mass_specific, bool slab_densities = false,
                             const CapView& outflow_share = CapView(), const CellMask& skip = CellMask(),
                             const FractionView& volume_fraction = FractionView());
  AdvectionStatus outfluxStatus(const LargestOutflow& local) const;
  void update(Field<Dim>& mass, const std::vector<Field<Dim>*>& mass_specific);

  std::shared_ptr<const Layout<Dim>> layout_;
  int materials_;
  Options options_;
  // Per local cell: the local ids of its 3^Dim block (itself included), the cell's own id where
  // there is none held by this rank; built once, read by the limiter bounds.
  Kokkos::View<LocalOrdinal**, MemorySpace> block_;
  // Per local cell (owned and ghost), face f = 2 d + side and material: the mass leaving the cell
  // through f in this step (>= 0).
  WorkView outflow_mass_;
  // Per local cell, face and material: the profile's value in the face's slab (slabDensities).
  WorkView slab_density_;
  // Per local cell, face and quantity column (all fields' columns side by side): the value of the
  // quantity in the outflow slab; and per local cell and column, the block bounds [lo, hi] of the
  // quantity (computed once for the limiter, reused by the update's final bound).
  WorkView outflow_value_, bounds_;
};

extern template class Advector<2>;
extern template class Advector<3>;

}  // namespace cfdmpm
