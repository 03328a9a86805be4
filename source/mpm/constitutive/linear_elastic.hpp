#pragma once
// Linear elasticity in hypo-elastic rate form (small strain per step, finite rotation):
//   sigma_{n+1} = R sigma_n R^T + lambda tr(d eps) I + 2 G d eps,   d eps = dt sym(L),
// with the Hughes-Winget rotation R (common.hpp). For small total strain and no rotation this is
// sigma = lambda tr(eps) I + 2 G eps. Parameters: E (Pa), nu (-), or K, G (Pa).
#include "mpm/constitutive/common.hpp"

namespace cfdmpm::mpm {

struct LinearElasticParameters {
  ElasticModuli elastic;
};

class LinearElastic {
 public:
  explicit LinearElastic(const LinearElasticParameters& parameters) : elastic_(parameters.elastic)
  {
    // Re-validate: parameters may have been filled field by field.
    ElasticModuli::fromBulkShear(elastic_.bulk_modulus, elastic_.shear_modulus);
  }

  KOKKOS_INLINE_FUNCTION const ElasticModuli& moduli() const { return elastic_; }
  KOKKOS_INLINE_FUNCTION double waveSpeed(double density) const
  {
    return elastic_.waveSpeed(density);
  }

  /// Advances `stress` (in-plane / full Cauchy stress, Pa) by one step; see the file comment.
  template <int Dim>
  KOKKOS_INLINE_FUNCTION void update(const StepKinematics<Dim>& kinematics, MaterialState& state,
                                     Mat<Dim>& stress) const
  {
    Mat<3> strain_increment, trial;
    hypoelasticTrial(elastic_, kinematics, stress, state.out_of_plane_stress, strain_increment,
                     trial);
    extractPlaneStrain(trial, stress, state.out_of_plane_stress);
  }

 private:
  ElasticModuli elastic_;
};

}  // namespace cfdmpm::mpm
