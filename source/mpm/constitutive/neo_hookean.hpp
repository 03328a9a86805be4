#pragma once
// Compressible Neo-Hookean hyperelasticity (the seed paper's rigid bed; Uintah's comp_neo_hook):
//   sigma = (K/2) (J - 1/J) I + G J^(-5/3) dev(b),   b = F F^T,  J = det F,
// from the stored energy W = (K/2) [(J^2 - 1)/2 - ln J] + (G/2) [tr(J^(-2/3) b) - 3].
// Depends on the total deformation gradient only (no history), so it is objective by construction:
// F -> Q F gives sigma -> Q sigma Q^T. For small strain it reduces to linear elasticity with the
// same K and G. Plane strain: F is embedded with F_zz = 1 (and F_xz = F_zx = F_yz = F_zy = 0), so
// b_zz = 1 and sigma_zz = (K/2)(J - 1/J) + G J^(-5/3) (1 - tr(b)/3) is stored in the state.
// J <= 0 (an inverted particle) gives a meaningless stress; the caller checks J > 0.
#include "mpm/constitutive/common.hpp"

namespace cfdmpm::mpm {

struct NeoHookeanParameters {
  ElasticModuli elastic;
};

class NeoHookean {
 public:
  explicit NeoHookean(const NeoHookeanParameters& parameters) : elastic_(parameters.elastic)
  {
    ElasticModuli::fromBulkShear(elastic_.bulk_modulus, elastic_.shear_modulus);
  }

  KOKKOS_INLINE_FUNCTION const ElasticModuli& moduli() const { return elastic_; }
  /// Small-strain dilatational speed at the current density; the tangent stiffens under strong
  /// compression, which the density factor (rho = rho0 / J) partly captures.
  KOKKOS_INLINE_FUNCTION double waveSpeed(double density) const
  {
    return elastic_.waveSpeed(density);
  }

  /// Cauchy stress of a deformation gradient, on the 3 x 3 plane-strain embedding.
  KOKKOS_INLINE_FUNCTION Mat<3> cauchyStress(const Mat<3>& F) const
  {
    const double J = determinant(F);
    const Mat<3> b = F * transpose(F);
    const double cbrt_J = math::cbrt(J);
    const double shear_factor = elastic_.shear_modulus / (J * cbrt_J * cbrt_J);  // G J^(-5/3)
    Mat<3> sigma = shear_factor * deviator(b);
    const double mean = 0.5 * elastic_.bulk_modulus * (J - 1.0 / J);
    for (int i = 0; i < 3; ++i) sigma(i, i) += mean;
    return sigma;
  }

  /// Sets `stress` from kinematics.deformation_gradient; the old stress and dt are not used.
  template <int Dim>
  KOKKOS_INLINE_FUNCTION void update(const StepKinematics<Dim>& kinematics, MaterialState& state,
                                     Mat<Dim>& stress) const
  {
    Mat<3> F = embedPlaneStrain(kinematics.deformation_gradient, 1.0);
    extractPlaneStrain(cauchyStress(F), stress, state.out_of_plane_stress);
  }

 private:
  ElasticModuli elastic_;
};

}  // namespace cfdmpm::mpm
