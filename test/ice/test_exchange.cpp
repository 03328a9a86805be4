// Implicit momentum and heat exchange: velocity equilibrium in one step at K = 1e15 with momentum
// conserved to round-off, no change at K = 0, the closed-form two-material answer, a quad-precision
// solve of Uintah's form as the reference at every K, energy conservation, and the face exchange.
#include "ice/exchange.hpp"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace cfdmpm::ice;

namespace {

using Velocity2 = Kokkos::Array<double, 2>;

// Water, air and sand in one cell at about 1.2 bar: volume fractions, specific volumes [m^3/kg]
// and mass densities rho_CC = theta/v (consistent, as after the equilibration).
struct Cell {
  int count = 3;
  MaterialArray<double> volume_fraction;
  MaterialArray<double> specific_volume;
  MaterialArray<double> mass_density;
  MaterialArray<Velocity2> velocity;
};

Cell waterAirSand()
{
  Cell cell;
  const double theta[3] = {0.5, 0.1, 0.4};
  const double v[3] = {1.0 / 1000.3, 1.0 / 1.505, 1.0 / 1985.0};
  const Velocity2 u[3] = {{0.3, -0.1}, {2.0, 1.5}, {-0.5, 0.2}};
  for (int m = 0; m < 3; ++m) {
    cell.volume_fraction[m] = theta[m];
    cell.specific_volume[m] = v[m];
    cell.mass_density[m] = theta[m] / v[m];
    cell.velocity[m] = u[m];
  }
  return cell;
}

double momentum(const Cell& cell, const MaterialArray<Velocity2>& u, int d)
{
  double sum = 0.0;
  for (int m = 0; m < cell.count; ++m) sum += cell.mass_density[m] * u[m][d];
  return sum;
}

double momentumMagnitudeSum(const Cell& cell, const MaterialArray<Velocity2>& u, int d)
{
  double sum = 0.0;
  for (int m = 0; m < cell.count; ++m) sum += cell.mass_density[m] * std::fabs(u[m][d]);
  return sum;
}

// Uintah's form solved in quad precision: A u' = u, A = I + diag(sum beta) - beta,
// beta_mn = dt v_m theta_n K_mn, Gaussian elimination with partial pivoting. Its own error is
// ~ 1e-34 * beta, far below double round-off for every beta used here (<= 1e18).
#ifdef __SIZEOF_FLOAT128__
using Quad = __float128;
constexpr bool kHaveQuad = true;
#else
using Quad = long double;  // quad only where long double is (e.g. aarch64); else the test skips
constexpr bool kHaveQuad = LDBL_MANT_DIG >= 113;
#endif

std::vector<double> quadReference(int count, double dt, double K, const MaterialArray<double>& theta,
                                  const MaterialArray<double>& rate_scale, const std::vector<double>& q)
{
  Quad a[kMaxMaterials][kMaxMaterials + 1];
  for (int m = 0; m < count; ++m) {
    Quad diagonal = 1;
    for (int n = 0; n < count; ++n) {
      if (n == m) continue;
      const Quad beta = Quad(dt) * Quad(rate_scale[m]) * Quad(theta[n]) * Quad(K);
      a[m][n] = -beta;
      diagonal += beta;
    }
    a[m][m] = diagonal;
    a[m][count] = q[m];
  }
  for (int k = 0; k < count; ++k) {
    int best = k;
    for (int i = k + 1; i < count; ++i)
      if ((a[i][k] < 0 ? -a[i][k] : a[i][k]) > (a[best][k] < 0 ? -a[best][k] : a[best][k])) best = i;
    for (int j = 0; j <= count; ++j) {
      const Quad t = a[k][j];
      a[k][j] = a[best][j];
      a[best][j] = t;
    }
    for (int i = k + 1; i < count; ++i) {
      const Quad l = a[i][k] / a[k][k];
      for (int j = k; j <= count; ++j) a[i][j] -= l * a[k][j];
    }
  }
  std::vector<double> x(count);
  Quad xq[kMaxMaterials];
  for (int k = count - 1; k >= 0; --k) {
    Quad s = a[k][count];
    for (int j = k + 1; j < count; ++j) s -= a[k][j] * xq[j];
    xq[k] = s / a[k][k];
    x[k] = double(xq[k]);
  }
  return x;
}

}  // namespace

TEST(Exchange, ReachesCommonVelocityInOneStepAndConservesMomentum)
{
  // K = 1e15 (the seed scene's coefficient) and dt = 1e-4 s. The weakest coupling is sand's to air,
  // beta = dt v_sand theta_air K = 5e6, so the implicit step leaves a spread of about 1/beta = 2e-7
  // of the initial one (two materials: exactly d/(1 + beta_12 + beta_21)).
  Cell cell = waterAirSand();
  const MaterialArray<Velocity2> before = cell.velocity;
  ASSERT_EQ(exchangeMomentumCC<2>(cell.count, 1e-4, ExchangeCoefficients::uniform(1e15), cell.mass_density,
                                  cell.volume_fraction, cell.specific_volume, cell.velocity),
            ExchangeStatus::Ok);
  double total_mass = 0.0;
  for (int m = 0; m < cell.count; ++m) total_mass += cell.mass_density[m];
  for (int d = 0; d < 2; ++d) {
    const double common = momentum(cell, before, d) / total_mass;
    for (int m = 0; m < cell.count; ++m)
      EXPECT_NEAR(cell.velocity[m][d], common, 4e-7) << "material " << m;  // spread 2.5 m/s * 2e-7 * 0.8
    // Conservation: the mean carries sum m u with n+1 roundings, the projection leaves
    // sum m d at n roundings of sum m |d|, and this test's own sum adds n more: (3n + 1) eps of
    // sum m |u| = 10 eps for n = 3. (A direct solve of Uintah's form loses eps * beta ~ 1e-9 here.)
    EXPECT_NEAR(momentum(cell, cell.velocity, d), momentum(cell, before, d),
                10.0 * DBL_EPSILON * momentumMagnitudeSum(cell, before, d));
  }
}

TEST(Exchange, MatchesQuadPrecisionSolveForEveryK)
{
  // The error of the exchanged velocity must not grow with K: compare with Uintah's form solved in
  // quad precision, from K = 0.1 (beta ~ 1e-6) to K = 1e18 (beta ~ 1e9, where a double-precision
  // solve of Uintah's form has lost all but 7 digits of the common velocity).
  if (!kHaveQuad) GTEST_SKIP() << "no quad precision type";
  const Cell start = waterAirSand();
  std::printf("  K          max |u - u_quad| / max |u|\n");
  for (double K = 0.1; K <= 1e18; K *= 100.0) {
    Cell cell = start;
    ASSERT_EQ(exchangeMomentumCC<2>(cell.count, 1e-4, ExchangeCoefficients::uniform(K), cell.mass_density,
                                    cell.volume_fraction, cell.specific_volume, cell.velocity),
              ExchangeStatus::Ok);
    double worst = 0.0;
    for (int d = 0; d < 2; ++d) {
      std::vector<double> q(cell.count);
      for (int m = 0; m < cell.count; ++m) q[m] = start.velocity[m][d];
      const std::vector<double> reference =
          quadReference(cell.count, 1e-4, K, cell.volume_fraction, cell.specific_volume, q);
      for (int m = 0; m < cell.count; ++m)
        worst = std::fmax(worst, std::fabs(cell.velocity[m][d] - reference[m]) / 2.0);  // max |u| = 2
    }
    std::printf("  %-9.1e  %.2e\n", K, worst);
    // A few roundings of the largest velocity: the mean (n + 1), the elimination and the
    // projection (n each) add up to about 3n + 1 = 10 eps.
    EXPECT_LE(worst, 10.0 * DBL_EPSILON) << "K " << K;
  }
}

TEST(Exchange, StaysExactWhenOnePlusBetaRoundsToBeta)
{
  // dt = 1000 s with K = 1e15: beta up to 3e17, so 1 + beta == beta in double. A Gaussian
  // elimination of Uintah's form then meets a pivot that is pure round-off; the subtraction-free
  // elimination does not, and the result is the common velocity to round-off.
  Cell cell = waterAirSand();
  const MaterialArray<Velocity2> before = cell.velocity;
  ASSERT_EQ(exchangeMomentumCC<2>(cell.count, 1000.0, ExchangeCoefficients::uniform(1e15), cell.mass_density,
                                  cell.volume_fraction, cell.specific_volume, cell.velocity),
            ExchangeStatus::Ok);
  double total_mass = 0.0;
  for (int m = 0; m < cell.count; ++m) total_mass += cell.mass_density[m];
  for (int d = 0; d < 2; ++d) {
    const double common = momentum(cell, before, d) / total_mass;
    for (int m = 0; m < cell.count; ++m)
      // The exact spread is ~1e-17 of the initial one (beta >= 5e16); what is left is round-off of
      // the largest velocity (2 m/s), as in the conservation bound below.
      EXPECT_NEAR(cell.velocity[m][d], common, 10.0 * DBL_EPSILON * 2.0);
    EXPECT_NEAR(momentum(cell, cell.velocity, d), momentum(cell, before, d),
                10.0 * DBL_EPSILON * momentumMagnitudeSum(cell, before, d));  // as above
  }
}

TEST(Exchange, ZeroCoefficientsLeaveVelocitiesUnchanged)
{
  // K = 0: no exchange at all; the values must come back bit for bit (no rounding through a solve).
  Cell cell = waterAirSand();
  const MaterialArray<Velocity2> before = cell.velocity;
  ASSERT_EQ(exchangeMomentumCC<2>(cell.count, 1e-4, ExchangeCoefficients(), cell.mass_density,
                                  cell.volume_fraction, cell.specific_volume, cell.velocity),
            ExchangeStatus::Ok);
  for (int m = 0; m < cell.count; ++m)
    for (int d = 0; d < 2; ++d) EXPECT_EQ(cell.velocity[m][d], before[m][d]);
}

TEST(Exchange, TwoMaterialsMatchTheClosedForm)
{
  // For two materials the implicit step u'_1 = u_1 + b12 (u'_2 - u'_1), u'_2 = u_2 + b21 (u'_1 - u'_2)
  // solves by Cramer's rule:
  //   u'_1 = ((1 + b21) u_1 + b12 u_2) / (1 + b12 + b21),  u'_2 = (b21 u_1 + (1 + b12) u_2) / (1 + b12 + b21),
  // with b_mn = dt v_m theta_n K. Water and air with K chosen so that b12, b21 ~ 0.1 ... 10.
  const double dt = 1e-3;
  const double theta[2] = {0.7, 0.3};
  const double v[2] = {1.0 / 999.9, 1.0 / 1.2};
  const double u[2] = {0.25, -1.75};
  for (double K : {1e2, 1e3, 1e4}) {
    MaterialArray<double> volume_fraction, specific_volume, mass_density;
    MaterialArray<Kokkos::Array<double, 1>> velocity;
    for (int m = 0; m < 2; ++m) {
      volume_fraction[m] = theta[m];
      specific_volume[m] = v[m];
      mass_density[m] = theta[m] / v[m];
      velocity[m][0] = u[m];
    }
    ASSERT_EQ(exchangeMomentumCC<1>(2, dt, ExchangeCoefficients::uniform(K), mass_density, volume_fraction,
                                    specific_volume, velocity),
              ExchangeStatus::Ok);
    const double b12 = dt * v[0] * theta[1] * K;
    const double b21 = dt * v[1] * theta[0] * K;
    const double det = 1.0 + b12 + b21;
    // Both sides are a handful of roundings of values <= 1.75: 8 eps * 1.75.
    EXPECT_NEAR(velocity[0][0], ((1.0 + b21) * u[0] + b12 * u[1]) / det, 8 * DBL_EPSILON * 1.75) << "K " << K;
    EXPECT_NEAR(velocity[1][0], (b21 * u[0] + (1.0 + b12) * u[1]) / det, 8 * DBL_EPSILON * 1.75) << "K " << K;
  }
}

TEST(Exchange, MasslessMaterialIsCarriedAlong)
{
  // A material absent from the cell (no mass, no volume) exerts no force and follows its row of
  // Uintah's system: u' = (u + sum_n beta_mn u'_n)/(1 + sum_n beta_mn), beta_mn = dt v_m theta_n K.
  Cell cell = waterAirSand();
  cell.count = 4;
  cell.volume_fraction[3] = 0.0;
  cell.mass_density[3] = 0.0;
  cell.specific_volume[3] = 1.0 / 900.0;
  cell.velocity[3] = {5.0, -5.0};
  Cell without = waterAirSand();
  const double dt = 1e-4, K = 1e3;
  ASSERT_EQ(exchangeMomentumCC<2>(cell.count, dt, ExchangeCoefficients::uniform(K), cell.mass_density,
                                  cell.volume_fraction, cell.specific_volume, cell.velocity),
            ExchangeStatus::Ok);
  ASSERT_EQ(exchangeMomentumCC<2>(without.count, dt, ExchangeCoefficients::uniform(K), without.mass_density,
                                  without.volume_fraction, without.specific_volume, without.velocity),
            ExchangeStatus::Ok);
  for (int d = 0; d < 2; ++d) {
    double beta_sum = 0.0, pull = 0.0;
    for (int n = 0; n < 3; ++n) {
      EXPECT_EQ(cell.velocity[n][d], without.velocity[n][d]);  // the others do not feel it at all
      const double beta = dt * cell.specific_volume[3] * cell.volume_fraction[n] * K;
      beta_sum += beta;
      pull += beta * cell.velocity[n][d];
    }
    const double initial = d == 0 ? 5.0 : -5.0;
    EXPECT_NEAR(cell.velocity[3][d], (initial + pull) / (1.0 + beta_sum), 8 * DBL_EPSILON * 5.0);  // same formula
  }
}

TEST(Exchange, HeatExchangeConservesEnergy)
{
  // Water, air and sand at different temperatures and specific heats; sum m cv T is invariant for
  // every H, and H = 1e15 brings all to the mass-cv-weighted mean temperature.
  const Cell cell = waterAirSand();
  const double cv[3] = {4145.4, 716.0, 830.0};
  const double T0[3] = {278.15, 300.0, 290.0};
  MaterialArray<double> specific_heat;
  double energy = 0.0, energy_magnitude = 0.0, heat_capacity = 0.0;
  for (int m = 0; m < 3; ++m) {
    specific_heat[m] = cv[m];
    energy += cell.mass_density[m] * cv[m] * T0[m];
    heat_capacity += cell.mass_density[m] * cv[m];
  }
  energy_magnitude = energy;  // all terms positive
  MaterialArray<double> heat_rate_scale;  // beta_mn = dt (v_m/cv_m) theta_n H
  for (int m = 0; m < 3; ++m) heat_rate_scale[m] = cell.specific_volume[m] / cv[m];
  for (double H : {1e3, 1e6, 1e9, 1e15, 1e18}) {
    MaterialArray<double> T;
    for (int m = 0; m < 3; ++m) T[m] = T0[m];
    ASSERT_EQ(exchangeHeatCC(3, 1e-4, ExchangeCoefficients::uniform(H), cell.mass_density, cell.volume_fraction,
                             cell.specific_volume, specific_heat, T),
              ExchangeStatus::Ok);
    double after = 0.0;
    for (int m = 0; m < 3; ++m) after += cell.mass_density[m] * cv[m] * T[m];
    EXPECT_NEAR(after, energy, 10.0 * DBL_EPSILON * energy_magnitude) << "H " << H;  // as for momentum
    if (kHaveQuad) {
      // Uintah's form in quad precision; as for the velocities, a few roundings of T (~300 K).
      const std::vector<double> reference = quadReference(3, 1e-4, H, cell.volume_fraction, heat_rate_scale,
                                                          {T0[0], T0[1], T0[2]});
      for (int m = 0; m < 3; ++m) EXPECT_NEAR(T[m], reference[m], 10.0 * DBL_EPSILON * 300.0) << "H " << H;
    }
    if (H == 1e18) {
      // Weakest coupling: sand to water, dt (v_sand/cv_sand) theta_water H = 3e7, so the spread of
      // 22 K shrinks below 1e-6 K: one common temperature.
      for (int m = 0; m < 3; ++m) EXPECT_NEAR(T[m], energy / heat_capacity, 1e-6);
    }
  }
}

TEST(Exchange, HeatExchangeOfTwoMaterialsMatchesTheClosedForm)
{
  // As for momentum, with b_mn = dt v_m theta_n H / cv_m.
  const double dt = 1e-3, H = 5e4;
  const double theta[2] = {0.6, 0.4}, v[2] = {1.0 / 999.9, 1.0 / 1.2}, cv[2] = {4145.4, 716.0};
  const double T0[2] = {280.0, 310.0};
  MaterialArray<double> volume_fraction, specific_volume, mass_density, specific_heat, T;
  for (int m = 0; m < 2; ++m) {
    volume_fraction[m] = theta[m];
    specific_volume[m] = v[m];
    mass_density[m] = theta[m] / v[m];
    specific_heat[m] = cv[m];
    T[m] = T0[m];
  }
  ASSERT_EQ(exchangeHeatCC(2, dt, ExchangeCoefficients::uniform(H), mass_density, volume_fraction,
                           specific_volume, specific_heat, T),
            ExchangeStatus::Ok);
  const double b12 = dt * v[0] * theta[1] * H / cv[0];
  const double b21 = dt * v[1] * theta[0] * H / cv[1];
  const double det = 1.0 + b12 + b21;
  // The temperatures themselves are ~300 K: the mean-removed form rounds at 300 eps, a few times.
  EXPECT_NEAR(T[0], ((1.0 + b21) * T0[0] + b12 * T0[1]) / det, 8 * DBL_EPSILON * 310.0);
  EXPECT_NEAR(T[1], (b21 * T0[0] + (1.0 + b12) * T0[1]) / det, 8 * DBL_EPSILON * 310.0);
}

TEST(FaceExchange, OneMaterialGivesTheHarmonicMeanSpecificVolume)
{
  MaterialArray<double> theta_l, theta_r, v_l, v_r, u, v_face;
  theta_l[0] = theta_r[0] = 1.0;
  v_l[0] = 1.0 / 1000.0;
  v_r[0] = 1.0 / 1.2;
  u[0] = 0.7;
  ASSERT_EQ(exchangeMomentumFC(1, 1e-4, ExchangeCoefficients::uniform(1e15), theta_l, theta_r, v_l, v_r, u,
                               v_face),
            ExchangeStatus::Ok);
  EXPECT_EQ(u[0], 0.7);                                                   // nothing to exchange with
  EXPECT_EQ(v_face[0], 2.0 * v_l[0] * v_r[0] / (v_l[0] + v_r[0]));       // same expression, bit for bit
}

TEST(FaceExchange, TwoMaterialsMatchTheClosedForm)
{
  // The face system has b_mn = dt vbar_m thetabar_n K with vbar the harmonic mean and thetabar the
  // average; the velocity and the specific volume both go through the same 2x2 inverse.
  const double dt = 1e-3, K = 2e3;
  MaterialArray<double> theta_l, theta_r, v_l, v_r, u, v_face;
  theta_l[0] = 0.9, theta_r[0] = 0.5;
  theta_l[1] = 0.1, theta_r[1] = 0.5;
  v_l[0] = 1.0 / 1000.2, v_r[0] = 1.0 / 1000.1;
  v_l[1] = 1.0 / 1.21, v_r[1] = 1.0 / 1.19;
  u[0] = 0.1, u[1] = 3.0;
  double vbar[2], tbar[2];
  for (int m = 0; m < 2; ++m) {
    vbar[m] = 2.0 * v_l[m] * v_r[m] / (v_l[m] + v_r[m]);
    tbar[m] = 0.5 * (theta_l[m] + theta_r[m]);
  }
  const double u0[2] = {u[0], u[1]};
  ASSERT_EQ(exchangeMomentumFC(2, dt, ExchangeCoefficients::uniform(K), theta_l, theta_r, v_l, v_r, u, v_face),
            ExchangeStatus::Ok);
  const double b12 = dt * vbar[0] * tbar[1] * K, b21 = dt * vbar[1] * tbar[0] * K;
  const double det = 1.0 + b12 + b21;
  EXPECT_NEAR(u[0], ((1.0 + b21) * u0[0] + b12 * u0[1]) / det, 8 * DBL_EPSILON * 3.0);  // few roundings of 3
  EXPECT_NEAR(u[1], (b21 * u0[0] + (1.0 + b12) * u0[1]) / det, 8 * DBL_EPSILON * 3.0);
  EXPECT_NEAR(v_face[0], ((1.0 + b21) * vbar[0] + b12 * vbar[1]) / det, 8 * DBL_EPSILON * vbar[1]);
  EXPECT_NEAR(v_face[1], (b21 * vbar[0] + (1.0 + b12) * vbar[1]) / det, 8 * DBL_EPSILON * vbar[1]);
}

TEST(FaceExchange, LargeKGivesTheMixtureSpecificVolumeAndOneVelocity)
{
  // K = 1e15: every material moves with the face's bulk-density-weighted velocity and responds to
  // the pressure gradient with the mixture's specific volume sum(theta)/sum(theta/v).
  MaterialArray<double> theta_l, theta_r, v_l, v_r, u, v_face;
  theta_l[0] = 0.999, theta_r[0] = 0.2;
  theta_l[1] = 0.001, theta_r[1] = 0.8;
  v_l[0] = 1.0 / 1000.2, v_r[0] = 1.0 / 1000.1;
  v_l[1] = 1.0 / 1.21, v_r[1] = 1.0 / 1.19;
  u[0] = -0.2, u[1] = 1.5;
  double weight_sum = 0.0, theta_sum = 0.0, momentum = 0.0;
  for (int m = 0; m < 2; ++m) {
    const double vbar = 2.0 * v_l[m] * v_r[m] / (v_l[m] + v_r[m]);
    const double tbar = 0.5 * (theta_l[m] + theta_r[m]);
    weight_sum += tbar / vbar;
    theta_sum += tbar;
    momentum += tbar / vbar * u[m];
  }
  ASSERT_EQ(exchangeMomentumFC(2, 1e-4, ExchangeCoefficients::uniform(1e15), theta_l, theta_r, v_l, v_r, u,
                               v_face),
            ExchangeStatus::Ok);
  // Weakest coupling: water from air, dt vbar_w thetabar_a K = 4e7; spread 1.7 m/s / 4e7 = 4e-8.
  for (int m = 0; m < 2; ++m) {
    EXPECT_NEAR(u[m], momentum / weight_sum, 1e-7);
    EXPECT_NEAR(v_face[m], theta_sum / weight_sum, 1e-7 * theta_sum / weight_sum);  // same 1/beta
  }
}

TEST(Exchange, ReportsNonFiniteInput)
{
  Cell cell = waterAirSand();
  cell.velocity[1][0] = std::nan("");
  EXPECT_EQ(exchangeMomentumCC<2>(cell.count, 1e-4, ExchangeCoefficients::uniform(1e15), cell.mass_density,
                                  cell.volume_fraction, cell.specific_volume, cell.velocity),
            ExchangeStatus::NonFinite);
}

TEST(Exchange, ReportsMaterialCountOutOfRange)
{
  Cell cell = waterAirSand();
  EXPECT_EQ(exchangeMomentumCC<2>(kMaxMaterials + 1, 1e-4, ExchangeCoefficients::uniform(1e15),
                                  cell.mass_density, cell.volume_fraction, cell.specific_volume, cell.velocity),
            ExchangeStatus::InvalidInput);
}

// The general elimination's loops throughout (Loops = true: without its written-out pair,
// eliminatePair, or the two-material form): the reference of the written-out forms.
ExchangeStatus loopsCC(int count, double dt, const ExchangeCoefficients& K, const MaterialArray<double>& rho,
                       const MaterialArray<double>& theta, const MaterialArray<double>& v, MaterialArray<Velocity2>& u)
{
  return exchangeMomentumCC<2, 0, true>(count, dt, K, rho, theta, v, u);
}
ExchangeStatus loopsFC(int count, double dt, const ExchangeCoefficients& K, const MaterialArray<double>& theta_l,
                       const MaterialArray<double>& theta_r, const MaterialArray<double>& v_l,
                       const MaterialArray<double>& v_r, MaterialArray<double>& uf, MaterialArray<double>& vf)
{
  return exchangeMomentumFC<0, true>(count, dt, K, theta_l, theta_r, v_l, v_r, uf, vf);
}

// The same velocities (and sign of zero) and status from two exchanges (Ok: values compared).
void expectSameBits(ExchangeStatus s_a, ExchangeStatus s_b, int count, const MaterialArray<Velocity2>& a,
                    const MaterialArray<Velocity2>& b, int trial)
{
  ASSERT_EQ(s_a, s_b) << "trial " << trial;
  if (s_a != ExchangeStatus::Ok) return;
  for (int m = 0; m < count; ++m)
    for (int d = 0; d < 2; ++d) {
      ASSERT_EQ(std::signbit(a[m][d]), std::signbit(b[m][d])) << "trial " << trial;
      ASSERT_EQ(a[m][d], b[m][d]) << "trial " << trial << ", material " << m << ", component " << d;
    }
}

TEST(Exchange, TwoMaterialFormIsTheGeneralEliminationBitForBit)
{
  // The kernels call the exchange with the material count fixed at compile time; for two materials
  // that is a written-out elimination, which must give the general one's results to the bit: both
  // present, one or both without mass, K = 0, 1e3 and 1e15 (with denormal-scale volume fractions),
  // and non-finite input.
  unsigned state = 12345;
  const auto uniform = [&state](double lo, double hi) {
    state = state * 1664525u + 1013904223u;
    return lo + (hi - lo) * double(state >> 8) / double(1u << 24);
  };
  const double coefficients[3] = {0.0, 1e3, 1e15};
  int cases = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const double K = coefficients[trial % 3];
    const double dt = uniform(1e-6, 1e-3);
    MaterialArray<double> theta{}, v{}, rho{};
    MaterialArray<Velocity2> u{};
    for (int m = 0; m < 2; ++m) {
      const int kind = (trial / 3 + m) % 5;  // 0: without mass; 1: a trace; else a share of the cell
      theta[m] = kind == 0 ? 0.0 : kind == 1 ? uniform(1e-300, 1e-12) : uniform(0.0, 1.0);
      v[m] = m == 0 ? uniform(9e-4, 1.1e-3) : uniform(0.7, 0.9);
      rho[m] = theta[m] / v[m];
      u[m] = {uniform(-3.0, 3.0), trial % 7 == 0 ? -0.0 : uniform(-3.0, 3.0)};
    }
    if (trial % 97 == 0) u[trial % 2][1] = std::nan("");
    MaterialArray<Velocity2> general = u, two = u, loops = u;
    const ExchangeStatus s_general =
        exchangeMomentumCC<2>(2, dt, ExchangeCoefficients::uniform(K), rho, theta, v, general);
    const ExchangeStatus s_two =
        exchangeMomentumCC<2, 2>(2, dt, ExchangeCoefficients::uniform(K), rho, theta, v, two);
    const ExchangeStatus s_loops = loopsCC(2, dt, ExchangeCoefficients::uniform(K), rho, theta, v, loops);
    expectSameBits(s_loops, s_two, 2, loops, two, trial);
    expectSameBits(s_loops, s_general, 2, loops, general, trial);

    MaterialArray<double> theta_r{}, v_r{}, uf{}, vf_general{}, vf_two{};
    for (int m = 0; m < 2; ++m) {
      theta_r[m] = (trial / 5) % 3 == 0 ? 0.0 : uniform(0.0, 1.0);
      v_r[m] = v[m] * uniform(0.99, 1.01);
      uf[m] = u[m][0];
    }
    MaterialArray<double> uf_general = uf, uf_two = uf, uf_loops = uf, vf_loops{};
    const ExchangeStatus f_general = exchangeMomentumFC(2, dt, ExchangeCoefficients::uniform(K), theta, theta_r, v,
                                                        v_r, uf_general, vf_general);
    const ExchangeStatus f_two = exchangeMomentumFC<2>(2, dt, ExchangeCoefficients::uniform(K), theta, theta_r, v,
                                                       v_r, uf_two, vf_two);
    const ExchangeStatus f_loops =
        loopsFC(2, dt, ExchangeCoefficients::uniform(K), theta, theta_r, v, v_r, uf_loops, vf_loops);
    ASSERT_EQ(f_general, f_loops) << "trial " << trial;
    ASSERT_EQ(f_two, f_loops) << "trial " << trial;
    if (f_loops == ExchangeStatus::Ok)
      for (int m = 0; m < 2; ++m) {
        ASSERT_EQ(uf_general[m], uf_loops[m]) << "trial " << trial;
        ASSERT_EQ(vf_general[m], vf_loops[m]) << "trial " << trial;
        ASSERT_EQ(uf_two[m], uf_loops[m]) << "trial " << trial;
        ASSERT_EQ(vf_two[m], vf_loops[m]) << "trial " << trial;
      }
    ++cases;
  }
  EXPECT_EQ(cases, 3000);
  // A count that is not the compiled one is refused.
  MaterialArray<double> theta{}, v{}, rho{};
  MaterialArray<Velocity2> u{};
  EXPECT_EQ((exchangeMomentumCC<2, 2>(3, 1e-4, ExchangeCoefficients::uniform(1e15), rho, theta, v, u)),
            ExchangeStatus::InvalidInput);
}

TEST(Exchange, FourMaterialsWithTwoPresentAreTheLoopsBitForBit)
{
  // Four materials (the seed scene's bed, sand, water and air), each without mass, a trace or a
  // share of the cell, so that 0 to 4 are present: the exchange with its pair written out (two
  // present, e.g. water and air where no solid is) gives the loops' results to the bit, with a
  // uniform K and with the seed scene's pattern (the fluids' pair 1e3, a solid and a fluid 1e15,
  // the two solids 0), and non-finite input.
  unsigned state = 2468;
  const auto uniform = [&state](double lo, double hi) {
    state = state * 1664525u + 1013904223u;
    return lo + (hi - lo) * double(state >> 8) / double(1u << 24);
  };
  const auto seed = [] {
    ExchangeCoefficients k = ExchangeCoefficients::uniform(1e15);
    k.set(0, 1, 0.0);
    k.set(2, 3, 1e3);
    return k;
  }();
  const ExchangeCoefficients coefficients[3] = {ExchangeCoefficients::uniform(1e3), seed,
                                                ExchangeCoefficients::uniform(0.0)};
  int pairs = 0;
  for (int trial = 0; trial < 6000; ++trial) {
    const ExchangeCoefficients& K = coefficients[trial % 3];
    const double dt = uniform(1e-6, 1e-3);
    MaterialArray<double> theta{}, v{}, rho{}, theta_r{}, v_r{}, uf{};
    MaterialArray<Velocity2> u{};
    int present = 0;
    for (int m = 0; m < 4; ++m) {
      const int kind = int(uniform(0.0, 3.0 - 1e-9));  // 0: without mass, 1: a trace, 2: a share of the cell
      const int k = m < 2 && trial % 2 == 0 ? 0 : kind;  // half the trials without solids, as most cells
      theta[m] = k == 0 ? 0.0 : k == 1 ? uniform(1e-300, 1e-12) : uniform(0.0, 1.0);
      v[m] = m < 2 ? uniform(3e-4, 6e-4) : m == 2 ? uniform(9e-4, 1.1e-3) : uniform(0.7, 0.9);
      rho[m] = theta[m] / v[m];
      present += rho[m] > 0;
      u[m] = {uniform(-3.0, 3.0), trial % 7 == 0 ? -0.0 : uniform(-3.0, 3.0)};
      theta_r[m] = trial % 5 == 0 ? 0.0 : uniform(0.0, 1.0);
      v_r[m] = v[m] * uniform(0.99, 1.01);
      uf[m] = u[m][0];
    }
    if (trial % 97 == 0) u[trial % 4][1] = std::nan("");
    pairs += present == 2;
    MaterialArray<Velocity2> fixed = u, loops = u;
    const ExchangeStatus s_fixed = exchangeMomentumCC<2, 4>(4, dt, K, rho, theta, v, fixed);
    const ExchangeStatus s_loops = loopsCC(4, dt, K, rho, theta, v, loops);
    expectSameBits(s_loops, s_fixed, 4, loops, fixed, trial);

    MaterialArray<double> uf_fixed = uf, uf_loops = uf, vf_fixed{}, vf_loops{};
    const ExchangeStatus f_fixed = exchangeMomentumFC<4>(4, dt, K, theta, theta_r, v, v_r, uf_fixed, vf_fixed);
    const ExchangeStatus f_loops = loopsFC(4, dt, K, theta, theta_r, v, v_r, uf_loops, vf_loops);
    ASSERT_EQ(f_fixed, f_loops) << "trial " << trial;
    if (f_loops == ExchangeStatus::Ok)
      for (int m = 0; m < 4; ++m) {
        ASSERT_EQ(uf_fixed[m], uf_loops[m]) << "trial " << trial;
        ASSERT_EQ(vf_fixed[m], vf_loops[m]) << "trial " << trial;
      }
  }
  EXPECT_GT(pairs, 1000);  // the written-out pair was taken often (about a third of the trials)
}
