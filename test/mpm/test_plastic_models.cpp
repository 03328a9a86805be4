// Plastic models: Tresca (the seed paper's sand) and Drucker-Prager with dilatancy.
#include "mpm/constitutive/drucker_prager.hpp"
#include "mpm/constitutive/tresca.hpp"
#include "mpm_test_helpers.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace cfdmpm::mpm {
namespace {

using testing::maxShearStress;
using testing::meanStress;
using testing::principalStresses;
using testing::step;

// Seed paper sand: E = 50 MPa, nu = 0.25 (G = 20 MPa), c = 200 Pa; yield shear strain c/G = 1e-5.
const ElasticModuli kSand = ElasticModuli::fromYoungPoisson(50e6, 0.25);
constexpr double kSandCohesion = 200.0;

Tresca sand() { return Tresca(TrescaParameters{kSand, kSandCohesion}); }

template <int Dim>
Mat<Dim> simpleShear(double rate)
{
  Mat<Dim> L;
  L(0, 1) = rate;  // v_x = rate * y
  return L;
}

// Simple shear, shear strain 1e-6 per step (a tenth of the yield strain), to 2e-3 (200 times the
// yield strain). Elastic until tau = c, then tau_max = c at every step: the return is exact, so
// it lands on the surface to round-off (relative 1e-10 is the required bound, measured ~1e-15).
// Simple shear is isochoric and Tresca flow deviatoric, so the pressure stays 0 (round-off of
// sigma_xx, sigma_yy ~ 1e-16 relative) and the volumetric plastic strain is 0.
template <int Dim>
void trescaSimpleShear()
{
  const Tresca model = sand();
  const double G = kSand.shear_modulus, c = kSandCohesion;
  const double rate = 1.0, dt = 1e-6;
  Mat<Dim> stress;
  MaterialState state;
  double worst_excess = 0, worst_below = 0, worst_pressure = 0;
  int first_plastic_step = -1;
  const int steps = 2000;
  for (int n = 1; n <= steps; ++n) {
    model.update(step(simpleShear<Dim>(rate), dt), state, stress);
    const double tau = maxShearStress(stress, state);
    worst_excess = std::max(worst_excess, (tau - c) / c);
    worst_pressure = std::max(worst_pressure, std::abs(meanStress(stress, state)) / c);
    if (state.equivalent_plastic_strain > 0 && first_plastic_step < 0) first_plastic_step = n;
    if (first_plastic_step > 0) worst_below = std::max(worst_below, (c - tau) / c);
    if (n < 10) {
      // Elastic: tau = G gamma. Rotation of the stress adds O(gamma^2) relative.
      EXPECT_NEAR(stress(0, 1), G * rate * dt * n, 1e-9 * c);
    }
  }
  EXPECT_EQ(first_plastic_step, 11);  // gamma = 1.1e-5 is the first step beyond c/G = 1e-5
  EXPECT_LT(worst_excess, 1e-10);
  EXPECT_LT(worst_below, 1e-10);
  EXPECT_LT(worst_pressure, 1e-12);
  EXPECT_LT(std::abs(state.volumetric_plastic_strain), 1e-18);
  // Plastic shear strain gamma_p = gamma - c/G; equivalent strain gamma_p / sqrt(3). In steady
  // simple shear the rotation term tilts the stress's principal axes off 45 degrees by O(c/G) =
  // 1e-5 (sigma_xx = -sigma_yy ~ c^2/G = 2e-3 Pa), which changes sigma_xy and the plastic strain
  // by O((c/G)^2) = 1e-10 relative: tolerance 1e-8.
  const double gamma_p = rate * dt * steps - c / G;
  EXPECT_NEAR(state.equivalent_plastic_strain, gamma_p / std::sqrt(3.0), 1e-8 * gamma_p);
  EXPECT_NEAR(stress(0, 1), c, 1e-8 * c);
  EXPECT_NEAR(stress(0, 0), c * c / G, 1e-2 * c * c / G);
  std::printf("  [Dim %d] yield at step %d; max (tau_max - c)/c = %.2e, max (c - tau_max)/c "
              "after yield = %.2e, max |p|/c = %.2e, eps_p_vol = %.2e, eps_p_eq = %.10e "
              "(expected %.10e), sigma_xy = %.12f Pa, sigma_xx = %.3e Pa\n",
              Dim, first_plastic_step, worst_excess, worst_below, worst_pressure,
              state.volumetric_plastic_strain, state.equivalent_plastic_strain,
              gamma_p / std::sqrt(3.0), stress(0, 1), stress(0, 0));
}
TEST(Tresca, SimpleShearReachesCohesionAndStaysOnIt2D) { trescaSimpleShear<2>(); }
TEST(Tresca, SimpleShearReachesCohesionAndStaysOnIt3D) { trescaSimpleShear<3>(); }

// After yielding in shear, reversing the shear unloads elastically: tau drops by G d gamma per
// step with no plastic strain, through zero, until it yields at tau = -c after 2c/G = 2e-5 of
// reverse shear (20 steps).
TEST(Tresca, UnloadsElasticallyAfterYield)
{
  const Tresca model = sand();
  const double G = kSand.shear_modulus, c = kSandCohesion;
  const double dt = 1e-6;
  Mat<2> stress;
  MaterialState state;
  for (int n = 0; n < 100; ++n) model.update(step(simpleShear<2>(1.0), dt), state, stress);
  ASSERT_GT(state.equivalent_plastic_strain, 0.0);
  const double plastic_at_reversal = state.equivalent_plastic_strain;
  const double tau_at_reversal = stress(0, 1);
  int reverse_yield_step = -1;
  for (int n = 1; n <= 40; ++n) {
    model.update(step(simpleShear<2>(-1.0), dt), state, stress);
    if (state.equivalent_plastic_strain > plastic_at_reversal) {
      reverse_yield_step = n;
      break;
    }
    // Elastic unloading: sigma_xy = tau_0 - G gamma_reverse (rotation terms O(gamma^2) c).
    EXPECT_NEAR(stress(0, 1), tau_at_reversal - G * dt * n, 1e-6 * c);
  }
  EXPECT_EQ(reverse_yield_step, 21);  // 2c/G = 2e-5: the 21st reverse step crosses -c
  EXPECT_NEAR(maxShearStress(stress, state), c, 1e-10 * c);
  EXPECT_LT(stress(0, 1), -0.99 * c);
  std::printf("  unloading from sigma_xy = %.4f Pa: elastic for %d steps, reverse yield at "
              "sigma_xy = %.4f Pa\n",
              tau_at_reversal, reverse_yield_step - 1, stress(0, 1));
}

// Plane-strain uniaxial compression: the trial stress has sigma_yy = sigma_zz, a corner of the
// Tresca hexagon. The return goes to the edge: the two lateral stresses stay equal and
// sigma_lateral - sigma_xx = 2c; the pressure is the elastic K tr(eps) (no plastic volume change).
TEST(Tresca, CornerReturnInPlaneStrainCompression)
{
  const Tresca model = sand();
  const double c = kSandCohesion, K = kSand.bulk_modulus;
  Mat<2> L;
  L(0, 0) = -1.0;
  const double dt = 1e-6;
  Mat<2> stress;
  MaterialState state;
  const int steps = 200;
  for (int n = 0; n < steps; ++n) model.update(step(L, dt), state, stress);
  const double scale = K * dt * steps;  // |sigma| ~ 6.7e3 Pa
  EXPECT_NEAR(stress(1, 1), state.out_of_plane_stress, 1e-12 * scale);
  EXPECT_NEAR(stress(1, 1) - stress(0, 0), 2 * c, 1e-12 * scale);
  EXPECT_NEAR(meanStress(stress, state), -K * dt * steps, 1e-12 * scale);
  EXPECT_NEAR(maxShearStress(stress, state), c, 1e-10 * c);
  std::printf("  sigma_xx = %.6f, sigma_yy = %.6f, sigma_zz = %.6f Pa\n", stress(0, 0),
              stress(1, 1), state.out_of_plane_stress);
}

// Random velocity gradients (strain increments ~ the yield strain per step, 5000 steps): the
// stress never leaves the surface by more than 1e-10 relative, and the mean stress stays the
// elastic K sum tr(d eps): Tresca flow changes no volume. Round-off over 5000 steps ~ 1e-12.
template <int Dim>
void trescaRandomPaths()
{
  const Tresca model = sand();
  const double c = kSandCohesion, K = kSand.bulk_modulus;
  std::mt19937_64 rng(Dim);
  Mat<Dim> stress;
  MaterialState state;
  double volumetric_strain = 0, worst_excess = 0, worst_pressure = 0;
  const double dt = 1e-5;
  for (int n = 0; n < 5000; ++n) {
    const Mat<Dim> L = testing::randomMatrix<Dim>(rng, 1.0);
    volumetric_strain += dt * trace(L);
    model.update(step(L, dt), state, stress);
    worst_excess = std::max(worst_excess, (maxShearStress(stress, state) - c) / c);
    const double p_elastic = K * volumetric_strain;
    worst_pressure = std::max(worst_pressure, std::abs(meanStress(stress, state) - p_elastic) /
                                                  std::max(std::abs(p_elastic), c));
  }
  EXPECT_GT(state.equivalent_plastic_strain, 1e-3);  // the path did yield, many times
  EXPECT_LT(worst_excess, 1e-10);
  EXPECT_LT(worst_pressure, 1e-10);
  EXPECT_LT(std::abs(state.volumetric_plastic_strain), 1e-15);
  std::printf("  [Dim %d] eps_p_eq = %.3e; max (tau_max - c)/c = %.2e; max pressure error "
              "%.2e relative\n",
              Dim, state.equivalent_plastic_strain, worst_excess, worst_pressure);
}
TEST(Tresca, RandomPathsStayInsideYieldSurfaceWithoutVolumeChange2D) { trescaRandomPaths<2>(); }
TEST(Tresca, RandomPathsStayInsideYieldSurfaceWithoutVolumeChange3D) { trescaRandomPaths<3>(); }

TEST(Tresca, RejectsNonPositiveCohesion)
{
  EXPECT_THROW(Tresca(TrescaParameters{kSand, 0.0}), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Drucker-Prager

DruckerPrager soil(double phi, double psi, double cohesion,
                   DruckerPragerFit fit = DruckerPragerFit::PlaneStrain)
{
  return DruckerPrager(DruckerPragerParameters{kSand, phi, cohesion, psi, fit});
}

Mat<2> isotropic2(double mean) { Mat<2> s; s(0, 0) = s(1, 1) = mean; return s; }

// Coefficients of the fits against the textbook closed forms (de Souza Neto et al. 2008,
// eqs. 6.121-6.122): the same formulas rearranged, so agreement to a few ulp (1e-14).
TEST(DruckerPrager, FitsMatchTextbookCoefficients)
{
  const double phi = 30.0, s = 0.5, co = std::sqrt(3.0) / 2, t = std::tan(degreesToRadians(30.0));
  const DruckerPrager associated = soil(phi, phi, 1.0);
  EXPECT_NEAR(associated.eta(), 3 * t / std::sqrt(9 + 12 * t * t), 1e-14);
  EXPECT_NEAR(associated.xi(), 3 / std::sqrt(9 + 12 * t * t), 1e-14);
  EXPECT_NEAR(associated.etaBar(), associated.eta(), 1e-14);
  const DruckerPrager no_dilatancy = soil(phi, 0.0, 1.0);
  EXPECT_NEAR(no_dilatancy.eta(), s, 1e-15);
  EXPECT_NEAR(no_dilatancy.xi(), co, 1e-15);
  EXPECT_EQ(no_dilatancy.etaBar(), 0.0);
  const DruckerPrager outer = soil(phi, phi, 1.0, DruckerPragerFit::OuterCone);
  EXPECT_NEAR(outer.eta(), 6 * s / (std::sqrt(3.0) * (3 - s)), 1e-14);
  EXPECT_NEAR(outer.xi(), 6 * co / (std::sqrt(3.0) * (3 - s)), 1e-14);
  const DruckerPrager inner = soil(phi, phi, 1.0, DruckerPragerFit::InnerCone);
  EXPECT_NEAR(inner.eta(), 6 * s / (std::sqrt(3.0) * (3 + s)), 1e-14);
  EXPECT_THROW(soil(30.0, 35.0, 1.0), std::invalid_argument);
  EXPECT_THROW(soil(0.0, 0.0, 0.0), std::invalid_argument);
}

/// Drives a plane-strain particle from isotropic stress -p0 along a constant in-plane principal
/// strain rate (rate_x, rate_y) to its limit state; returns the in-plane shear strength
/// t = (sigma_1 - sigma_3)/2 and the in-plane mean pressure p_in = -(sigma_1 + sigma_3)/2.
struct LimitState {
  double t, p_in, plastic_dilation_per_step, last_change;
};
LimitState planeStrainLimit(const DruckerPrager& model, double p0, double rate_x, double rate_y,
                            int steps)
{
  Mat<2> stress = isotropic2(-p0);
  MaterialState state;
  state.out_of_plane_stress = -p0;
  Mat<2> L;
  L(0, 0) = rate_x;
  L(1, 1) = rate_y;
  const double dt = 1e-5;
  LimitState r{};
  for (int n = 0; n < steps; ++n) {
    const Mat<2> before = stress;
    const double volumetric_before = state.volumetric_plastic_strain;
    model.update(step(L, dt), state, stress);
    r.plastic_dilation_per_step = state.volumetric_plastic_strain - volumetric_before;
    r.last_change = testing::maxAbsDifference(stress, before);
  }
  // L is diagonal, so x and y are principal directions.
  r.t = 0.5 * std::abs(stress(0, 0) - stress(1, 1));
  r.p_in = -0.5 * (stress(0, 0) + stress(1, 1));
  return r;
}

// Shear strength grows with confinement as Mohr-Coulomb's c cos(phi) + p sin(phi) in plane strain
// (the fit's defining property). Pure shear from isotropic pressure p0 = 0, 10 and 100 kPa,
// phi = 30 deg, psi = 0 (so the pressure stays p0): the stress converges to the limit state
// exponentially in the plastic strain (rate ~ G / t), and 20000 steps of 1e-5 reach it to round-off.
// Relative tolerance 1e-9 (measured ~1e-15).
TEST(DruckerPrager, PlaneStrainShearStrengthGrowsWithConfiningPressure)
{
  const double phi = 30.0, c = 1000.0;
  const DruckerPrager model = soil(phi, 0.0, c);
  const double sin_phi = std::sin(degreesToRadians(phi)), cos_phi = std::cos(degreesToRadians(phi));
  double previous_t = 0;
  for (double p0 : {0.0, 1e4, 1e5}) {
    const LimitState s = planeStrainLimit(model, p0, 1.0, -1.0, 20000);
    const double mohr_coulomb = c * cos_phi + s.p_in * sin_phi;
    EXPECT_NEAR(s.p_in, p0, 1e-9 * (p0 + c));  // psi = 0 and isochoric: pressure unchanged
    EXPECT_NEAR(s.t, mohr_coulomb, 1e-9 * mohr_coulomb);
    EXPECT_LT(std::abs(s.last_change), 1e-9 * mohr_coulomb);  // converged
    EXPECT_GT(s.t, previous_t);
    previous_t = s.t;
    std::printf("  p0 = %6.0f Pa: t = %.9f Pa, c cos(phi) + p sin(phi) = %.9f Pa\n", p0, s.t,
                mohr_coulomb);
  }
}

// With dilatancy psi = 15 deg (phi = 30): a path that expands at Mohr-Coulomb's plane-strain
// dilation rate, d eps_v / (d eps_1 - d eps_3) = sin(psi), reaches a limit state where all strain
// is plastic. There the stress satisfies t = c cos(phi) + p_in sin(phi) and the plastic dilation
// per step equals the imposed one, 2 rate dt sin(psi). Same convergence argument as above.
TEST(DruckerPrager, DilatantPlaneStrainLimitStateMatchesMohrCoulomb)
{
  const double phi = 30.0, psi = 15.0, c = 1000.0, p0 = 5e4;
  const DruckerPrager model = soil(phi, psi, c);
  const double sin_psi = std::sin(degreesToRadians(psi));
  const double rate = 1.0;
  const LimitState s = planeStrainLimit(model, p0, rate * (1 + sin_psi), -rate * (1 - sin_psi),
                                        20000);
  const double mohr_coulomb =
      c * std::cos(degreesToRadians(phi)) + s.p_in * std::sin(degreesToRadians(phi));
  EXPECT_NEAR(s.t, mohr_coulomb, 1e-9 * mohr_coulomb);
  EXPECT_NEAR(s.plastic_dilation_per_step, 2 * rate * 1e-5 * sin_psi, 1e-9 * 2e-5 * sin_psi);
  std::printf("  p_in = %.3f Pa, t = %.9f Pa, Mohr-Coulomb %.9f Pa; plastic dilation per step "
              "%.9e (imposed %.9e)\n",
              s.p_in, s.t, mohr_coulomb, s.plastic_dilation_per_step, 2 * rate * 1e-5 * sin_psi);
}

// 3-D: under any path the stress stays in the cone sqrt(J2) <= xi c + eta p_c (to 1e-10 of the
// strength), and with psi = 0 the plastic volume change is zero away from the apex.
TEST(DruckerPrager, RandomPathsStayInsideTheCone3D)
{
  const double c = 1000.0;
  const DruckerPrager model = soil(30.0, 0.0, c);
  std::mt19937_64 rng(99);
  Mat<3> stress;
  for (int i = 0; i < 3; ++i) stress(i, i) = -2e4;  // confined, away from the apex
  MaterialState state;
  double worst = 0;
  for (int n = 0; n < 5000; ++n) {
    Mat<3> L = testing::randomMatrix<3>(rng, 1.0);
    for (int i = 0; i < 3; ++i) L(i, i) -= trace(L) / 3.0;  // isochoric: stays confined
    model.update(step(L, 1e-5), state, stress);
    const double strength = model.xi() * c - model.eta() * trace(stress) / 3.0;
    worst = std::max(worst, model.yieldFunction(stress) / strength);
  }
  EXPECT_GT(state.equivalent_plastic_strain, 1e-3);
  EXPECT_LT(worst, 1e-10);
  EXPECT_LT(std::abs(state.volumetric_plastic_strain), 1e-18);
  std::printf("  eps_p_eq = %.3e, max f / strength = %.2e, eps_p_vol = %.2e\n",
              state.equivalent_plastic_strain, worst, state.volumetric_plastic_strain);
}

// Dilatant (psi = 10 deg) along random, volume-changing paths that also open the material into
// tension and onto the apex: never outside the cone, and plastic volume change only ever dilation.
TEST(DruckerPrager, RandomDilatantPathsStayInsideTheConeAndApex3D)
{
  const double c = 500.0;
  const DruckerPrager model = soil(30.0, 10.0, c);
  std::mt19937_64 rng(123);
  Mat<3> stress;
  MaterialState state;
  double worst = 0, previous_volumetric = 0;
  bool dilation_only = true;
  int apex_steps = 0;
  for (int n = 0; n < 5000; ++n) {
    Mat<3> L = testing::randomMatrix<3>(rng, 1.0);
    if (n % 1000 < 100)
      for (int i = 0; i < 3; ++i) L(i, i) += 2.0;  // bursts of expansion drive it onto the apex
    model.update(step(L, 1e-5), state, stress);
    if (frobeniusNorm(deviator(stress)) == 0.0) ++apex_steps;
    const double strength = std::max(model.xi() * c - model.eta() * trace(stress) / 3.0, c);
    worst = std::max(worst, model.yieldFunction(stress) / strength);
    dilation_only = dilation_only && state.volumetric_plastic_strain >= previous_volumetric;
    previous_volumetric = state.volumetric_plastic_strain;
  }
  EXPECT_GT(state.volumetric_plastic_strain, 1e-4);
  EXPECT_GT(apex_steps, 0);
  EXPECT_LT(worst, 1e-10);  // the return is closed form: round-off only
  EXPECT_TRUE(dilation_only);
  std::printf("  eps_p_eq = %.3e, eps_p_vol = %.3e, %d steps ended on the apex, max f / strength "
              "= %.2e\n",
              state.equivalent_plastic_strain, state.volumetric_plastic_strain, apex_steps, worst);
}

// Tension beyond the apex: the stress returns to the apex, sigma = (xi c / eta) I, with zero
// deviator, whether the trial is hydrostatic or carries shear. The apex stress is assigned, not
// computed, so the only error is one rounding: tolerance 1e-12 of the apex stress.
TEST(DruckerPrager, TensionBeyondTheApexReturnsToTheApex)
{
  const double c = 1000.0;
  const DruckerPrager model = soil(30.0, 0.0, c);
  const double apex = model.apexMeanStress();
  EXPECT_NEAR(apex, c * std::sqrt(3.0), 1e-12 * c);  // xi/eta = cot(30 deg) = sqrt(3) for psi = 0
  for (double shear : {0.0, 0.3}) {
    Mat<3> L;
    for (int i = 0; i < 3; ++i) L(i, i) = 1.0;
    L(0, 1) = shear;
    Mat<3> stress;
    MaterialState state;
    model.update(step(L, 1e-3), state, stress);  // trial p = 3K * 1e-3 / 3 = 33 kPa >> apex
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        EXPECT_NEAR(stress(i, j), i == j ? apex : 0.0, 1e-12 * apex);
    // The excess tension becomes volumetric plastic strain: tr(d eps) - apex / K.
    EXPECT_NEAR(state.volumetric_plastic_strain, 3e-3 - apex / kSand.bulk_modulus, 1e-15);
    std::printf("  shear %.1f: sigma = %.6f I Pa (apex %.6f), eps_p_vol = %.6e\n", shear,
                stress(0, 0), apex, state.volumetric_plastic_strain);
  }
}

// Plane strain with an in-plane isotropic tension that passes the apex: sigma_zz is part of the
// apex return, so all three normal stresses land on the apex.
TEST(DruckerPrager, PlaneStrainApexIncludesOutOfPlaneStress)
{
  const DruckerPrager model = soil(30.0, 10.0, 500.0);
  Mat<2> L;
  L(0, 0) = L(1, 1) = 1.0;
  Mat<2> stress;
  MaterialState state;
  model.update(step(L, 1e-3), state, stress);
  const double apex = model.apexMeanStress();
  EXPECT_NEAR(stress(0, 0), apex, 1e-12 * apex);
  EXPECT_NEAR(stress(1, 1), apex, 1e-12 * apex);
  EXPECT_NEAR(state.out_of_plane_stress, apex, 1e-12 * apex);
}

}  // namespace
}  // namespace cfdmpm::mpm
