#pragma once
// Equilibration pressure of one cell (MPMICE step 3; Kashiwa et al. 2000, "A cell-centered ICE
// method for multiphase flow simulations", LA-UR; Uintah MPMICE::computeEquilibrationPressure).
//
// Every material m in the cell has a mass density rho_CC,m = mass_m/V_cell, a temperature T_m and
// an EOS. All materials share one pressure p, and together they fill the cell:
//
//   f(p) = sum_m theta_m(p) - 1 = 0,   theta_m(p) = rho_CC,m / rho_micro,m(p, T_m),
//
// with rho_micro,m(p, T) the EOS's density(p, T). Each theta_m falls monotonically with p, so the
// root is unique on the pressures that every present material's EOS can represent.
//
// Method: Newton's method inside a bracket that is finite from the start,
//   max_m p_m(rho_CC,m) <= p <= max_m p_m(n rho_CC,m),
// with p_m the EOS pressure at T_m and n the number of materials with mass: alone in the cell a
// material would sit at its own p_m(rho_CC,m), and the others only squeeze it; at the root one
// material fills at least 1/n of the cell. The bounds are cut to the pressures every material can
// represent (an ideal gas needs p > 0, a linear liquid p > p0 - Kf rho0, a solid p < p_ref + K).
// For one material both bounds are its own pressure; for two at one half each the upper bound is
// the root. A guess outside the bracket starts from the nearer bound.
//
// With S = sum theta and S' = dS/dp = -sum theta_m kappa_m, kappa_m = 1/(rho_micro,m dp/drho_m),
// the Newton variable follows what dominates S':
//   - gas-like materials (p kappa ~ 1, theta ~ 1/p): Newton on S - 1 in x = 1/p, in which their
//     theta is linear. Newton in p would creep towards the root of a/p - d, doubling p per step
//     (a thin gas in a liquid, far below the root).
//   - otherwise: Newton on F(p) = 1 - 1/S in p, step dp = -(S - 1) S/S'. F is linear for one linear
//     liquid (and one ideal gas), and the step is Newton's on S - 1 when S is near 1.
// Every evaluation shrinks the bracket (S > 1: p is below the root). A Newton iterate outside the
// bracket, or one whose step grew, is replaced by the bracket's untried bound (when it points past
// it) or by a bisection, geometric when the bracket spans more than a factor 4 of positive pressures.
//
// Converged when |S - 1| < 100 DBL_EPSILON (Uintah's test) or when the pressure changes by less than
// 1e-14 relative. Nothing throws: the result carries a status, and the caller reports the cell.
#include "ice/eos.hpp"

#include <cfloat>

namespace cfdmpm::ice {

struct EquilibrationControl {
  int max_iterations = 100;                         // Uintah's max_iteration_equilibration default
  double residual_tolerance = 100.0 * DBL_EPSILON;  // on |sum theta - 1|
  double relative_pressure_tolerance = 1e-14;       // on |dp|/|p|
};

enum class EquilibrationStatus : int {
  Converged = 0,
  NotConverged,  // max_iterations reached (or no root inside the EOS ranges); values at the last p
  InvalidInput,  // a mass density is negative or not a number, no material has mass, the count is out
                 // of range, or the materials' pressure ranges do not overlap
};

/// Everything the later steps need from the equilibration, per material m < count.
struct EquilibrationResult {
  double pressure = 0.0;                  // p [Pa]
  MaterialArray<double> volume_fraction;  // theta_m = rho_CC,m/rho_micro,m (0 for a material without mass)
  MaterialArray<double> density;          // rho_micro,m = EOS density(p, T_m) [kg/m^3]
  MaterialArray<double> sound_speed;      // c_m [m/s]
  MaterialArray<double> compressibility;  // kappa_m = 1/(rho_micro,m c_m^2) [1/Pa]
  int iterations = 0;                     // EOS evaluations of the whole cell
  int bisections = 0;                     // of those, how many came from bisection, not Newton
  EquilibrationStatus status = EquilibrationStatus::InvalidInput;

  KOKKOS_INLINE_FUNCTION bool converged() const { return status == EquilibrationStatus::Converged; }
};

namespace detail {

/// A point strictly inside the open interval (lo, hi); +-DBL_MAX marks an unbounded side.
KOKKOS_INLINE_FUNCTION double insideBracket(double lo, double hi)
{
  const bool lo_bounded = lo > -DBL_MAX;
  const bool hi_bounded = hi < DBL_MAX;
  if (lo_bounded && hi_bounded) {
    if (lo > 0.0 && hi > 4.0 * lo)
      return Kokkos::Experimental::sqrt(lo) * Kokkos::Experimental::sqrt(hi);  // pressures span decades
    return 0.5 * lo + 0.5 * hi;
  }
  if (lo_bounded) return lo + Kokkos::Experimental::fmax(1.0, Kokkos::Experimental::fabs(lo));
  if (hi_bounded) return hi - Kokkos::Experimental::fmax(1.0, Kokkos::Experimental::fabs(hi));
  return 0.0;
}

}  // namespace detail

/// Finds the common pressure of `count` materials in one cell.
///   eos[m], mass_density[m] = mass_m/V_cell [kg/m^3], temperature[m] [K] for m < count;
///   pressure_guess [Pa]: any start, best the cell's pressure of the previous step (a guess outside
///   the EOS ranges is replaced by a point inside).
/// Materials with zero mass density take no part in the root; their density, sound speed and
/// compressibility are still evaluated at the result pressure.
/// Count > 0 fixes the number of materials at compile time (loops with constant bounds; `count` must
/// equal it, else InvalidInput); 0 reads it from `count`.
template <int Count = 0>
KOKKOS_INLINE_FUNCTION
EquilibrationResult equilibrationPressure(int count, const MaterialArray<Eos>& eos,
                                          const MaterialArray<double>& mass_density,
                                          const MaterialArray<double>& temperature, double pressure_guess,
                                          const EquilibrationControl& control = EquilibrationControl())
{
  EquilibrationResult result;
  if (count < 1 || count > kMaxMaterials) return result;
  if (Count > 0 && count != Count) return result;
  const int n = Count > 0 ? Count : count;

  // The bracket [lo, hi]. First, bounds on the root: alone in the cell, material m would sit at
  // p_m(rho_CC,m); the others only squeeze it, so p >= max_m p_m(rho_CC,m). And at the root some
  // material fills at least 1/n of the cell (n materials with mass), so p <= max_m p_m(n rho_CC,m).
  // Then the pressures every present material can represent (open bounds).
  int present = 0;
  for (int m = 0; m < n; ++m) {
    if (!(mass_density[m] >= 0.0)) return result;
    if (mass_density[m] > 0.0) ++present;
  }
  if (present == 0) return result;
  double lower_root = -DBL_MAX, upper_root = -DBL_MAX;
  double lo = -DBL_MAX, hi = DBL_MAX;
  for (int m = 0; m < n; ++m) {
    if (mass_density[m] == 0.0) continue;
    const double T = temperature[m];
    // Each bound is widened by its round-off, 16 eps (|p| + rho dp/drho), so that it is a bound of
    // the computed root too: with two materials at one half each, the upper bound is the root.
    const double alone_density = mass_density[m];
    const double squeezed_density = present * mass_density[m];
    const double alone = eos[m].pressure(alone_density, T);
    const double squeezed = eos[m].pressure(squeezed_density, T);
    const double alone_error =
        Kokkos::Experimental::fabs(alone) + alone_density * eos[m].dp_drho(alone_density, T);
    const double squeezed_error =
        Kokkos::Experimental::fabs(squeezed) + squeezed_density * eos[m].dp_drho(squeezed_density, T);
    lower_root = Kokkos::Experimental::fmax(lower_root, alone - 16.0 * DBL_EPSILON * alone_error);
    upper_root = Kokkos::Experimental::fmax(upper_root, squeezed + 16.0 * DBL_EPSILON * squeezed_error);
    const PressureRange range = eos[m].pressure_range(T);
    lo = Kokkos::Experimental::fmax(lo, range.min);
    hi = Kokkos::Experimental::fmin(hi, range.max);
  }
  if (!(lo < hi)) return result;  // no pressure suits every material
  // Closed bounds (the root may sit on them) where they lie inside the open EOS ranges.
  const bool lower_is_root_bound = lower_root > lo && lower_root < hi;
  const bool upper_is_root_bound = upper_root > lo && upper_root < hi;
  if (lower_is_root_bound) lo = lower_root;
  if (upper_is_root_bound) hi = upper_root;

  double p;
  if (pressure_guess > lo && pressure_guess < hi)
    p = pressure_guess;
  else if (pressure_guess <= lo && lower_is_root_bound)
    p = lo;
  else if (pressure_guess >= hi && upper_is_root_bound)
    p = hi;
  else
    p = detail::insideBracket(lo, hi);
  double previous_step = DBL_MAX;  // the first Newton step is always tried
  double older_step = DBL_MAX;     // the step before the previous one
  bool lo_untried = lower_is_root_bound && p != lo;  // closed bounds not evaluated yet
  bool hi_untried = upper_is_root_bound && p != hi;
  double evaluated_at = 0.0;
  bool evaluated = false;
  result.status = EquilibrationStatus::NotConverged;

  while (result.iterations < control.max_iterations) {
    ++result.iterations;
    double sum = 0.0;        // S = sum theta
    double slope = 0.0;      // S' = d(sum theta)/dp < 0
    double gas_slope = 0.0;  // the part of S' from gas-like materials (theta ~ 1/p)
    for (int m = 0; m < n; ++m) {
      if (mass_density[m] == 0.0) continue;
      const double rho = eos[m].density(p, temperature[m]);
      const double theta = mass_density[m] / rho;
      const double compressibility = 1.0 / (rho * eos[m].dp_drho(rho, temperature[m]));
      result.density[m] = rho;
      result.volume_fraction[m] = theta;
      sum += theta;
      slope -= theta * compressibility;
      if (p * compressibility > 0.5) gas_slope -= theta * compressibility;  // ideal gas: p kappa = 1
    }
    evaluated = true;
    evaluated_at = p;

    const double residual = sum - 1.0;
    if (Kokkos::Experimental::fabs(residual) < control.residual_tolerance) {
      result.status = EquilibrationStatus::Converged;
      break;
    }
    if (residual > 0.0) {
      lo = p;  // the materials need more room than the cell has: p is below the root
      lo_untried = false;
    } else if (residual < 0.0) {
      hi = p;
      hi_untried = false;
    }

    double p_next;
    if (gas_slope < 0.5 * slope)
      p_next = 1.0 / (1.0 / p + residual / (p * p * slope));  // Newton in x = 1/p
    else
      p_next = p - residual * sum / slope;  // Newton on F = 1 - 1/S
    // A Newton step this small says the root is here, even on a closed bracket (one material:
    // lo = hi = its own pressure). Bisections are not tested so: they also shrink when there is no
    // root, the bracket then closing on a bound of an EOS range.
    if (Kokkos::Experimental::fabs(p_next - p) <=
        control.relative_pressure_tolerance * Kokkos::Experimental::fabs(p)) {
      p = p_next;
      result.status = EquilibrationStatus::Converged;
      break;
    }
    const double newton_step = Kokkos::Experimental::fabs(p_next - p);
    if (p_next >= hi && hi_untried && newton_step <= previous_step) {
      p_next = hi;
      hi_untried = false;
    } else if (p_next <= lo && lo_untried && newton_step <= previous_step) {
      p_next = lo;
      lo_untried = false;
    } else if (!(p_next > lo && p_next < hi) || newton_step > previous_step || newton_step > 0.5 * older_step) {
      // Bisection also where Newton does not halve its step in two iterations (rtsafe's rule,
      // Numerical Recipes 9.4): the two Newton forms above can take turns across the root, each
      // step a little shorter than the last, and never converge (a bed cut cell with a trace of
      // soft sand, K = 1e5 Pa near 1e5 Pa, and water: 100 iterations from 1.0e5 to 1.1e6 Pa and
      // back, the root at 2.7e5 Pa; Equilibration.AlternatingNewtonFormsConverge).
      if (!(lo < hi)) break;  // closed on a bound without a root: not converged
      p_next = detail::insideBracket(lo, hi);
      ++result.bisections;
    }
    older_step = previous_step;
    previous_step = Kokkos::Experimental::fabs(p_next - p);
    p = p_next;
  }

  // Values of every material (including those without mass) at the final pressure.
  result.pressure = p;
  for (int m = 0; m < n; ++m) {
    const double T = temperature[m];
    if (mass_density[m] == 0.0 || !evaluated || evaluated_at != p) {
      result.density[m] = eos[m].density(p, T);
      result.volume_fraction[m] = mass_density[m] == 0.0 ? 0.0 : mass_density[m] / result.density[m];
    }
    const double rho = result.density[m];
    const double c2 = eos[m].sound_speed_squared(rho, T);
    result.sound_speed[m] = Kokkos::Experimental::sqrt(c2);
    result.compressibility[m] = 1.0 / (rho * c2);
  }
  return result;
}

}  // namespace cfdmpm::ice
