#pragma once
// Drucker-Prager elasto-perfectly-plastic solid with non-associated flow: a pressure-dependent
// soil (the seed paper's future work), fitted to Mohr-Coulomb's friction angle phi, cohesion c and
// dilatancy angle psi.
//
// With p = tr(sigma)/3 (tension positive here), s = dev(sigma), q = sqrt(J2) = sqrt(s:s / 2):
//     yield     f = q + eta p - xi c <= 0
//     potential g = q + eta_bar p              (flow d eps_p = d gamma dg/dsigma)
// so the shear strength sqrt(J2) = xi c + eta p_c grows with the confining pressure p_c = -p, and
// the plastic dilation is d eps_v = eta_bar d gamma (zero for psi = 0).
//
// Fits of (eta, xi, eta_bar) to Mohr-Coulomb (de Souza Neto, Peric & Owen 2008, sec. 6.4.6):
//  * PlaneStrain (default, for 2-D scenes): the cone that gives Mohr-Coulomb's plane-strain limit
//    state exactly, (sigma_1 - sigma_3)/2 = c cos(phi) + p_in sin(phi) with p_in = -(sigma_1 +
//    sigma_3)/2 the in-plane mean pressure, together with Mohr-Coulomb's plane-strain dilation
//    rate d eps_v / (d eps_1 - d eps_3) = sin(psi). With the plastic strain rate zero in z:
//        eta_bar = 3 sin(psi) / sqrt(9 + 3 sin^2 psi)
//        D       = sqrt(1 - eta_bar^2 / 3) + eta_bar sin(phi) / 3
//        eta     = sin(phi) / D,   xi = cos(phi) / D
//    (psi = phi gives the textbook 3 tan(phi) / sqrt(9 + 12 tan^2 phi); psi = 0 gives
//    eta = sin(phi), xi = cos(phi)). Derivation in doc/mpm-models.md.
//  * OuterCone: through Mohr-Coulomb's compressive meridian (triaxial compression):
//        eta = 6 sin(phi) / (sqrt(3) (3 - sin(phi))), xi = 6 cos(phi) / (sqrt(3) (3 - sin(phi))),
//    eta_bar the same with psi.
//  * InnerCone: through the tensile meridian (triaxial extension): 3 + sin in the denominators.
//
// Return map (closed form for perfect plasticity, de Souza Neto et al. 2008, Box 8.9):
//  * smooth cone: d gamma = f_trial / (G + K eta eta_bar),
//        s = (1 - G d gamma / q_trial) s_trial,  p = p_trial - K eta_bar d gamma;
//  * if that would make q negative, the trial stress lies beyond the apex and returns to it:
//        s = 0,  p = xi c / eta  (the largest mean tension the material carries; this is the
//    tension cut-off of the cone). The flow rule is not defined at the apex; the volumetric
//    plastic strain takes the excess, (p_trial - p) / K.
// Elasticity is hypo-elastic with the Hughes-Winget rotation (common.hpp). Plane strain: the
// return runs on the 3 x 3 stress with sigma_zz, as in a 3-D body with eps_zz = 0.
#include "mpm/constitutive/common.hpp"

namespace cfdmpm::mpm {

enum class DruckerPragerFit { PlaneStrain, OuterCone, InnerCone };

struct DruckerPragerParameters {
  ElasticModuli elastic;
  double friction_angle_degrees = 0.0;   ///< phi, 0 <= phi < 90
  double cohesion = 0.0;                 ///< c (Pa) >= 0; c > 0 when phi = 0
  double dilatancy_angle_degrees = 0.0;  ///< psi, 0 <= psi <= phi
  DruckerPragerFit fit = DruckerPragerFit::PlaneStrain;
};

class DruckerPrager {
 public:
  explicit DruckerPrager(const DruckerPragerParameters& parameters)
      : elastic_(parameters.elastic), cohesion_(parameters.cohesion)
  {
    ElasticModuli::fromBulkShear(elastic_.bulk_modulus, elastic_.shear_modulus);
    const double phi_deg = parameters.friction_angle_degrees;
    const double psi_deg = parameters.dilatancy_angle_degrees;
    if (!(phi_deg >= 0.0 && phi_deg < 90.0))
      throw std::invalid_argument("DruckerPrager: friction angle must lie in [0, 90) degrees, got " +
                                  std::to_string(phi_deg));
    if (!(psi_deg >= 0.0 && psi_deg <= phi_deg))
      throw std::invalid_argument(
          "DruckerPrager: dilatancy angle must lie in [0, friction angle] degrees, got " +
          std::to_string(psi_deg));
    if (!(cohesion_ >= 0.0) || (cohesion_ == 0.0 && phi_deg == 0.0))
      throw std::invalid_argument("DruckerPrager: cohesion must be >= 0 Pa, and > 0 when the "
                                  "friction angle is 0; got " + std::to_string(cohesion_));
    const double sin_phi = std::sin(degreesToRadians(phi_deg));
    const double cos_phi = std::cos(degreesToRadians(phi_deg));
    const double sin_psi = std::sin(degreesToRadians(psi_deg));
    switch (parameters.fit) {
      case DruckerPragerFit::PlaneStrain: {
        eta_bar_ = 3.0 * sin_psi / std::sqrt(9.0 + 3.0 * sin_psi * sin_psi);
        const double D = std::sqrt(1.0 - eta_bar_ * eta_bar_ / 3.0) + eta_bar_ * sin_phi / 3.0;
        eta_ = sin_phi / D;
        xi_ = cos_phi / D;
        break;
      }
      case DruckerPragerFit::OuterCone:
      case DruckerPragerFit::InnerCone: {
        const double sign = parameters.fit == DruckerPragerFit::OuterCone ? -1.0 : 1.0;
        const double root3 = std::sqrt(3.0);
        eta_ = 6.0 * sin_phi / (root3 * (3.0 + sign * sin_phi));
        xi_ = 6.0 * cos_phi / (root3 * (3.0 + sign * sin_phi));
        eta_bar_ = 6.0 * sin_psi / (root3 * (3.0 + sign * sin_psi));
        break;
      }
    }
  }

  KOKKOS_INLINE_FUNCTION const ElasticModuli& moduli() const { return elastic_; }
  KOKKOS_INLINE_FUNCTION double cohesion() const { return cohesion_; }
  KOKKOS_INLINE_FUNCTION double eta() const { return eta_; }          ///< friction coefficient
  KOKKOS_INLINE_FUNCTION double xi() const { return xi_; }            ///< cohesion coefficient
  KOKKOS_INLINE_FUNCTION double etaBar() const { return eta_bar_; }   ///< dilatancy coefficient
  /// Mean stress of the apex, xi c / eta (Pa, tension positive); infinite for phi = 0.
  KOKKOS_INLINE_FUNCTION double apexMeanStress() const { return xi_ * cohesion_ / eta_; }
  KOKKOS_INLINE_FUNCTION double waveSpeed(double density) const
  {
    return elastic_.waveSpeed(density);
  }

  /// f = sqrt(J2) + eta p - xi c (Pa) of a 3 x 3 stress; <= 0 inside the elastic domain.
  KOKKOS_INLINE_FUNCTION double yieldFunction(const Mat<3>& sigma) const
  {
    const Mat<3> s = deviator(sigma);
    return math::sqrt(0.5 * contract(s, s)) + eta_ * trace(sigma) / 3.0 - xi_ * cohesion_;
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

  /// Projects a trial stress onto the cone or its apex (no-op inside) and accumulates the plastic
  /// strain in `state`.
  KOKKOS_INLINE_FUNCTION void returnToYieldSurface(Mat<3>& sigma, MaterialState& state) const
  {
    const double p_trial = trace(sigma) / 3.0;
    const Mat<3> s_trial = deviator(sigma);
    const double q_trial = math::sqrt(0.5 * contract(s_trial, s_trial));
    const double f = q_trial + eta_ * p_trial - xi_ * cohesion_;
    if (f <= 0.0) return;

    const double K = elastic_.bulk_modulus;
    const double G = elastic_.shear_modulus;
    const double d_gamma = f / (G + K * eta_ * eta_bar_);
    double p = 0.0;
    double deviatoric_scale = 0.0;  // s = scale * s_trial
    if (q_trial - G * d_gamma >= 0.0) {
      p = p_trial - K * eta_bar_ * d_gamma;
      deviatoric_scale = 1.0 - G * d_gamma / q_trial;
      state.volumetric_plastic_strain += eta_bar_ * d_gamma;
      // dev(d eps_p) = d gamma s / (2q): its norm is d gamma / sqrt(2).
      state.equivalent_plastic_strain += d_gamma / math::sqrt(3.0);
    } else {
      p = apexMeanStress();
      deviatoric_scale = 0.0;
      state.volumetric_plastic_strain += (p_trial - p) / K;
      // dev(d eps_p) = s_trial / (2G).
      state.equivalent_plastic_strain +=
          math::sqrt(2.0 / 3.0) * math::sqrt(2.0) * q_trial / (2.0 * G);
    }
    sigma = deviatoric_scale * s_trial;
    for (int i = 0; i < 3; ++i) sigma(i, i) += p;
  }

 private:
  ElasticModuli elastic_;
  double cohesion_ = 0.0;
  double eta_ = 0.0;
  double xi_ = 0.0;
  double eta_bar_ = 0.0;
};

}  // namespace cfdmpm::mpm
