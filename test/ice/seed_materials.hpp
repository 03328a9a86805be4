#pragma once
// The fluids and solids of the seed scene (Rzadkiewicz slide), as the tests use them.
#include "ice/eos.hpp"

namespace cfdmpm::ice::test {

constexpr double kAtmosphere = 101325.0;  // Pa
constexpr double kFiveCelsius = 278.15;   // K, the scene's temperature

/// Seed paper eq. 5 with its numbers: p0 = 1 atm, rho0 = 999.8, T0 = 10 degC, beta = 0.18,
/// Kf = 2.15e6 m^2/s^2.
inline LinearWater seedWater() { return LinearWater(kAtmosphere, 999.8, 283.15, 0.18, 2.15e6); }

/// Air as in Uintah's SandBox input: gamma 1.4, cv 716 J/(kg K) (R = 286.4).
inline IdealGas seedAir() { return IdealGas(1.4, 716.0); }

/// Sand's bulk response: K = 8.33e6 Pa, rho0 = 1985 kg/m^3, about 1 atm.
inline SolidEos seedSand() { return SolidEos(8.33e6, 1985.0, kAtmosphere); }

}  // namespace cfdmpm::ice::test
