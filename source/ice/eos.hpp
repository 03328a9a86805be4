#pragma once
// Equations of state for the cell-centred ICE materials (and the bulk response of MPM solids in the
// equilibration pressure). Each EOS is a small value type with the same four functions of the
// material (micro) density rho [kg/m^3] and temperature T [K]:
//
//   pressure(rho, T)             p [Pa]
//   dp_drho(rho, T)              (dp/drho) at constant T [m^2/s^2]; the Newton derivative
//   density(p, T)                the inverse of pressure(): rho such that pressure(rho, T) == p
//   sound_speed_squared(rho, T)  c^2 [m^2/s^2]; the compressibility is 1/(rho c^2)
//
// and pressure_range(T), the open pressure interval on which density(p, T) is positive and finite.
// `Eos` is a tagged union of the four types: a cell loop over materials calls any of them through
// a switch, with no virtual call and no allocation. All functions run unchanged on every Kokkos
// backend. Units are SI, temperatures in kelvin. See doc/ice-pointwise.md.
#include <Kokkos_Core.hpp>

#include <cfloat>

namespace cfdmpm::ice {

/// Most materials (ICE and MPM together) a cell can hold; per-cell work uses stack arrays this long.
constexpr int kMaxMaterials = 8;

/// One value per material in a cell, on the stack (no allocation inside kernels).
template <class T>
using MaterialArray = Kokkos::Array<T, kMaxMaterials>;

/// Open interval (min, max) of pressures an EOS can represent; +-DBL_MAX means unbounded.
struct PressureRange {
  double min;
  double max;
};

/// Ideal gas, seed paper eq. 4: p = rho R T with R = (gamma - 1) cv, i.e. p = (gamma - 1) rho cv T
/// (internal energy e = cv T). Parameters: gamma [-], cv [J/(kg K)].
struct IdealGas {
  double gamma;  // ratio of specific heats cp/cv, e.g. 1.4 for air
  double cv;     // specific heat at constant volume [J/(kg K)], e.g. 716 for air (R = 286.4)

  IdealGas() = default;
  KOKKOS_INLINE_FUNCTION IdealGas(double gamma_, double cv_) : gamma(gamma_), cv(cv_) {}
  /// From the specific gas constant R [J/(kg K)] and gamma: cv = R/(gamma - 1).
  KOKKOS_INLINE_FUNCTION static IdealGas fromGasConstant(double gas_constant, double gamma_)
  {
    return IdealGas(gamma_, gas_constant / (gamma_ - 1.0));
  }

  KOKKOS_INLINE_FUNCTION double gasConstant() const { return (gamma - 1.0) * cv; }
  KOKKOS_INLINE_FUNCTION double pressure(double rho, double T) const { return rho * gasConstant() * T; }
  KOKKOS_INLINE_FUNCTION double dp_drho(double, double T) const { return gasConstant() * T; }
  KOKKOS_INLINE_FUNCTION double density(double p, double T) const { return p / (gasConstant() * T); }
  /// Isentropic: c^2 = (dp/drho)_e + (dp/de)_rho p/rho^2 = gamma R T.
  KOKKOS_INLINE_FUNCTION double sound_speed_squared(double, double T) const
  {
    return gamma * gasConstant() * T;
  }
  KOKKOS_INLINE_FUNCTION PressureRange pressure_range(double) const { return {0.0, DBL_MAX}; }
};

/// Linear water, seed paper eq. 5:  p - p0 = Kf [(rho - rho0) - beta (T - T0)].
///
/// Units of Kf. With p in Pa and rho in kg/m^3, Kf is dp/drho and has units Pa/(kg/m^3) = m^2/s^2:
/// it is the square of the sound speed, Kf = K_bulk/rho0 for a bulk modulus K_bulk [Pa]. The seed
/// paper's number 2.15e6 is this Kf: c = sqrt(2.15e6 m^2/s^2) = 1466 m/s, the sound speed of water,
/// and Kf rho0 = 2.15e9 Pa is the bulk modulus of water (the paper's text, "2.15e6 kPa", gives
/// K_bulk; its table's unit "Pa" should read m^2/s^2). Taking 2.15e9 as Kf would give c = 46 km/s.
/// Uintah's KnaussSeaWater writes the same law as rho = rho0 + a(T - T0) + k(p - p0) with
/// k = 1/Kf = 4.6512e-7 s^2/m^2 and a = beta.
///
/// beta [kg/(m^3 K)] is used with the sign printed in eq. 5 (0.18 in the paper): at fixed pressure
/// the density then rises with T. Real water near 10 degC has beta ~ -0.15 (Knauss); the seed scene
/// is isothermal, where beta has no effect.
///
/// Cavitation (optional, a cavitation pressure p_c > 0): water does not hold tension; below the
/// vapour pressure it boils and the cell holds a mixture of liquid and vapour. Below the liquid's
/// density at p_c, rho_c(T), the law is p = p_c rho / rho_c: the mixture's volume grows as an
/// isothermal gas's would (p kappa = 1), continuous with the liquid at rho_c. Without it the law
/// stretches the water linearly to any tension (-80 MPa for a 4 % short cell); with it a cell that
/// holds too little water sits near p_c and takes the missing volume as vapour, as a real liquid
/// does (Brennen, "Cavitation and Bubble Dynamics", 1995, ch. 1). p_c = 0: off.
struct LinearWater {
  double reference_pressure;     // p0 [Pa], 101325 in the paper
  double reference_density;      // rho0 [kg/m^3], 999.8
  double reference_temperature;  // T0 [K], 283.15 (10 degC)
  double beta;                   // [kg/(m^3 K)], 0.18
  double Kf;                     // dp/drho = c^2 [m^2/s^2], 2.15e6
  double cavitation_pressure = 0.0;  // p_c [Pa]; 0: no cavitation

  LinearWater() = default;
  KOKKOS_INLINE_FUNCTION LinearWater(double p0, double rho0, double T0, double beta_, double Kf_)
      : reference_pressure(p0), reference_density(rho0), reference_temperature(T0), beta(beta_), Kf(Kf_)
  {
  }
  /// From a bulk modulus K_bulk [Pa]: Kf = K_bulk/rho0.
  KOKKOS_INLINE_FUNCTION static LinearWater fromBulkModulus(double bulk_modulus, double p0, double rho0,
                                                            double T0, double beta_)
  {
    return LinearWater(p0, rho0, T0, beta_, bulk_modulus / rho0);
  }

  /// The same law, cavitating below p_c (> 0, below p0, where the liquid's density is positive).
  KOKKOS_INLINE_FUNCTION LinearWater withCavitation(double p_c) const
  {
    LinearWater w = *this;
    w.cavitation_pressure = p_c;
    return w;
  }

  /// rho at p0 and T: the density about which the law is linear.
  KOKKOS_INLINE_FUNCTION double densityAtReferencePressure(double T) const
  {
    return reference_density + beta * (T - reference_temperature);
  }
  /// rho_c: the liquid's density at the cavitation pressure (0 without cavitation).
  KOKKOS_INLINE_FUNCTION double cavitationDensity(double T) const
  {
    return cavitation_pressure > 0 ? liquidDensity(cavitation_pressure, T) : 0.0;
  }
  KOKKOS_INLINE_FUNCTION double pressure(double rho, double T) const
  {
    const double rho_c = cavitationDensity(T);
    if (rho < rho_c) return cavitation_pressure * (rho / rho_c);
    return reference_pressure + Kf * ((rho - reference_density) - beta * (T - reference_temperature));
  }
  KOKKOS_INLINE_FUNCTION double dp_drho(double rho, double T) const
  {
    const double rho_c = cavitationDensity(T);
    return rho < rho_c ? cavitation_pressure / rho_c : Kf;
  }
  KOKKOS_INLINE_FUNCTION double density(double p, double T) const
  {
    if (cavitation_pressure > 0 && p < cavitation_pressure) return cavitationDensity(T) * (p / cavitation_pressure);
    return liquidDensity(p, T);
  }
  /// c^2 = dp/drho: Kf in the liquid. The isentropic correction (dp/de)_rho p/rho^2 =
  /// -Kf beta p/(cv rho^2) is 4e-6 of Kf at 1 atm and is left out, so the EOS needs no cv. (Uintah
  /// adds dp_de p/rho^2 with its dp_de = -a/k, which is dp/dT, not dp/de; with a = 0.18 that lowers
  /// c to 1453 m/s at 1 atm.)
  KOKKOS_INLINE_FUNCTION double sound_speed_squared(double rho, double T) const { return dp_drho(rho, T); }
  KOKKOS_INLINE_FUNCTION PressureRange pressure_range(double T) const
  {
    if (cavitation_pressure > 0) return {0.0, DBL_MAX};
    return {reference_pressure - Kf * densityAtReferencePressure(T), DBL_MAX};
  }

 private:
  KOKKOS_INLINE_FUNCTION double liquidDensity(double p, double T) const
  {
    return densityAtReferencePressure(T) + (p - reference_pressure) / Kf;
  }
};

/// Tait (Murnaghan) liquid: p = B [(rho/rho0)^n - 1] + p0 with B = rho0 c0^2/n. Temperature is
/// not used. Parameters: rho0 [kg/m^3], c0 [m/s] (sound speed at rho0), n [-] (7 for water), p0 [Pa].
struct Tait {
  double reference_density;   // rho0 [kg/m^3]
  double reference_sound_speed;  // c0 [m/s]
  double exponent;            // n [-]
  double reference_pressure;  // p0 [Pa]

  Tait() = default;
  KOKKOS_INLINE_FUNCTION Tait(double rho0, double c0, double n, double p0)
      : reference_density(rho0), reference_sound_speed(c0), exponent(n), reference_pressure(p0)
  {
  }

  KOKKOS_INLINE_FUNCTION double B() const
  {
    return reference_density * reference_sound_speed * reference_sound_speed / exponent;
  }
  KOKKOS_INLINE_FUNCTION double pressure(double rho, double) const
  {
    return B() * (Kokkos::Experimental::pow(rho / reference_density, exponent) - 1.0) + reference_pressure;
  }
  /// dp/drho = c0^2 (rho/rho0)^(n-1).
  KOKKOS_INLINE_FUNCTION double dp_drho(double rho, double) const
  {
    return reference_sound_speed * reference_sound_speed *
           Kokkos::Experimental::pow(rho / reference_density, exponent - 1.0);
  }
  KOKKOS_INLINE_FUNCTION double density(double p, double) const
  {
    const double ratio = (p - reference_pressure) / B() + 1.0;  // (rho/rho0)^n
    return reference_density * Kokkos::Experimental::pow(ratio, 1.0 / exponent);
  }
  KOKKOS_INLINE_FUNCTION double sound_speed_squared(double rho, double T) const { return dp_drho(rho, T); }
  KOKKOS_INLINE_FUNCTION PressureRange pressure_range(double) const
  {
    return {reference_pressure - B(), DBL_MAX};
  }
};

/// Bulk response of an MPM solid for the equilibration pressure: p = p_ref + K ln(rho/rho0), the
/// logarithmic form of Uintah's p = p_ref + K (1 - rho0/rho) (computePressEOSCM), the same to first
/// order in the strain. The logarithm has no pressure at which the solid cannot be compressed further:
/// in a cell whose fluids alone overfill it (a sand front arriving before the water has left) the
/// pressure rises until the fluids fit and the solid's share shrinks as exp(-(p - p_ref)/K), where the
/// rational form ends at p_ref + K and the equilibration had no root.
/// Parameters: K [Pa] bulk modulus, rho0 [kg/m^3], p_ref [Pa]. Temperature is not used.
struct SolidEos {
  double bulk_modulus;        // K [Pa]
  double reference_density;   // rho0 [kg/m^3]
  double reference_pressure;  // p_ref [Pa]

  SolidEos() = default;
  KOKKOS_INLINE_FUNCTION SolidEos(double K, double rho0, double p_ref)
      : bulk_modulus(K), reference_density(rho0), reference_pressure(p_ref)
  {
  }

  KOKKOS_INLINE_FUNCTION double pressure(double rho, double) const
  {
    return reference_pressure + bulk_modulus * Kokkos::Experimental::log(rho / reference_density);
  }
  /// dp/drho = K/rho.
  KOKKOS_INLINE_FUNCTION double dp_drho(double rho, double) const { return bulk_modulus / rho; }
  KOKKOS_INLINE_FUNCTION double density(double p, double) const
  {
    return reference_density * Kokkos::Experimental::exp((p - reference_pressure) / bulk_modulus);
  }
  /// c^2 = dp/drho = K/rho, so the compressibility 1/(rho c^2) = 1/K, Uintah's.
  KOKKOS_INLINE_FUNCTION double sound_speed_squared(double rho, double T) const { return dp_drho(rho, T); }
  KOKKOS_INLINE_FUNCTION PressureRange pressure_range(double) const { return {-DBL_MAX, DBL_MAX}; }
};

enum class EosKind : int { None = 0, IdealGas, LinearWater, Tait, Solid };

/// Any of the EOS above, chosen at run time: a type tag and the parameters in a union. Built
/// implicitly from each type (`Eos eos = IdealGas(1.4, 716.0);`). A default-constructed Eos has
/// kind None and returns NaN from every function.
struct Eos {
  EosKind kind;
  union {
    IdealGas ideal_gas;
    LinearWater linear_water;
    Tait tait;
    SolidEos solid;
  };

  KOKKOS_INLINE_FUNCTION Eos() : kind(EosKind::None), ideal_gas() {}
  KOKKOS_INLINE_FUNCTION Eos(const IdealGas& e) : kind(EosKind::IdealGas), ideal_gas(e) {}
  KOKKOS_INLINE_FUNCTION Eos(const LinearWater& e) : kind(EosKind::LinearWater), linear_water(e) {}
  KOKKOS_INLINE_FUNCTION Eos(const Tait& e) : kind(EosKind::Tait), tait(e) {}
  KOKKOS_INLINE_FUNCTION Eos(const SolidEos& e) : kind(EosKind::Solid), solid(e) {}

  // One switch per function, so that no closure type has to be callable on a device.
  KOKKOS_INLINE_FUNCTION double pressure(double rho, double T) const
  {
    switch (kind) {
      case EosKind::IdealGas: return ideal_gas.pressure(rho, T);
      case EosKind::LinearWater: return linear_water.pressure(rho, T);
      case EosKind::Tait: return tait.pressure(rho, T);
      case EosKind::Solid: return solid.pressure(rho, T);
      default: return nan();
    }
  }
  KOKKOS_INLINE_FUNCTION double dp_drho(double rho, double T) const
  {
    switch (kind) {
      case EosKind::IdealGas: return ideal_gas.dp_drho(rho, T);
      case EosKind::LinearWater: return linear_water.dp_drho(rho, T);
      case EosKind::Tait: return tait.dp_drho(rho, T);
      case EosKind::Solid: return solid.dp_drho(rho, T);
      default: return nan();
    }
  }
  KOKKOS_INLINE_FUNCTION double density(double p, double T) const
  {
    switch (kind) {
      case EosKind::IdealGas: return ideal_gas.density(p, T);
      case EosKind::LinearWater: return linear_water.density(p, T);
      case EosKind::Tait: return tait.density(p, T);
      case EosKind::Solid: return solid.density(p, T);
      default: return nan();
    }
  }
  KOKKOS_INLINE_FUNCTION double sound_speed_squared(double rho, double T) const
  {
    switch (kind) {
      case EosKind::IdealGas: return ideal_gas.sound_speed_squared(rho, T);
      case EosKind::LinearWater: return linear_water.sound_speed_squared(rho, T);
      case EosKind::Tait: return tait.sound_speed_squared(rho, T);
      case EosKind::Solid: return solid.sound_speed_squared(rho, T);
      default: return nan();
    }
  }
  KOKKOS_INLINE_FUNCTION PressureRange pressure_range(double T) const
  {
    switch (kind) {
      case EosKind::IdealGas: return ideal_gas.pressure_range(T);
      case EosKind::LinearWater: return linear_water.pressure_range(T);
      case EosKind::Tait: return tait.pressure_range(T);
      case EosKind::Solid: return solid.pressure_range(T);
      default: return {nan(), nan()};
    }
  }

 private:
  KOKKOS_INLINE_FUNCTION static double nan() { return Kokkos::Experimental::nan(""); }
};

}  // namespace cfdmpm::ice
