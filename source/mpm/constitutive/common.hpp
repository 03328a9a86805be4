#pragma once
// What every solid model shares: elastic moduli, the per-particle state, the kinematics of one step,
// and the objective hypo-elastic predictor used by the small-strain models.
//
// Stress convention: Cauchy stress, tension positive (Pa). Pressure p = -tr(sigma)/3 is compression
// positive. 2-D scenes are plane strain: every model works on the 3 x 3 tensor of a slice with no
// motion in z (L_zz = L_xz = L_yz = 0, F_zz = 1) and keeps the out-of-plane stress sigma_zz, which
// in-plane kernels never see, in MaterialState::out_of_plane_stress.
#include "mpm/tensor.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cfdmpm::mpm {

/// Isotropic linear elastic moduli (Pa). Build with fromYoungPoisson or fromBulkShear.
struct ElasticModuli {
  double bulk_modulus = 0.0;   ///< K (Pa)
  double shear_modulus = 0.0;  ///< G (Pa)

  static ElasticModuli fromBulkShear(double bulk_modulus, double shear_modulus)
  {
    if (!(bulk_modulus > 0.0) || !(shear_modulus > 0.0))
      throw std::invalid_argument("elastic moduli: bulk modulus (got " +
                                  std::to_string(bulk_modulus) + " Pa) and shear modulus (got " +
                                  std::to_string(shear_modulus) + " Pa) must be positive");
    return ElasticModuli{bulk_modulus, shear_modulus};
  }

  /// E (Pa) and Poisson's ratio nu in (-1, 1/2).
  static ElasticModuli fromYoungPoisson(double youngs_modulus, double poisson_ratio)
  {
    if (!(youngs_modulus > 0.0))
      throw std::invalid_argument("elastic moduli: Young's modulus must be positive, got " +
                                  std::to_string(youngs_modulus) + " Pa");
    if (!(poisson_ratio > -1.0 && poisson_ratio < 0.5))
      throw std::invalid_argument("elastic moduli: Poisson's ratio must lie in (-1, 0.5), got " +
                                  std::to_string(poisson_ratio));
    return ElasticModuli{youngs_modulus / (3.0 * (1.0 - 2.0 * poisson_ratio)),
                         youngs_modulus / (2.0 * (1.0 + poisson_ratio))};
  }

  /// Lame's first parameter lambda = K - 2G/3 (Pa).
  KOKKOS_INLINE_FUNCTION double lame() const { return bulk_modulus - 2.0 * shear_modulus / 3.0; }
  /// P-wave (constrained) modulus K + 4G/3 (Pa): rho c^2 of the fastest elastic wave.
  KOKKOS_INLINE_FUNCTION double pWaveModulus() const
  {
    return bulk_modulus + 4.0 * shear_modulus / 3.0;
  }
  /// Dilatational wave speed sqrt((K + 4G/3) / rho) (m/s) at density rho (kg/m^3).
  KOKKOS_INLINE_FUNCTION double waveSpeed(double density) const
  {
    return math::sqrt(pWaveModulus() / density);
  }
};

/// Per-particle history of a solid model. One type for all models, so particle storage is the same
/// for every material (a model ignores what it does not use).
struct MaterialState {
  /// sigma_zz (Pa) in 2-D plane strain; unused (stays 0) in 3-D.
  double out_of_plane_stress = 0.0;
  /// Accumulated deviatoric plastic strain, sum of sqrt(2/3 dev(d eps_p) : dev(d eps_p)).
  double equivalent_plastic_strain = 0.0;
  /// Accumulated volumetric plastic strain, sum of tr(d eps_p); positive is dilation.
  double volumetric_plastic_strain = 0.0;
};

/// Kinematics of one particle over one step, from the grid-to-particle transfer.
template <int Dim>
struct StepKinematics {
  Mat<Dim> velocity_gradient;     ///< L = grad v at the particle (1/s)
  Mat<Dim> deformation_gradient;  ///< F at the end of the step, F_{n+1} = (I + dt L) F_n
  double dt = 0.0;                ///< time step (s)
};

/// Objective elastic predictor of the hypo-elastic (rate-form) models:
///   sigma_trial = R sigma_n R^T + lambda tr(d eps) I + 2 G d eps,   d eps = dt sym(L),
/// with R = (I - dt W / 2)^-1 (I + dt W / 2), W = skew(L): the incremental rotation of Hughes &
/// Winget 1980, exactly orthogonal, so a rigid rotation rotates the stress and changes none of its
/// invariants. Works on the 3 x 3 plane-strain embedding; returns d eps and the trial stress.
template <int Dim>
KOKKOS_INLINE_FUNCTION void hypoelasticTrial(const ElasticModuli& moduli,
                                             const StepKinematics<Dim>& kinematics,
                                             const Mat<Dim>& stress, double out_of_plane_stress,
                                             Mat<3>& strain_increment, Mat<3>& trial)
{
  const Mat<3> L = embedPlaneStrain(kinematics.velocity_gradient, 0.0);
  const double dt = kinematics.dt;
  strain_increment = dt * symmetricPart(L);
  const Mat<3> half_spin = (0.5 * dt) * skewPart(L);
  const Mat<3> I = Mat<3>::identity();
  const Mat<3> R = inverse(I - half_spin) * (I + half_spin);
  const Mat<3> sigma = embedPlaneStrain(stress, out_of_plane_stress);
  // Symmetrised so round-off in the rotation cannot make the stress drift off symmetric.
  trial = symmetricPart(R * sigma * transpose(R)) + (2.0 * moduli.shear_modulus) * strain_increment;
  const double volumetric = moduli.lame() * trace(strain_increment);
  for (int i = 0; i < 3; ++i) trial(i, i) += volumetric;
}

/// Degrees to radians for the angle parameters (input files give degrees).
inline double degreesToRadians(double degrees)
{
  constexpr double kPi = 3.14159265358979323846;
  return degrees * (kPi / 180.0);
}

}  // namespace cfdmpm::mpm
