// Equations of state: inverse round trips, derivatives, the numbers of the seed scene, and the
// tagged union giving the same values as the concrete types.
#include "ice/eos.hpp"
#include "seed_materials.hpp"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <vector>

using namespace cfdmpm::ice;
using namespace cfdmpm::ice::test;

namespace {

struct State {
  double density;
  double temperature;
};

// Densities from strongly expanded to strongly compressed for each material, at several T.
const std::vector<State> kAirStates = {{1e-6, 200.0}, {0.01, 278.15}, {1.2, 293.15}, {50.0, 600.0}};
const std::vector<State> kWaterStates = {{980.0, 278.15}, {999.8, 283.15}, {1000.3, 278.15}, {1030.0, 350.0}};
const std::vector<State> kSandStates = {{1900.0, 278.15}, {1985.0, 278.15}, {1986.0, 300.0}, {2100.0, 278.15}};

template <class E>
void expectRoundTrip(const E& eos, const std::vector<State>& states)
{
  for (const State& s : states) {
    const double p = eos.pressure(s.density, s.temperature);
    const double back = eos.density(p, s.temperature);
    // 1e-14 relative: each direction is a few roundings; in the liquid ones p0 and Kf only scale
    // the pressure, whose rounding (eps p) maps back to eps p/Kf, far below eps rho.
    EXPECT_NEAR(back, s.density, 1e-14 * s.density) << "rho " << s.density << " T " << s.temperature;
  }
}

template <class E>
void expectDerivativeMatchesDifference(const E& eos, const std::vector<State>& states)
{
  for (const State& s : states) {
    const double h = 1e-5 * s.density;
    const double difference =
        (eos.pressure(s.density + h, s.temperature) - eos.pressure(s.density - h, s.temperature)) / (2 * h);
    const double exact = eos.dp_drho(s.density, s.temperature);
    // Central difference: truncation (h/rho)^2 ~ 1e-10 relative for these smooth laws; rounding
    // eps |p|/h, which for the stiff solid at its largest |p| is ~1e-9 of dp/drho.
    EXPECT_NEAR(difference, exact, 1e-8 * std::fabs(exact)) << "rho " << s.density;
  }
}

}  // namespace

TEST(Eos, IdealGasRoundTrip) { expectRoundTrip(seedAir(), kAirStates); }
TEST(Eos, LinearWaterRoundTrip) { expectRoundTrip(seedWater(), kWaterStates); }
TEST(Eos, TaitRoundTrip) { expectRoundTrip(Tait(999.8, 1466.0, 7.0, kAtmosphere), kWaterStates); }
TEST(Eos, SolidRoundTrip) { expectRoundTrip(seedSand(), kSandStates); }

TEST(Eos, DerivativesMatchCentralDifferences)
{
  expectDerivativeMatchesDifference(seedAir(), kAirStates);
  expectDerivativeMatchesDifference(seedWater(), kWaterStates);
  expectDerivativeMatchesDifference(Tait(999.8, 1466.0, 7.0, kAtmosphere), kWaterStates);
  expectDerivativeMatchesDifference(seedSand(), kSandStates);
}

TEST(Eos, AirDensityAtNormalConditions)
{
  const IdealGas air = IdealGas::fromGasConstant(287.0, 1.4);
  const double rho = air.density(101325.0, 293.15);
  // The textbook value 1.204 kg/m^3 is given to 4 digits: agree to half a unit of its last digit.
  EXPECT_NEAR(rho, 1.204, 0.0005);
  // And exactly the formula p/(R T), to the two roundings of the computation.
  EXPECT_NEAR(rho, 101325.0 / (287.0 * 293.15), 4 * DBL_EPSILON * rho);
  // Isentropic sound speed sqrt(gamma R T) = 343.2 m/s at 20 degC (4 digits again).
  EXPECT_NEAR(std::sqrt(air.sound_speed_squared(rho, 293.15)), 343.2, 0.05);
}

TEST(Eos, WaterSoundSpeedIs1466)
{
  // Three readings of the water parameters: the seed paper's Kf = 2.15e6 m^2/s^2 (1466.29 m/s),
  // the bulk modulus 2.15e9 Pa over rho0 = 999.8 (1466.43 m/s), and Uintah's KnaussSeaWater
  // k = 4.6512e-7 s^2/m^2, Kf = 1/k (1466.28 m/s). 1466 m/s is quoted to 4 digits and the readings
  // differ by 0.15 m/s: each must lie within 0.5 m/s of it.
  const LinearWater paper = seedWater();
  const LinearWater from_bulk = LinearWater::fromBulkModulus(2.15e9, kAtmosphere, 999.8, 283.15, 0.18);
  const LinearWater uintah(kAtmosphere, 999.8, 283.15, 0.18, 1.0 / 4.6512e-7);
  for (const LinearWater& water : {paper, from_bulk, uintah}) {
    const double rho = water.density(kAtmosphere, kFiveCelsius);
    EXPECT_NEAR(std::sqrt(water.sound_speed_squared(rho, kFiveCelsius)), 1466.0, 0.5);
  }
  // Compressibility 1/(rho c^2) = 1/(rho Kf) of water: the inverse bulk modulus 1/2.15e9 Pa, to the
  // 0.11 % by which rho at 5 degC (998.9) differs from 1000; allow 0.2 %.
  const double rho = paper.density(kAtmosphere, kFiveCelsius);
  EXPECT_NEAR(1.0 / (rho * paper.sound_speed_squared(rho, kFiveCelsius)), 1.0 / 2.15e9, 0.002 / 2.15e9);
}

TEST(Eos, LinearWaterMatchesPaperEquation5)
{
  // p - p0 = Kf [(rho - rho0) - beta (T - T0)] at the scene's 5 degC and 1 m of water depth
  // (p0 + 999.8 * 9.81 * 1): rho = rho0 + beta (T - T0) + (p - p0)/Kf, written out independently.
  const LinearWater water = seedWater();
  const double p = kAtmosphere + 999.8 * 9.81;
  const double expected = 999.8 + 0.18 * (278.15 - 283.15) + (p - kAtmosphere) / 2.15e6;
  EXPECT_NEAR(water.density(p, kFiveCelsius), expected, 4 * DBL_EPSILON * expected);  // same formula
}

TEST(Eos, TaitAtReferenceDensityGivesReferencePressureAndSoundSpeed)
{
  const Tait tait(999.8, 1466.0, 7.0, kAtmosphere);
  EXPECT_DOUBLE_EQ(tait.pressure(999.8, 0.0), kAtmosphere);  // (rho/rho0)^n - 1 = 0 exactly
  EXPECT_NEAR(std::sqrt(tait.sound_speed_squared(999.8, 0.0)), 1466.0, 1e-12);  // pow(1, n-1) = 1
  EXPECT_DOUBLE_EQ(tait.B(), 999.8 * 1466.0 * 1466.0 / 7.0);
}

TEST(Eos, SolidCompressibilityIsInverseBulkModulusAtReferenceDensity)
{
  const SolidEos sand = seedSand();
  EXPECT_DOUBLE_EQ(sand.pressure(1985.0, 0.0), kAtmosphere);
  // rho c^2 = K at every density (Uintah's MPM compressibility 1/K), to rounding.
  EXPECT_NEAR(1985.0 * sand.sound_speed_squared(1985.0, 0.0), 8.33e6, 4 * DBL_EPSILON * 8.33e6);
  EXPECT_NEAR(2500.0 * sand.sound_speed_squared(2500.0, 0.0), 8.33e6, 4 * DBL_EPSILON * 8.33e6);
  // p = p_ref + K ln(rho/rho0), and density() is its inverse, beyond p_ref + K as well.
  EXPECT_NEAR(sand.pressure(1985.0 * std::exp(0.01), 0.0), kAtmosphere + 0.01 * 8.33e6, 1e-9 * 8.33e6);
  EXPECT_NEAR(sand.density(kAtmosphere + 2.0 * 8.33e6, 0.0), 1985.0 * std::exp(2.0), 1e-12 * 1985.0 * std::exp(2.0));
}

TEST(Eos, PressureRangeBoundsWherePositiveDensityExists)
{
  // At the lower bound of a liquid's range its density reaches zero; just above it, it is positive.
  const LinearWater water = seedWater();
  const PressureRange range = water.pressure_range(kFiveCelsius);
  EXPECT_NEAR(water.density(range.min, kFiveCelsius), 0.0, 1e-12);  // rounding eps * p0 / Kf
  EXPECT_GT(water.density(range.min + 1.0, kFiveCelsius), 0.0);
  EXPECT_EQ(seedAir().pressure_range(300.0).min, 0.0);
  EXPECT_EQ(seedSand().pressure_range(300.0).max, DBL_MAX);  // a solid can be squeezed at any pressure
}

TEST(Eos, TaggedUnionGivesTheConcreteValues)
{
  // The union only dispatches: the values must be bit for bit those of the concrete types.
  const Tait tait(999.8, 1466.0, 7.0, kAtmosphere);
  const Eos air = seedAir(), water = seedWater(), liquid = tait, sand = seedSand();
  EXPECT_EQ(air.kind, EosKind::IdealGas);
  EXPECT_EQ(sand.kind, EosKind::Solid);
  EXPECT_EQ(air.pressure(1.2, 300.0), seedAir().pressure(1.2, 300.0));
  EXPECT_EQ(water.density(2e5, 280.0), seedWater().density(2e5, 280.0));
  EXPECT_EQ(liquid.dp_drho(1001.0, 280.0), tait.dp_drho(1001.0, 280.0));
  EXPECT_EQ(sand.sound_speed_squared(1990.0, 280.0), seedSand().sound_speed_squared(1990.0, 280.0));
  EXPECT_EQ(water.pressure_range(280.0).min, seedWater().pressure_range(280.0).min);
  EXPECT_TRUE(std::isnan(Eos().pressure(1.0, 1.0)));  // kind None
}

// Cavitation: below p_c the water boils; p = p_c ρ/ρ_c, continuous with the liquid at ρ_c, its
// density positive at every positive pressure and the round trip exact on both branches.
TEST(Eos, CavitatingWaterBoilsBelowItsVapourPressure)
{
  const double p_c = 872.0;  // Pa, water's vapour pressure at 5 C
  const LinearWater water = seedWater().withCavitation(p_c);
  const double rho_c = water.cavitationDensity(kFiveCelsius);
  // ρ_c is the liquid's density at p_c: the law is continuous there.
  EXPECT_NEAR(rho_c, seedWater().density(p_c, kFiveCelsius), 1e-12 * rho_c);
  EXPECT_NEAR(water.pressure(rho_c, kFiveCelsius), p_c, 1e-9 * p_c);  // rounding eps Kf ρ_c, ~1e-7 Pa
  // A cell 3 % short of water sits 3 % below p_c (the liquid alone would hold -64 MPa).
  EXPECT_NEAR(water.pressure(0.97 * rho_c, kFiveCelsius), 0.97 * p_c, 1e-12 * p_c);
  EXPECT_LT(seedWater().pressure(0.97 * rho_c, kFiveCelsius), -6e7);
  // Above p_c the liquid's law is unchanged, to the bit.
  EXPECT_EQ(water.pressure(1000.5, kFiveCelsius), seedWater().pressure(1000.5, kFiveCelsius));
  EXPECT_EQ(water.density(2e5, kFiveCelsius), seedWater().density(2e5, kFiveCelsius));
  expectRoundTrip(water, {{0.5 * rho_c, kFiveCelsius}, {0.97 * rho_c, kFiveCelsius}, {999.9, kFiveCelsius}});
  // The boiling branch is an isothermal gas: p κ = 1 (κ = 1 / (ρ c²)).
  const double rho = 0.9 * rho_c;
  EXPECT_NEAR(water.pressure(rho, kFiveCelsius) / (rho * water.sound_speed_squared(rho, kFiveCelsius)), 1.0, 1e-12);
  expectDerivativeMatchesDifference(water, {{0.5 * rho_c, kFiveCelsius}, {1001.0, kFiveCelsius}});
  // Every positive pressure has a positive density; zero is the range's bound.
  EXPECT_EQ(water.pressure_range(kFiveCelsius).min, 0.0);
  EXPECT_GT(water.density(1e-3, kFiveCelsius), 0.0);
  // Off (p_c = 0, the default): the liquid holds any tension.
  EXPECT_EQ(seedWater().cavitation_pressure, 0.0);
  EXPECT_EQ(seedWater().density(-1e6, kFiveCelsius), seedWater().withCavitation(0.0).density(-1e6, kFiveCelsius));
  EXPECT_LT(seedWater().density(-1e6, kFiveCelsius), 999.8);
}
