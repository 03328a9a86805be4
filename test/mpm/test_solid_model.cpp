// SolidModel: tag dispatch, visit, wave speeds, and use inside a Kokkos kernel.
#include "mpm/constitutive/solid_model.hpp"
#include "mpm_test_helpers.hpp"

#include <gtest/gtest.h>

#include <Kokkos_Core.hpp>

#include <cstdio>
#include <vector>

namespace cfdmpm::mpm {
namespace {

using testing::step;

const ElasticModuli kSand = ElasticModuli::fromYoungPoisson(50e6, 0.25);
const ElasticModuli kBed = ElasticModuli::fromBulkShear(1.17e9, 4.38e8);

std::vector<SolidModel> allModels()
{
  RigidParameters rigid;
  rigid.velocity[0] = 0.5;
  return {SolidModel(LinearElastic(LinearElasticParameters{kSand})),
          SolidModel(NeoHookean(NeoHookeanParameters{kBed})),
          SolidModel(Tresca(TrescaParameters{kSand, 200.0})),
          SolidModel(DruckerPrager(DruckerPragerParameters{kSand, 30.0, 200.0, 5.0})),
          SolidModel(Rigid(rigid))};
}

// 2-D is plane strain: a 2-D particle follows exactly the 3-D particle whose kinematics have no
// z-motion (L and F embedded with L_zz = 0, F_zz = 1), for every model, along a random path that
// yields the plastic models many times. Same operations on the same numbers, except that the 3-D
// run also carries the zero xz, yz entries: agreement to round-off, 1e-12 of the stress scale.
TEST(SolidModel, PlaneStrainEqualsThreeDimensionalSliceWithoutZMotion)
{
  for (const SolidModel& model : allModels()) {
    std::mt19937_64 rng(17);
    Mat<2> stress2, F2 = Mat<2>::identity();
    Mat<3> stress3, F3 = Mat<3>::identity();
    MaterialState state2, state3;
    double scale = 0, worst = 0;
    for (int n = 0; n < 2000; ++n) {
      const Mat<2> L2 = testing::randomMatrix<2>(rng, 1.0);
      const StepKinematics<2> k2 = step(L2, 1e-5, F2);
      const StepKinematics<3> k3 = step(embedPlaneStrain(L2, 0.0), 1e-5, F3);
      F2 = k2.deformation_gradient;
      F3 = k3.deformation_gradient;
      model.update(k2, state2, stress2);
      model.update(k3, state3, stress3);
      const Mat<3> full2 = embedPlaneStrain(stress2, state2.out_of_plane_stress);
      scale = std::max(scale, frobeniusNorm(stress3));
      worst = std::max(worst, testing::maxAbsDifference(full2, stress3));
    }
    EXPECT_LE(worst, 1e-12 * scale) << model.name();
    EXPECT_NEAR(state2.equivalent_plastic_strain, state3.equivalent_plastic_strain,
                1e-12 * std::max(1.0, state3.equivalent_plastic_strain))
        << model.name();
    std::printf("  %-15s max |sigma_2D - sigma_3D| = %.2e Pa (stress scale %.3e Pa), eps_p_eq "
                "%.3e\n",
                model.name(), worst, scale, state3.equivalent_plastic_strain);
  }
}

// The tagged update is the concrete update: identical arithmetic, so bitwise equal.
TEST(SolidModel, DispatchCallsTheConcreteModel)
{
  std::mt19937_64 rng(3);
  for (const SolidModel& model : allModels()) {
    Mat<2> stress_tagged, stress_direct;
    MaterialState state_tagged, state_direct;
    Mat<2> F = Mat<2>::identity();
    for (int n = 0; n < 50; ++n) {
      const Mat<2> L = testing::randomMatrix<2>(rng, 1.0);
      const StepKinematics<2> k = step(L, 1e-5, F);
      F = k.deformation_gradient;
      model.update(k, state_tagged, stress_tagged);
      model.visit([&](const auto& concrete) { concrete.update(k, state_direct, stress_direct); });
    }
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) EXPECT_EQ(stress_tagged(i, j), stress_direct(i, j));
    EXPECT_EQ(state_tagged.equivalent_plastic_strain, state_direct.equivalent_plastic_strain);
    EXPECT_EQ(state_tagged.out_of_plane_stress, state_direct.out_of_plane_stress);
  }
}

struct KindOf {
  SolidModelKind operator()(const LinearElastic&) const { return SolidModelKind::LinearElastic; }
  SolidModelKind operator()(const NeoHookean&) const { return SolidModelKind::NeoHookean; }
  SolidModelKind operator()(const Tresca&) const { return SolidModelKind::Tresca; }
  SolidModelKind operator()(const DruckerPrager&) const { return SolidModelKind::DruckerPrager; }
  SolidModelKind operator()(const Rigid&) const { return SolidModelKind::Rigid; }
};

TEST(SolidModel, VisitPassesTheConcreteType)
{
  for (const SolidModel& model : allModels()) {
    EXPECT_EQ(model.visit(KindOf{}), model.kind()) << model.name();
    EXPECT_NE(model.getIf<Rigid>() != nullptr, model.kind() != SolidModelKind::Rigid);
  }
  const SolidModel tresca = allModels()[2];
  ASSERT_NE(tresca.getIf<Tresca>(), nullptr);
  EXPECT_EQ(tresca.getIf<Tresca>()->cohesion(), 200.0);
  EXPECT_STREQ(tresca.name(), "tresca");
}

// Time-step speeds sqrt((K + 4G/3) / rho): the seed scene's sand (rho 1985) 173.85 m/s and
// Neo-Hookean bed (rho 8900) 443.9 m/s, the ~440 m/s that limits Uintah's step. Closed forms,
// tolerance a few ulp.
TEST(SolidModel, WaveSpeedsOfTheSeedMaterials)
{
  const auto models = allModels();
  const double sand = models[2].waveSpeed(1985.0);
  const double bed = models[1].waveSpeed(8900.0);
  EXPECT_NEAR(sand, std::sqrt(60e6 / 1985.0), 1e-12 * sand);
  EXPECT_NEAR(bed, std::sqrt((1.17e9 + 4.0 / 3.0 * 4.38e8) / 8900.0), 1e-12 * bed);
  EXPECT_EQ(models[4].waveSpeed(8900.0), 0.0);
  std::printf("  sand %.4f m/s, bed %.4f m/s\n", sand, bed);
}

TEST(SolidModel, RigidCarriesNoStress)
{
  const SolidModel model = allModels()[4];
  Mat<3> stress;
  stress(0, 0) = 5.0;
  MaterialState state;
  model.update(step(Mat<3>::identity(), 1e-3), state, stress);
  EXPECT_EQ(frobeniusNorm(stress), 0.0);
  EXPECT_EQ(model.getIf<Rigid>()->velocity(0), 0.5);
}

// The intended use: visit once per material, then a Kokkos kernel over its particles with the
// concrete model captured by value. Same results as a plain host loop (same arithmetic: exact).
TEST(SolidModel, StressUpdateRunsInAKokkosKernel)
{
  const int particles = 64;
  const SolidModel model = allModels()[2];  // Tresca sand
  Kokkos::View<double* [2][2]> stress("stress", particles);
  Kokkos::View<double*> out_of_plane("out_of_plane", particles);
  Kokkos::View<double*> plastic("plastic", particles);
  const double dt = 1e-6;
  auto shear_rate = [](int p) { return 1.0 + 0.1 * p; };
  for (int n = 0; n < 100; ++n) {
    model.visit([&](const auto& concrete) {
      Kokkos::parallel_for(
          "test::stress_update", Kokkos::RangePolicy<>(0, particles), KOKKOS_LAMBDA(const int p) {
            StepKinematics<2> k;
            k.velocity_gradient(0, 1) = 1.0 + 0.1 * p;
            k.deformation_gradient = Mat<2>::identity();
            k.dt = dt;
            Mat<2> sigma;
            for (int i = 0; i < 2; ++i)
              for (int j = 0; j < 2; ++j) sigma(i, j) = stress(p, i, j);
            MaterialState state;
            state.out_of_plane_stress = out_of_plane(p);
            state.equivalent_plastic_strain = plastic(p);
            concrete.update(k, state, sigma);
            for (int i = 0; i < 2; ++i)
              for (int j = 0; j < 2; ++j) stress(p, i, j) = sigma(i, j);
            out_of_plane(p) = state.out_of_plane_stress;
            plastic(p) = state.equivalent_plastic_strain;
          });
    });
  }
  Kokkos::fence();
  auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), stress);
  for (int p = 0; p < particles; p += 9) {
    Mat<2> sigma;
    MaterialState state;
    Mat<2> L;
    L(0, 1) = shear_rate(p);
    for (int n = 0; n < 100; ++n) model.update(step(L, dt), state, sigma);
    EXPECT_EQ(host(p, 0, 1), sigma(0, 1)) << "particle " << p;
  }
}

}  // namespace
}  // namespace cfdmpm::mpm
