// Equilibration pressure: one material gives its own EOS pressure; water and air agree on one
// pressure for air volume fractions from 1e-9 to 1 - 1e-9; bad guesses and three materials; the
// kernel runs inside Kokkos::parallel_reduce.
#include "ice/equilibration.hpp"
#include "seed_materials.hpp"

#include <gtest/gtest.h>
#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace cfdmpm::ice;
using namespace cfdmpm::ice::test;

namespace {

// A cell built from a known state: every material at pressure p_true, with the given volume
// fractions; the solver has to find p_true and the fractions back from mass densities alone.
struct KnownCell {
  int count = 0;
  MaterialArray<Eos> eos;
  MaterialArray<double> mass_density;
  MaterialArray<double> temperature;
  MaterialArray<double> volume_fraction;
  double pressure = 0.0;
};

KnownCell knownCell(const std::vector<Eos>& eos, const std::vector<double>& volume_fraction,
                    const std::vector<double>& temperature, double pressure)
{
  KnownCell cell;
  cell.count = int(eos.size());
  cell.pressure = pressure;
  for (int m = 0; m < cell.count; ++m) {
    cell.eos[m] = eos[m];
    cell.temperature[m] = temperature[m];
    cell.volume_fraction[m] = volume_fraction[m];
    cell.mass_density[m] = volume_fraction[m] * eos[m].density(pressure, temperature[m]);
  }
  return cell;
}

EquilibrationResult solve(const KnownCell& cell, double guess)
{
  return equilibrationPressure(cell.count, cell.eos, cell.mass_density, cell.temperature, guess);
}

// sum_m theta_m/(rho_m dp/drho_m) = -d(sum theta)/dp: how strongly the cell's volume constraint
// pins the pressure.
double volumeStiffness(const KnownCell& cell, const EquilibrationResult& r)
{
  double s = 0.0;
  for (int m = 0; m < cell.count; ++m)
    s += r.volume_fraction[m] / (r.density[m] * cell.eos[m].dp_drho(r.density[m], cell.temperature[m]));
  return s;
}

// Checks a converged result against the known state; returns the relative pressure error.
double expectRecovers(const KnownCell& cell, const EquilibrationResult& r)
{
  EXPECT_TRUE(r.converged()) << "status " << int(r.status) << " after " << r.iterations;
  double sum = 0.0;
  for (int m = 0; m < cell.count; ++m) sum += r.volume_fraction[m];
  // The solver stops at |sum - 1| < 100 eps (or a relative pressure step below 1e-14, where the
  // sum is within a few eps); 1e-12 leaves a factor 45.
  EXPECT_NEAR(sum, 1.0, 1e-12);

  // Pressure error bound: the inputs carry one rounding each (eps relative in rho_CC), the stopping
  // test allows 100 eps in sum theta, and a change dS of sum theta moves p by dS/stiffness.
  const double bound = 104.0 * DBL_EPSILON / volumeStiffness(cell, r);
  EXPECT_NEAR(r.pressure, cell.pressure, bound);

  for (int m = 0; m < cell.count; ++m) {
    // Each material's EOS gives the common pressure at its density: the round trip p -> rho -> p
    // loses eps rho dp/drho (ulp of rho times the EOS slope) plus eps p.
    const double rho = r.density[m];
    const double slope = cell.eos[m].dp_drho(rho, cell.temperature[m]);
    EXPECT_NEAR(cell.eos[m].pressure(rho, cell.temperature[m]), r.pressure,
                4.0 * DBL_EPSILON * (rho * slope + std::fabs(r.pressure)))
        << "material " << m;
    // The volume fraction of a material is recovered to the pressure error's effect plus rounding.
    EXPECT_NEAR(r.volume_fraction[m], cell.volume_fraction[m],
                4.0 * DBL_EPSILON * cell.volume_fraction[m] + 104.0 * DBL_EPSILON)
        << "material " << m;
  }
  return std::fabs(r.pressure - cell.pressure) / cell.pressure;
}

}  // namespace

TEST(Equilibration, SingleMaterialReturnsItsEosPressure)
{
  struct Case {
    Eos eos;
    double density;
    double temperature;
  };
  const std::vector<Case> cases = {{seedAir(), 1.17682926829, 300.0},
                                   {seedAir(), 1e-3, 278.15},
                                   {seedWater(), 1000.1, kFiveCelsius},
                                   {seedWater(), 990.0, kFiveCelsius},  // tension: p < 0 in eq. 5
                                   {seedWater().withCavitation(872.0), 990.0, kFiveCelsius},  // boiling: p < p_c
                                   {seedWater().withCavitation(872.0), 1000.1, kFiveCelsius},
                                   {Tait(999.8, 1466.0, 7.0, kAtmosphere), 1003.0, kFiveCelsius},
                                   {seedSand(), 1990.0, kFiveCelsius}};
  for (const Case& c : cases) {
    MaterialArray<Eos> eos;
    MaterialArray<double> rho, T;
    eos[0] = c.eos;
    rho[0] = c.density;
    T[0] = c.temperature;
    const double expected = c.eos.pressure(c.density, c.temperature);
    const EquilibrationResult r = equilibrationPressure(1, eos, rho, T, kAtmosphere);
    ASSERT_TRUE(r.converged());
    std::printf("  kind %d, rho %-12g: p = %.10g Pa after %d evaluation(s)\n", int(c.eos.kind), c.density,
                r.pressure, r.iterations);
    // theta = rho/rho_micro(p) = 1 within the stopping test (100 eps), so rho_micro is rho to
    // 100 eps relative and p is the EOS pressure to 100 eps * rho dp/drho (plus eps p).
    const double slope = c.eos.dp_drho(c.density, c.temperature);
    EXPECT_NEAR(r.pressure, expected, 100.0 * DBL_EPSILON * (c.density * slope + std::fabs(expected)));
    EXPECT_NEAR(r.volume_fraction[0], 1.0, 100.0 * DBL_EPSILON);
    EXPECT_NEAR(r.sound_speed[0], std::sqrt(c.eos.sound_speed_squared(c.density, c.temperature)),
                1e-12 * r.sound_speed[0]);  // c^2 varies slowly with rho; rho is right to 1e-14
    // One material: both root bounds are its own pressure p(rho), so the solve starts there and
    // the first evaluation confirms it (measured: 1 for every EOS).
    EXPECT_EQ(r.iterations, 1) << "kind " << int(c.eos.kind) << " rho " << c.density;
  }
}

TEST(Equilibration, WaterAndAirAgreeForVanishingVolumeFractions)
{
  // Hydrostatic pressure 1 m below the surface; the solver starts from 1 atm (the surface value).
  const double p_true = kAtmosphere + 999.8 * 9.81;
  std::vector<double> air_fractions;
  for (int e = -9; e <= -1; ++e) air_fractions.push_back(std::pow(10.0, e));
  air_fractions.push_back(0.5);
  for (int e = -1; e >= -9; --e) air_fractions.push_back(1.0 - std::pow(10.0, e));

  std::printf("  air fraction   iterations  bisections  |p - p_true|/p_true\n");
  for (double theta_air : air_fractions) {
    const double theta_water = theta_air > 0.5 ? std::pow(10.0, std::round(std::log10(1.0 - theta_air)))
                                               : 1.0 - theta_air;
    const KnownCell cell = knownCell({seedWater(), seedAir()}, {theta_water, 1.0 - theta_water},
                                     {kFiveCelsius, kFiveCelsius}, p_true);
    const EquilibrationResult r = solve(cell, kAtmosphere);
    const double error = expectRecovers(cell, r);
    std::printf("  %-12.9g   %10d  %10d  %.2e\n", 1.0 - theta_water, r.iterations, r.bisections, error);
    // Measured: 2 to 4 evaluations, no bisection. 8 leaves room without hiding a regression to
    // the tens of steps that an unbracketed Newton on sum theta - 1 needs from far guesses.
    EXPECT_LE(r.iterations, 8) << "air fraction " << 1.0 - theta_water;
  }
}

TEST(Equilibration, ConvergesFromFarGuesses)
{
  // Guesses from below zero (outside the gas's range) to 1e12 Pa, at both extremes of the mixture.
  const double p_true = kAtmosphere + 999.8 * 9.81;
  for (double theta_water : {1.0 - 1e-9, 1e-9}) {
    const KnownCell cell = knownCell({seedWater(), seedAir()}, {theta_water, 1.0 - theta_water},
                                     {kFiveCelsius, kFiveCelsius}, p_true);
    for (double guess : {-5.0, 1e-3, 1e3, 1e7, 1e12}) {
      const EquilibrationResult r = solve(cell, guess);
      expectRecovers(cell, r);
      std::printf("  water fraction %-10.3g guess %-8.0e: %d iterations, %d bisections\n", theta_water,
                  guess, r.iterations, r.bisections);
      // Measured: 2 to 4. A guess outside the root bounds starts from the nearer one; with
      // 1e-9 of air the lower bound (water's own pressure) is 2 Pa below the root. 8 as above.
      EXPECT_LE(r.iterations, 8) << "guess " << guess;
    }
  }
}

TEST(Equilibration, WaterAirAndSandShareOnePressure)
{
  // Three materials as in a cell at the slide's surface; sand's solid EOS bounds p from above.
  const KnownCell cell = knownCell({seedWater(), seedAir(), seedSand()}, {0.45, 1e-6, 0.55 - 1e-6},
                                   {kFiveCelsius, kFiveCelsius, kFiveCelsius}, 1.3e5);
  for (double guess : {kAtmosphere, 1.0, 5e6}) expectRecovers(cell, solve(cell, guess));
}

TEST(Equilibration, MaterialWithoutMassGetsEosValuesAtTheCommonPressure)
{
  KnownCell cell = knownCell({seedWater(), seedAir()}, {1.0, 0.0}, {kFiveCelsius, kFiveCelsius}, 1.5e5);
  const EquilibrationResult r = solve(cell, kAtmosphere);
  ASSERT_TRUE(r.converged());
  EXPECT_EQ(r.volume_fraction[1], 0.0);
  EXPECT_EQ(r.density[1], seedAir().density(r.pressure, kFiveCelsius));  // same expression
  EXPECT_NEAR(r.pressure, 1.5e5, 100.0 * DBL_EPSILON * 999.8 * 2.15e6);  // water alone sets p
}

TEST(Equilibration, ReportsInvalidInputInsteadOfThrowing)
{
  MaterialArray<Eos> eos;
  MaterialArray<double> rho, T;
  eos[0] = seedWater();
  eos[1] = seedAir();
  T[0] = T[1] = kFiveCelsius;
  rho[0] = 0.0;
  rho[1] = 0.0;
  EXPECT_EQ(equilibrationPressure(2, eos, rho, T, kAtmosphere).status, EquilibrationStatus::InvalidInput);
  rho[0] = -1.0;
  EXPECT_EQ(equilibrationPressure(2, eos, rho, T, kAtmosphere).status, EquilibrationStatus::InvalidInput);
  rho[0] = std::nan("");
  EXPECT_EQ(equilibrationPressure(2, eos, rho, T, kAtmosphere).status, EquilibrationStatus::InvalidInput);
  EXPECT_EQ(equilibrationPressure(kMaxMaterials + 1, eos, rho, T, kAtmosphere).status,
            EquilibrationStatus::InvalidInput);
}

TEST(Equilibration, SqueezesTheSolidAsFarAsTheFluidsNeed)
{
  // Dense air plus sand: the air alone would need more than the cell at the sand's reference
  // pressure, and beyond p_ref + K (where a rational solid EOS ends). The logarithmic solid EOS has
  // a root for any such cell: the pressure at which the air fits beside the sand squeezed to
  // θ_s = θ_s0 exp(−(p − p_ref)/K).
  const KnownCell cell = knownCell({seedAir(), seedSand()}, {0.5, 0.5}, {300.0, 300.0}, 1e5);
  KnownCell heavy = cell;
  heavy.mass_density[0] = 2.0 * seedAir().density(2.0 * (kAtmosphere + 8.33e6), 300.0);
  const EquilibrationResult r = solve(heavy, kAtmosphere);
  ASSERT_TRUE(r.converged());
  EXPECT_GT(r.pressure, kAtmosphere + 8.33e6);
  // The sand's share from its EOS, written out independently; the shares fill the cell (the
  // solver's convergence test is on Σθ − 1, at 1e-12).
  const double sand_share = heavy.mass_density[1] / (1985.0 * std::exp((r.pressure - kAtmosphere) / 8.33e6));
  EXPECT_NEAR(r.volume_fraction[1], sand_share, 1e-12);
  EXPECT_NEAR(r.volume_fraction[0] + r.volume_fraction[1], 1.0, 1e-12);
}

TEST(Equilibration, AlternatingNewtonFormsConverge)
{
  // A cell of the seed scene at 10 mm, 0.51 s (its inputs to the bit): the rigid bed's cut cell
  // (a quarter, K = 1e10 Pa), a trace of the soft sand (K = 1e5 Pa, at p ~ 1e5 Pa it counts as
  // gas-like: p / K > 0.5) and water; the shares fill 1.00037 of the cell at the guess. Newton in
  // 1/p (for the sand) overshoots to 1.3e6 Pa, plain Newton (for the water) comes back to 1.0e5,
  // each step a little shorter than the last: 100 iterations ended at 1.0015e5 Pa, not converged,
  // and the run stopped. Bisection where Newton does not halve its step in two iterations finds
  // the root in a handful.
  const double p_ref = 0x1.9f288e24d1e2ep+16, guess = 0x1.813bbcc7dbe4fp+16, T = 278.15;
  MaterialArray<double> mass_density{}, temperature{};
  mass_density[0] = 0x1.16200000001a1p+11;  // bed, kg/m^3 of the cell
  mass_density[1] = 0x1.6bd2a9e29e30bp-1;   // sand
  mass_density[2] = 0x1.76ecb2ea620b8p+9;   // water
  const double bed_share = 0x1.000000000018p-2, sand_share = 0x1.6c227c7b7bf65p-12;
  MaterialArray<Eos> eos{};
  eos[0] = SolidEos(1e10, mass_density[0] / bed_share, p_ref);
  eos[1] = SolidEos(1e5, mass_density[1] / sand_share, p_ref);
  const LinearWater water_eos(101325.0, 999.8, 278.15, 0.18, 2.15e9 / 999.8);  // the scene's water
  eos[2] = water_eos;
  for (int m = 0; m < 3; ++m) temperature[m] = T;
  const EquilibrationResult r = equilibrationPressure(3, eos, mass_density, temperature, guess);
  ASSERT_TRUE(r.converged()) << "status " << int(r.status) << " after " << r.iterations << " at " << r.pressure;
  // Newton converges quadratically once bracketed: 20 iterations is a generous bound (7 here).
  EXPECT_LE(r.iterations, 20);
  // The shares from the EOS written out at the result fill the cell: the bed and sand
  // exp(-(p - p_ref)/K), the water linear in p (c^2 = 2.15e9/999.8).
  const double bed = bed_share * std::exp(-(r.pressure - p_ref) / 1e10);
  const double sand = sand_share * std::exp(-(r.pressure - p_ref) / 1e5);
  const double water = mass_density[2] / water_eos.density(r.pressure, T);
  EXPECT_NEAR(bed + sand + water, 1.0, 1e-12);
  // The root lies above p_ref, and below the pressure at which the water alone would take the
  // excess 3.7e-4 of the cell (2.15e9 Pa x 3.7e-4 / 0.75 = 1.1 MPa): the sand gives most of it.
  EXPECT_GT(r.pressure, p_ref);
  EXPECT_LT(r.pressure, p_ref + 1.1e6);
}

TEST(Equilibration, RunsInsideAParallelKernel)
{
  // The same solve in a Kokkos kernel over cells whose air fraction sweeps 1e-9 ... 1 - 1e-9.
  const int cells = 19;
  MaterialArray<Eos> eos;
  eos[0] = seedWater();
  eos[1] = seedAir();
  const double p_true = 1.2e5;
  int failures = 0;
  Kokkos::parallel_reduce(
      "equilibration_cells", Kokkos::RangePolicy<>(0, cells),
      KOKKOS_LAMBDA(int c, int& failed) {
        const double e = -9.0 + 9.0 * c / (cells - 1);  // log10 of the smaller fraction
        const double small = Kokkos::Experimental::pow(10.0, e);
        MaterialArray<double> rho, T;
        T[0] = T[1] = 278.15;
        rho[0] = (c % 2 ? small : 1.0 - small) * eos[0].density(p_true, T[0]);
        rho[1] = (c % 2 ? 1.0 - small : small) * eos[1].density(p_true, T[1]);
        const EquilibrationResult r = equilibrationPressure(2, eos, rho, T, 1e5);
        if (!r.converged()) ++failed;
      },
      failures);
  EXPECT_EQ(failures, 0);
}

TEST(Equilibration, RandomCellsConvergeWithinTheErrorBound)
{
  // 20000 cells of 2 to 5 materials (linear water, air, sand, Tait water, the stiff bed's solid
  // EOS), volume fractions spread over 9 decades, temperatures 270-330 K, pressures 1e3-1e6 Pa and
  // guesses from -1e10 to 1e10 Pa: every cell must converge, to the error bound of expectRecovers.
  // Measured over 1e6 such cells: no failure, 4.4 evaluations on average, 17 at most, error at
  // most 0.97 of the bound.
  MaterialArray<Eos> eos;
  eos[0] = seedWater();
  eos[1] = seedAir();
  eos[2] = seedSand();
  eos[3] = Tait(999.8, 1466.0, 7.0, kAtmosphere);
  eos[4] = SolidEos(1.17e9, 8900.0, kAtmosphere);
  std::mt19937_64 random(20240501);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int worst_iterations = 0;
  for (int c = 0; c < 20000; ++c) {
    const int count = 2 + int(random() % 4);
    std::vector<Eos> materials(eos.data(), eos.data() + count);
    std::vector<double> fractions(count), temperatures(count);
    double sum = 0.0;
    for (int m = 0; m < count; ++m) sum += fractions[m] = std::pow(10.0, -9.0 * uniform(random));
    for (int m = 0; m < count; ++m) {
      fractions[m] /= sum;
      temperatures[m] = 270.0 + 60.0 * uniform(random);
    }
    const KnownCell cell =
        knownCell(materials, fractions, temperatures, std::pow(10.0, 3.0 + 3.0 * uniform(random)));
    const double guess = (random() % 4 == 0 ? -1.0 : 1.0) * std::pow(10.0, -2.0 + 12.0 * uniform(random));
    const EquilibrationResult r = solve(cell, guess);
    ASSERT_TRUE(r.converged()) << "cell " << c << " guess " << guess;
    const double bound = 104.0 * DBL_EPSILON / volumeStiffness(cell, r);  // as in expectRecovers
    ASSERT_NEAR(r.pressure, cell.pressure, bound) << "cell " << c;
    worst_iterations = std::max(worst_iterations, r.iterations);
  }
  std::printf("  most evaluations: %d\n", worst_iterations);
  EXPECT_LE(worst_iterations, 30);  // 17 measured over 1e6 cells; the limit is 100
}
