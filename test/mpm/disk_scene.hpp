#pragma once
// Two elastic disks that meet head-on along the diagonal of the unit square (Sulsky, Chen &
// Schreyer 1994): the material, the disks and the stored energy shared by test_mpm_disks (one
// material, no contact) and test_mpm_contact_stability (two materials with contact).

#include "input/scene.hpp"
#include "mpm/particles.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <string>

namespace cfdmpm::mpm::scenes::disks {

constexpr double kYoung = 1000.0, kPoisson = 0.3, kDensity = 1000.0, kSpeed = 0.1, kRadius = 0.2;
constexpr double kBulk = kYoung / (3 * (1 - 2 * kPoisson)), kShear = kYoung / (2 * (1 + kPoisson));

/// A disk of radius kRadius (a 128-gon) of `material` centred at (cx, cy), moving at (v, v).
inline void addDisk(Scene& scene, const std::string& material, double cx, double cy, double v)
{
  RegionSpec disk;
  disk.name = "disk_" + std::to_string(scene.regions.size());
  disk.material = material;
  disk.shape = "polygon";
  for (int k = 0; k < 128; ++k) {
    const double a = 2 * M_PI * k / 128;
    disk.vertices.push_back({cx + kRadius * std::cos(a), cy + kRadius * std::sin(a)});
  }
  disk.velocity = {v, v, 0};
  disk.temperature = 293.15;
  scene.regions.push_back(disk);
}

/// Stored energy of the rank's particles, sum V_p0 W(F_p), with the neo-Hookean energy of
/// source/mpm/constitutive/neo_hookean.hpp in plane strain (F_zz = 1):
///   W = (K/2) [(J^2 - 1)/2 - ln J] + (G/2) [J^(-2/3) tr(F F^T) - 3].
inline double storedEnergy(const Particles<2>& particles)
{
  auto F = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.deformation_gradient);
  auto V0 = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.initial_volume);
  double energy = 0;
  for (int p = 0; p < particles.count; ++p) {
    const double J = F(p, 0, 0) * F(p, 1, 1) - F(p, 0, 1) * F(p, 1, 0);
    double trace_b = 1.0;
    for (int d = 0; d < 2; ++d)
      for (int e = 0; e < 2; ++e) trace_b += F(p, d, e) * F(p, d, e);
    energy += V0(p) * (0.5 * kBulk * (0.5 * (J * J - 1) - std::log(J)) +
                       0.5 * kShear * (std::pow(J, -2.0 / 3.0) * trace_b - 3));
  }
  return energy;
}

}  // namespace cfdmpm::mpm::scenes::disks
