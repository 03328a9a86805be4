#pragma once
// Tresca elasto-perfectly-plastic solid: the seed paper's undrained sand ("elasto-plastic Tresca
// material model with no plastic volume change").
//
// Yield function, with principal stresses sigma_1 >= sigma_2 >= sigma_3 (tension positive):
//     f = sigma_1 - sigma_3 - 2 c <= 0,   i.e. the maximum shear stress tau_max <= c.
// c (Pa) is the undrained shear strength. The paper's "yield stress 200 Pa" is read as c = 200 Pa,
// as in its Uintah input (MohrCoulomb with friction angle ~0 and cohesion 200 Pa). A uniaxial
// yield stress sigma_y would be 2c (Tresca); give cohesion = sigma_y / 2 in that case.
//
// Elasticity is linear and hypo-elastic (linear_elastic.hpp); flow is associated and deviatoric,
// so the plastic volume change is zero and the pressure is purely elastic. The return map is the
// exact closest-point projection in principal stress space (de Souza Neto, Peric & Owen 2008,
// "Computational Methods for Plasticity", sec. 8.2, Tresca as Mohr-Coulomb with phi = 0):
//   1. main plane: d gamma = f_trial / (4G); sigma_1 -= 2G dg, sigma_3 += 2G dg;
//   2. if that breaks sigma_1 >= sigma_2 (right corner, sigma_1 = sigma_2 after) or
//      sigma_2 >= sigma_3 (left corner, sigma_2 = sigma_3 after), return to the edge where two
//      planes are active, a 2 x 2 linear system with the closed-form solution below.
// The principal directions of the trial stress are kept (isotropic elasticity).
//
// Plane strain: the return runs on the full 3 x 3 stress, sigma_zz included, so the out-of-plane
// stress takes part in tau_max exactly as in a 3-D body with eps_zz = 0. When sigma_zz is the
// intermediate principal stress (the usual case in shear) this is the in-plane Tresca criterion
// (sigma_1 - sigma_3)/2 = c on the in-plane principal stresses.
#include "mpm/constitutive/common.hpp"

namespace cfdmpm::mpm {

struct TrescaParameters {
  ElasticModuli elastic;
  double cohesion = 0.0;  ///< c = maximum shear stress at yield (Pa)
};

class Tresca {
 public:
  explicit Tresca(const TrescaParameters& parameters)
      : elastic_(parameters.elastic), cohesion_(parameters.cohesion)
  {
    ElasticModuli::fromBulkShear(elastic_.bulk_modulus, elastic_.shear_modulus);
    if (!(cohesion_ > 0.0))
      throw std::invalid_argument("Tresca: cohesion (maximum shear stress) must be positive, got " +
                                  std::to_string(cohesion_) + " Pa");
  }

  KOKKOS_INLINE_FUNCTION const ElasticModuli& moduli() const { return elastic_; }
  KOKKOS_INLINE_FUNCTION double cohesion() const { return cohesion_; }
  KOKKOS_INLINE_FUNCTION double waveSpeed(double density) const
  {
    return elastic_.waveSpeed(density);
  }

  /// f = sigma_1 - sigma_3 - 2c of a 3 x 3 stress (Pa); <= 0 inside the elastic domain.
  KOKKOS_INLINE_FUNCTION double yieldFunction(const Mat<3>& sigma) const
  {
    double principal[3];
    Mat<3> directions;
    symmetricEigen(sigma, principal, directions);
    return principal[0] - principal[2] - 2.0 * cohesion_;
  }

  template <int Dim>
  KOKKOS_INLINE_FUNCTION void update(const StepKinematics<Dim>& kinematics, MaterialState& state,
                                     Mat<Dim>& stress) const
  {
    Mat<3> strain_increment, sigma;
    hypoelasticTrial(elastic_, kinematics, stress, state.out_of_plane_stress, strain_increment,
                     sigma);
    returnToYieldSurface(sigma, state);
    extractPlaneStrain(sigma, stress, state.out_of_plane_stress);
  }

  /// Projects a trial stress onto the yield surface (no-op inside it) and accumulates the plastic
  /// strain in `state`.
  KOKKOS_INLINE_FUNCTION void returnToYieldSurface(Mat<3>& sigma, MaterialState& state) const
  {
    double principal[3];
    Mat<3> directions;
    symmetricEigen(sigma, principal, directions);
    const double two_c = 2.0 * cohesion_;
    const double f = principal[0] - principal[2] - two_c;
    if (f <= 0.0) return;

    const double G = elastic_.shear_modulus;
    // Principal plastic strain increments; deviatoric, so d sigma_k = -2G d_k.
    double plastic[3];
    const double main_plane = f / (4.0 * G);
    const double sigma1 = principal[0] - 2.0 * G * main_plane;
    const double sigma3 = principal[2] + 2.0 * G * main_plane;
    if (principal[1] > sigma1) {
      // Right corner: planes sigma_1 - sigma_3 and sigma_2 - sigma_3 active;
      // [4G 2G; 2G 4G] (a, b) = (f_a, f_b).
      const double f_b = principal[1] - principal[2] - two_c;
      const double a = (2.0 * f - f_b) / (6.0 * G);
      const double b = (2.0 * f_b - f) / (6.0 * G);
      plastic[0] = a;
      plastic[1] = b;
      plastic[2] = -(a + b);
    } else if (principal[1] < sigma3) {
      // Left corner: planes sigma_1 - sigma_3 and sigma_1 - sigma_2 active.
      const double f_b = principal[0] - principal[1] - two_c;
      const double a = (2.0 * f - f_b) / (6.0 * G);
      const double b = (2.0 * f_b - f) / (6.0 * G);
      plastic[0] = a + b;
      plastic[1] = -b;
      plastic[2] = -a;
    } else {
      plastic[0] = main_plane;
      plastic[1] = 0.0;
      plastic[2] = -main_plane;
    }

    // sigma_new = sigma_trial - sum_k 2G d_k n_k n_k^T (corrections only, so the trial's accuracy
    // is kept where the decomposition's round-off would otherwise enter).
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double correction = 0.0;
        for (int k = 0; k < 3; ++k)
          correction += plastic[k] * directions(i, k) * directions(j, k);
        sigma(i, j) -= 2.0 * G * correction;
      }

    const double volumetric = plastic[0] + plastic[1] + plastic[2];
    double deviatoric_squared = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double dev = plastic[k] - volumetric / 3.0;
      deviatoric_squared += dev * dev;
    }
    state.volumetric_plastic_strain += volumetric;
    state.equivalent_plastic_strain += math::sqrt(2.0 / 3.0 * deviatoric_squared);
  }

 private:
  ElasticModuli elastic_;
  double cohesion_ = 0.0;
};

}  // namespace cfdmpm::mpm
