#pragma once
// Material points in structure-of-arrays form: one Kokkos View per quantity, the first `count`
// entries in use, the rest spare capacity. Kernels capture a Particles by value (a set of view
// handles) and index it by particle; capacity grows only on the host, outside kernels (resize).
//
// Units: SI. Positions (m), velocities (m/s), mass (kg; kg/m in 2-D, per metre of thickness),
// volume (m^3; m^2 in 2-D), stress (Pa, Cauchy, tension positive; in 2-D the in-plane block, with
// sigma_zz in the MaterialState). Seeding: seedParticles below.
#include "common/types.hpp"
#include "grid/layout.hpp"
#include "mpm/constitutive/common.hpp"
#include "mpm/solid_material.hpp"

#include <vector>

namespace cfdmpm::mpm {

template <int Dim>
struct Particles {
  using ScalarView = Kokkos::View<double*, MemorySpace>;
  using VectorView = Kokkos::View<double* [Dim], MemorySpace>;
  using TensorView = Kokkos::View<double* [Dim][Dim], MemorySpace>;

  /// Doubles per particle in a migration buffer (pack / unpack); material and id travel as
  /// doubles, exact for ids below 2^53.
  static constexpr int kPackedSize = 3 * Dim + 3 + 2 * Dim * Dim + 3 + 2 * Dim + 2;

  int count = 0;  ///< particles in use: entries [0, count)

  VectorView position;              ///< x_p (m)
  VectorView velocity;              ///< v_p (m/s)
  ScalarView mass;                  ///< m_p (kg), constant
  ScalarView volume;                ///< V_p = det(F) V_p0 (m^3)
  ScalarView initial_volume;        ///< V_p0 (m^3)
  TensorView deformation_gradient;  ///< F (-)
  TensorView stress;                ///< Cauchy stress sigma (Pa)
  Kokkos::View<MaterialState*, MemorySpace> state;  ///< plastic history, sigma_zz in 2-D
  Kokkos::View<int*, MemorySpace> material;         ///< MPM material index (SolidMaterial list)
  VectorView half_width;            ///< uGIMP particle half-width l_p per direction (m)
  Kokkos::View<long long*, MemorySpace> id;         ///< unique, independent of the decomposition
  /// The velocity change the fluids gave the particle in the present coupled step (m/s), which its
  /// particle steps inside that step take in equal parts (MpmSolver::addParticleVelocityChange);
  /// migrated with the particle, since it moves to other ranks between those steps.
  VectorView velocity_change;
  /// With particle steps inside the fluids' step: the particle's own acceleration (its stress,
  /// gravity, contact; not the fluids' force) over the last coupled step (m/s^2), from which the
  /// next step forecasts its velocity for the fluids (MpmSolver::particlesToCells); migrated.
  VectorView own_acceleration;
  /// Velocity gradient of the last step (1/s); scratch between G2P and the stress update, not
  /// migrated.
  TensorView velocity_gradient;

  int capacity() const { return int(mass.extent(0)); }

  /// Sets the count to n, growing every view by at least half its capacity when n exceeds it (the
  /// first n_old entries are kept). Host only, never inside a kernel.
  void resize(int n);

  /// Copies every migrated quantity of particle `from` to slot `to`.
  KOKKOS_INLINE_FUNCTION void copyParticle(int from, int to) const
  {
    for (int d = 0; d < Dim; ++d) {
      position(to, d) = position(from, d);
      velocity(to, d) = velocity(from, d);
      half_width(to, d) = half_width(from, d);
      velocity_change(to, d) = velocity_change(from, d);
      own_acceleration(to, d) = own_acceleration(from, d);
      for (int e = 0; e < Dim; ++e) {
        deformation_gradient(to, d, e) = deformation_gradient(from, d, e);
        stress(to, d, e) = stress(from, d, e);
      }
    }
    mass(to) = mass(from);
    volume(to) = volume(from);
    initial_volume(to) = initial_volume(from);
    state(to) = state(from);
    material(to) = material(from);
    id(to) = id(from);
  }

  /// Writes particle p to row[0 .. kPackedSize).
  KOKKOS_INLINE_FUNCTION void pack(int p, double* row) const
  {
    int k = 0;
    for (int d = 0; d < Dim; ++d) row[k++] = position(p, d);
    for (int d = 0; d < Dim; ++d) row[k++] = velocity(p, d);
    for (int d = 0; d < Dim; ++d) row[k++] = half_width(p, d);
    row[k++] = mass(p);
    row[k++] = volume(p);
    row[k++] = initial_volume(p);
    for (int d = 0; d < Dim; ++d)
      for (int e = 0; e < Dim; ++e) row[k++] = deformation_gradient(p, d, e);
    for (int d = 0; d < Dim; ++d)
      for (int e = 0; e < Dim; ++e) row[k++] = stress(p, d, e);
    row[k++] = state(p).out_of_plane_stress;
    row[k++] = state(p).equivalent_plastic_strain;
    row[k++] = state(p).volumetric_plastic_strain;
    for (int d = 0; d < Dim; ++d) row[k++] = velocity_change(p, d);
    for (int d = 0; d < Dim; ++d) row[k++] = own_acceleration(p, d);
    row[k++] = double(material(p));
    row[k++] = double(id(p));
  }

  /// Reads particle p from a row written by pack.
  KOKKOS_INLINE_FUNCTION void unpack(const double* row, int p) const
  {
    int k = 0;
    for (int d = 0; d < Dim; ++d) position(p, d) = row[k++];
    for (int d = 0; d < Dim; ++d) velocity(p, d) = row[k++];
    for (int d = 0; d < Dim; ++d) half_width(p, d) = row[k++];
    mass(p) = row[k++];
    volume(p) = row[k++];
    initial_volume(p) = row[k++];
    for (int d = 0; d < Dim; ++d)
      for (int e = 0; e < Dim; ++e) deformation_gradient(p, d, e) = row[k++];
    for (int d = 0; d < Dim; ++d)
      for (int e = 0; e < Dim; ++e) stress(p, d, e) = row[k++];
    state(p).out_of_plane_stress = row[k++];
    state(p).equivalent_plastic_strain = row[k++];
    state(p).volumetric_plastic_strain = row[k++];
    for (int d = 0; d < Dim; ++d) velocity_change(p, d) = row[k++];
    for (int d = 0; d < Dim; ++d) own_acceleration(p, d) = row[k++];
    material(p) = int(row[k++]);
    id(p) = static_cast<long long>(row[k++]);
  }
};

/// Material points of every solid material in the rank's owned cells, n x n (x n) per cell on a
/// regular lattice (n = particles_per_cell of the material) wherever the scene's regions put that
/// material (MaterialRegions::materialAt at the point). Each point carries the cell's share of mass,
/// density x cell volume / n^Dim, the velocity of the region it lies in (a rigid material's own
/// velocity), zero stress, F = I, the
/// uGIMP half-width h / (2 n), and the id (cell id x solids + material) x n_max^Dim + lattice index,
/// which does not depend on the decomposition.
template <int Dim>
Particles<Dim> seedParticles(const Scene& scene, const Layout<Dim>& layout, const std::vector<SolidMaterial>& solids);

extern template struct Particles<2>;
extern template struct Particles<3>;

}  // namespace cfdmpm::mpm
