// Elastic models: linear elasticity (hypo-elastic rate form) and compressible Neo-Hookean.
#include "mpm/constitutive/linear_elastic.hpp"
#include "mpm/constitutive/neo_hookean.hpp"
#include "mpm_test_helpers.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace cfdmpm::mpm {
namespace {

using testing::maxAbsDifference;
using testing::step;

// The seed paper's sand moduli: E = 50 MPa, nu = 0.25, so K = 33.3 MPa, G = 20 MPa, lambda = 20 MPa.
const ElasticModuli kSand = ElasticModuli::fromYoungPoisson(50e6, 0.25);

TEST(ElasticModuli, YoungPoissonConversion)
{
  // Exact arithmetic up to one rounding per operation.
  EXPECT_NEAR(kSand.bulk_modulus, 50e6 / 1.5, 1e-8);
  EXPECT_NEAR(kSand.shear_modulus, 20e6, 1e-8);
  EXPECT_NEAR(kSand.lame(), 20e6, 1e-7);
  EXPECT_THROW(ElasticModuli::fromYoungPoisson(50e6, 0.5), std::invalid_argument);
  EXPECT_THROW(ElasticModuli::fromBulkShear(-1.0, 1.0), std::invalid_argument);
}

// Uniaxial strain eps_xx = eps in 100 equal increments: sigma_xx = (lambda + 2G) eps,
// sigma_yy = sigma_zz = lambda eps. The sum of 100 increments carries ~100 ulp of round-off:
// relative tolerance 1e-13.
template <int Dim>
void uniaxialStrain()
{
  const LinearElastic model(LinearElasticParameters{kSand});
  Mat<Dim> L;
  L(0, 0) = 1e-2;  // 1/s
  const double dt = 1e-3;
  Mat<Dim> stress;
  MaterialState state;
  for (int n = 0; n < 100; ++n) model.update(step(L, dt), state, stress);
  const double eps = 1e-3;
  const double sigma_xx = (kSand.lame() + 2 * kSand.shear_modulus) * eps;  // 60 kPa
  const double sigma_lateral = kSand.lame() * eps;                         // 20 kPa
  EXPECT_NEAR(stress(0, 0), sigma_xx, 1e-13 * sigma_xx);
  EXPECT_NEAR(stress(1, 1), sigma_lateral, 1e-13 * sigma_xx);
  const double sigma_zz = Dim == 3 ? stress(Dim - 1, Dim - 1) : state.out_of_plane_stress;
  EXPECT_NEAR(sigma_zz, sigma_lateral, 1e-13 * sigma_xx);
  EXPECT_NEAR(stress(0, 1), 0.0, 1e-13 * sigma_xx);
  std::printf("  [Dim %d] sigma_xx = %.10g Pa (expected %.10g), lateral %.10g (expected %.10g)\n",
              Dim, stress(0, 0), sigma_xx, stress(1, 1), sigma_lateral);
}
TEST(LinearElastic, UniaxialStrainGivesConstrainedModulus2D) { uniaxialStrain<2>(); }
TEST(LinearElastic, UniaxialStrainGivesConstrainedModulus3D) { uniaxialStrain<3>(); }

// A pure spin W carries a pre-stressed particle through a rigid rotation. The Hughes-Winget
// increment is an exact rotation by 2 atan(omega dt / 2) per step, so after n steps the stress is
// Q sigma_0 Q^T with that angle; 1000 matrix products accumulate ~1e-13 relative round-off.
TEST(LinearElastic, RigidRotationRotatesTheStress)
{
  const LinearElastic model(LinearElasticParameters{kSand});
  const double omega = 2.0;  // rad/s
  const double dt = 1e-3;
  const int steps = 1000;
  Mat<3> L;  // v = omega e_z x r: L = [[0, -omega, 0], [omega, 0, 0], [0, 0, 0]]
  L(0, 1) = -omega;
  L(1, 0) = omega;
  Mat<3> sigma0;
  sigma0(0, 0) = -3e4;
  sigma0(1, 1) = 1e4;
  sigma0(2, 2) = -5e3;
  sigma0(0, 1) = sigma0(1, 0) = 7e3;
  sigma0(1, 2) = sigma0(2, 1) = 2e3;
  Mat<3> stress = sigma0;
  MaterialState state;
  for (int n = 0; n < steps; ++n) model.update(step(L, dt), state, stress);
  const double axis[3] = {0, 0, 1};
  const Mat<3> Q = testing::rotation3(axis, steps * 2.0 * std::atan(0.5 * omega * dt));
  const Mat<3> expected = Q * sigma0 * transpose(Q);
  const double error = maxAbsDifference(stress, expected);
  EXPECT_LT(error, 1e-12 * 3e4);
  std::printf("  rotation by %.4f rad: max |sigma - Q sigma0 Q^T| = %.2e Pa\n",
              steps * 2.0 * std::atan(0.5 * omega * dt), error);
}

// Neo-Hookean for |H| = eps small (F = I + H): sigma = lambda tr(e) I + 2G e + O(eps^2), e = sym H.
// The check is the order itself: the difference to linear elasticity, divided by eps^2 K, stays
// O(1) (bound 10) and is the same at eps and eps/2 (ratio 1 + O(eps): within 1 +- 1e-2), i.e. the
// difference is exactly second order.
template <int Dim>
void neoHookeanSmallStrain()
{
  const NeoHookean model(NeoHookeanParameters{kSand});
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat<Dim> direction = testing::randomMatrix<Dim>(rng, 1.0);
    double errors[2];
    for (int level = 0; level < 2; ++level) {
      const double eps = 1e-4 / (1 << level);
      const Mat<Dim> H = eps * direction;
      StepKinematics<Dim> k;
      k.deformation_gradient = Mat<Dim>::identity() + H;
      Mat<Dim> stress;
      MaterialState state;
      model.update(k, state, stress);
      const Mat<Dim> e = symmetricPart(H);
      Mat<Dim> linear = (2 * kSand.shear_modulus) * e;
      for (int i = 0; i < Dim; ++i) linear(i, i) += kSand.lame() * trace(e);
      errors[level] = maxAbsDifference(stress, linear) / (eps * eps * kSand.bulk_modulus);
      if constexpr (Dim == 2) {
        // Plane strain: sigma_zz = lambda tr(e) + O(eps^2).
        errors[level] = std::max(errors[level],
                                 std::abs(state.out_of_plane_stress - kSand.lame() * trace(e)) /
                                     (eps * eps * kSand.bulk_modulus));
      }
    }
    EXPECT_LT(errors[0], 10.0);
    const double ratio = errors[0] / errors[1];
    EXPECT_NEAR(ratio, 1.0, 1e-2);
    if (trial == 0)
      std::printf("  [Dim %d] |sigma_NH - sigma_lin| / (eps^2 K) = %.3f at eps 1e-4, scaled ratio "
                  "eps / (eps/2) %.5f\n",
                  Dim, errors[0], ratio);
  }
}
TEST(NeoHookean, ReducesToLinearElasticityForSmallStrain2D) { neoHookeanSmallStrain<2>(); }
TEST(NeoHookean, ReducesToLinearElasticityForSmallStrain3D) { neoHookeanSmallStrain<3>(); }

// Objectivity: sigma(Q F) = Q sigma(F) Q^T for a finite deformation (|F - I| up to 0.3) and a
// finite rotation. Both sides are the same arithmetic in a rotated frame: relative round-off of a
// few hundred ulp of the stress scale, tolerance 1e-12.
TEST(NeoHookean, IsObjective3D)
{
  const NeoHookean model(NeoHookeanParameters{ElasticModuli::fromBulkShear(1.17e9, 4.38e8)});
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat<3> F = Mat<3>::identity() + testing::randomMatrix<3>(rng, 0.3);
    ASSERT_GT(determinant(F), 0.0);
    const double axis[3] = {0.3, -1.0, 0.7 + 0.01 * trial};
    const Mat<3> Q = testing::rotation3(axis, 0.1 + 0.1 * trial);
    StepKinematics<3> k, kq;
    k.deformation_gradient = F;
    kq.deformation_gradient = Q * F;
    Mat<3> sigma, sigma_q;
    MaterialState state;
    model.update(k, state, sigma);
    model.update(kq, state, sigma_q);
    const Mat<3> expected = Q * sigma * transpose(Q);
    EXPECT_LT(maxAbsDifference(sigma_q, expected), 1e-12 * frobeniusNorm(sigma));
  }
}

TEST(NeoHookean, IsObjectivePlaneStrain)
{
  const NeoHookean model(NeoHookeanParameters{ElasticModuli::fromBulkShear(1.17e9, 4.38e8)});
  std::mt19937_64 rng(6);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat<2> F = Mat<2>::identity() + testing::randomMatrix<2>(rng, 0.3);
    const Mat<2> Q = testing::rotation2(0.37 * trial);
    StepKinematics<2> k, kq;
    k.deformation_gradient = F;
    kq.deformation_gradient = Q * F;
    Mat<2> sigma, sigma_q;
    MaterialState state, state_q;
    model.update(k, state, sigma);
    model.update(kq, state_q, sigma_q);
    const double scale = frobeniusNorm(sigma);
    EXPECT_LT(maxAbsDifference(sigma_q, Q * sigma * transpose(Q)), 1e-12 * scale);
    // An in-plane rotation leaves sigma_zz unchanged.
    EXPECT_NEAR(state_q.out_of_plane_stress, state.out_of_plane_stress, 1e-12 * scale);
  }
}

// A stress-free reference: F = I gives sigma = 0 exactly.
TEST(NeoHookean, ReferenceStateIsStressFree)
{
  const NeoHookean model(NeoHookeanParameters{kSand});
  StepKinematics<3> k;
  k.deformation_gradient = Mat<3>::identity();
  Mat<3> sigma;
  MaterialState state;
  model.update(k, state, sigma);
  EXPECT_EQ(frobeniusNorm(sigma), 0.0);
}

}  // namespace
}  // namespace cfdmpm::mpm
