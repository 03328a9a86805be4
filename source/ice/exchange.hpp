#pragma once
// Implicit momentum and heat exchange between the materials of one cell or one face
// (MPMICE step 4 and step 8; seed paper eqs. 2-3, f_rs = K_rs theta_r theta_s (u_r - u_s) and
// q_rs = H_rs theta_r theta_s (T_r - T_s); Kashiwa et al. 2000, "A cell-centered ICE method for
// multiphase flow simulations", LA-UR; Uintah ScalarExch::addExch_Vel_Temp_CC and vel_FC_exchange).
//
// The scheme. Per unit mass of material m the exchange force is sum_n K_mn theta_n v_m (u_n - u_m)
// (v_m = specific volume), taken implicitly over the step dt:
//
//   u'_m = u_m + sum_n beta_mn (u'_n - u'_m),   beta_mn = dt v_m theta_n K_mn   (Uintah's beta),
//
// i.e. A u' = u with A = I + diag(sum_n beta_mn) - beta. Multiplying row m by the bulk density
// w_m = theta_m/v_m gives the symmetric form
//
//   S u' = W u,   S = W + Laplacian(G),   G_mn = dt theta_m theta_n K_mn,   W = diag(w),
//
// whose columns sum to w: sum_m w_m u'_m = sum_m w_m u_m, the momentum is conserved exactly.
//
// How it is solved, and why. K = 1e15 (velocity equilibrium, as in the seed scene) makes G/w as
// large as 1e10 or more. Solving Uintah's form A du = b directly by Gaussian elimination gives
// errors of order eps * beta in the common (mass-weighted) velocity: the momentum error then grows
// with K. Here instead:
//   1. The conserved weighted mean ubar = sum w u / sum w is taken out: u' = ubar + d with
//      S d = W (u - ubar) (A 1 = 1, so any constant shifts through). d is the part of the velocity
//      that exchange drives to zero; for large K it is O(|u - ubar|/beta) and its error stays
//      O(eps |u - ubar|) whatever K is.
//   2. S is a symmetric, diagonally dominant M-matrix. It is eliminated subtraction-free (the GTH
//      variant of Gaussian elimination: Grassmann, Taksar & Heyman 1985; its accuracy for diagonally
//      dominant M-matrices: Alfa, Xue & Ye 2002): the matrix is held as its off-diagonal couplings
//      G >= 0 and row sums w >= 0, every pivot is computed as a sum of non-negative numbers, never as
//      1 + beta - beta^2/(1 + beta). Pivots are accurate for any K, even when 1 + beta rounds to beta.
//      Partial pivoting would pick the diagonal at every step of this matrix (each column's diagonal
//      is at least the sum of its other entries), so there is no row exchange to do.
//   3. d is projected to sum w d = 0, making conservation exact to round-off by construction.
// A material without mass (w_m = 0) exerts no force; its velocity follows its row of A,
// u'_m = (u_m + sum_n beta_mn u'_n)/(1 + sum_n beta_mn), a convex combination of the others.
//
// Heat is the same with H_mn, T, w_m = rho_m cv_m and beta_mn = dt v_m theta_n H_mn/cv_m: it conserves
// sum_m mass_m cv_m T_m.
#include "ice/eos.hpp"

#include <cfloat>

namespace cfdmpm::ice {

/// Symmetric exchange coefficients between materials, zero on the diagonal: K_mn [kg/(m^3 s)] for
/// momentum, H_mn [W/(m^3 K)] for heat.
struct ExchangeCoefficients {
  double value[kMaxMaterials][kMaxMaterials];

  KOKKOS_INLINE_FUNCTION ExchangeCoefficients()
  {
    for (int m = 0; m < kMaxMaterials; ++m)
      for (int n = 0; n < kMaxMaterials; ++n) value[m][n] = 0.0;
  }
  /// The same coefficient between every pair of materials.
  KOKKOS_INLINE_FUNCTION static ExchangeCoefficients uniform(double coefficient)
  {
    ExchangeCoefficients k;
    for (int m = 0; m < kMaxMaterials; ++m)
      for (int n = 0; n < kMaxMaterials; ++n) k.value[m][n] = m == n ? 0.0 : coefficient;
    return k;
  }
  /// From the upper triangle in material order (01, 02, ..., 0N-1, 12, ...), as Uintah's input
  /// <exchange_coefficients> lists them; `upper` holds count(count-1)/2 values.
  KOKKOS_INLINE_FUNCTION static ExchangeCoefficients fromUpperTriangle(int count, const double* upper)
  {
    ExchangeCoefficients k;
    int i = 0;
    for (int m = 0; m < count; ++m)
      for (int n = m + 1; n < count; ++n) k.set(m, n, upper[i++]);
    return k;
  }
  KOKKOS_INLINE_FUNCTION void set(int m, int n, double coefficient)
  {
    value[m][n] = coefficient;
    value[n][m] = coefficient;
  }
  KOKKOS_INLINE_FUNCTION double operator()(int m, int n) const { return value[m][n]; }
};

enum class ExchangeStatus : int {
  Ok = 0,
  NonFinite,     // an input or a result was infinite or not a number; the values are not to be used
  InvalidInput,  // count outside 0 ... kMaxMaterials; nothing was changed
};

namespace detail {

/// The exchange system of one cell or face, in the symmetric form of the file comment.
struct ExchangeSystem {
  int count;
  MaterialArray<double> weight;      // w_m >= 0, the conserved weight per unit volume
  MaterialArray<double> rate_scale;  // beta_mn = rate_scale_m theta_n K_mn dt (for massless rows)
  MaterialArray<double> volume_fraction;
  double dt;
};

KOKKOS_INLINE_FUNCTION bool isFinite(double x) { return x - x == 0.0; }

/// Two materials a < b, both with mass (weight > 0), exchanging: the elimination below for exactly
/// these two present, written out (its operations in its order, so that the results are the same to
/// the bit, without its index lists and loops over runtime counts). S = [[w0 + g01, -g01],
/// [-g10, w1 + g10]] and GTH gives the pivots w0 + g01 and w1 + l w0 (l = g10/(w0 + g01)): sums of
/// non-negative terms, as in the general case.
template <int MaxComponents>
KOKKOS_INLINE_FUNCTION void eliminatePair(const ExchangeSystem& system, const ExchangeCoefficients& K,
                                          double (&q)[kMaxMaterials][MaxComponents], int components, int a, int b)
{
  const double w0 = system.weight[a], w1 = system.weight[b];
  const double t0 = system.volume_fraction[a], t1 = system.volume_fraction[b];
  const double dt = system.dt;
  const double total_weight = w0 + w1;
  const double g01 = dt * t0 * t1 * K(a, b);
  const double g10 = dt * t1 * t0 * K(b, a);
  const double pivot0 = w0 + g01;
  const bool eliminate = g10 != 0.0;
  const double l = eliminate ? g10 / pivot0 : 0.0;
  const double pivot1 = eliminate ? w1 + l * w0 : w1;
  for (int c = 0; c < components; ++c) {
    double sum = 0.0;  // 0.0 + ... as in the general case (the sign of a zero sum)
    sum += w0 * q[a][c];
    sum += w1 * q[b][c];
    const double mean = sum / total_weight;
    double r0 = w0 * (q[a][c] - mean);
    double r1 = w1 * (q[b][c] - mean);
    if (eliminate) r1 += l * r0;
    r1 = r1 / pivot1;
    r0 = (r0 + g01 * r1) / pivot0;
    double drift = 0.0;
    drift += w0 * r0;
    drift += w1 * r1;
    drift /= total_weight;
    q[a][c] = mean + (r0 - drift);
    q[b][c] = mean + (r1 - drift);
  }
}

/// The elimination below written out for exactly two materials (eliminatePair where both have
/// mass), the same to the bit.
template <int MaxComponents>
KOKKOS_INLINE_FUNCTION ExchangeStatus implicitExchangeTwo(const ExchangeSystem& system,
                                                          const ExchangeCoefficients& K,
                                                          double (&q)[kMaxMaterials][MaxComponents],
                                                          int components)
{
  const double w0 = system.weight[0], w1 = system.weight[1];
  const double t0 = system.volume_fraction[0], t1 = system.volume_fraction[1];
  bool finite = isFinite(w0) && isFinite(w1) && isFinite(t0) && isFinite(t1) &&
                isFinite(system.rate_scale[0]) && isFinite(system.rate_scale[1]);
  for (int c = 0; c < components; ++c) finite = finite && isFinite(q[0][c]) && isFinite(q[1][c]);
  if (!finite) return ExchangeStatus::NonFinite;
  if (K(0, 1) == 0.0 && K(1, 0) == 0.0) return ExchangeStatus::Ok;  // no exchange: values unchanged

  const double dt = system.dt;
  if (w0 > 0.0 && w1 > 0.0) {
    eliminatePair(system, K, q, components, 0, 1);
  } else if (w0 > 0.0 || w1 > 0.0) {
    // One material with mass (a) keeps its value up to round-off; the massless one (b) follows its
    // row of A.
    const int a = w0 > 0.0 ? 0 : 1, b = 1 - a;
    const double w = a == 0 ? w0 : w1;
    const double beta = dt * system.rate_scale[b] * system.volume_fraction[a] * K(b, a);
    const double beta_sum = 0.0 + beta;
    for (int c = 0; c < components; ++c) {
      double sum = 0.0;
      sum += w * q[a][c];
      const double mean = sum / w;
      const double r = (w * (q[a][c] - mean)) / w;
      double drift = 0.0;
      drift += w * r;
      drift /= w;
      q[a][c] = mean + (r - drift);
      double pull = 0.0;
      pull += beta * q[a][c];
      q[b][c] = (q[b][c] + pull) / (1.0 + beta_sum);
    }
  } else {
    for (int c = 0; c < components; ++c) {
      q[0][c] = (q[0][c] + 0.0) / (1.0 + 0.0);
      q[1][c] = (q[1][c] + 0.0) / (1.0 + 0.0);
    }
  }
  for (int c = 0; c < components; ++c)
    if (!isFinite(q[0][c]) || !isFinite(q[1][c])) return ExchangeStatus::NonFinite;
  return ExchangeStatus::Ok;
}

/// The massless materials (weight 0) of the `count` follow their row of A with the new values of the
/// `np` present ones (`present`, ascending).
template <int MaxComponents>
KOKKOS_INLINE_FUNCTION void followPresent(const ExchangeSystem& system, const ExchangeCoefficients& K,
                                          double (&q)[kMaxMaterials][MaxComponents], int components, int count,
                                          const int (&present)[kMaxMaterials], int np)
{
  for (int m = 0; m < count; ++m) {
    if (system.weight[m] > 0.0) continue;
    double beta_sum = 0.0;
    double pull[MaxComponents];
    for (int c = 0; c < components; ++c) pull[c] = 0.0;
    for (int i = 0; i < np; ++i) {
      const int n = present[i];
      const double beta = system.dt * system.rate_scale[m] * system.volume_fraction[n] * K(m, n);
      beta_sum += beta;
      for (int c = 0; c < components; ++c) pull[c] += beta * q[n][c];
    }
    for (int c = 0; c < components; ++c) q[m][c] = (q[m][c] + pull[c]) / (1.0 + beta_sum);
  }
}

/// Ok if every value of the `count` materials is finite, else NonFinite.
template <int MaxComponents>
KOKKOS_INLINE_FUNCTION ExchangeStatus finiteValues(const double (&q)[kMaxMaterials][MaxComponents], int components,
                                                   int count)
{
  for (int m = 0; m < count; ++m)
    for (int c = 0; c < components; ++c)
      if (!isFinite(q[m][c])) return ExchangeStatus::NonFinite;
  return ExchangeStatus::Ok;
}

/// The general elimination for any number of materials (Count > 0: fixed at compile time). With
/// two of them present it takes eliminatePair (the same to the bit; Loops: the loops throughout,
/// which the tests compare it with).
template <int MaxComponents, int Count, bool Loops = false>
KOKKOS_INLINE_FUNCTION ExchangeStatus implicitExchangeGeneral(const ExchangeSystem& system,
                                                              const ExchangeCoefficients& K,
                                                              double (&q)[kMaxMaterials][MaxComponents],
                                                              int components)
{
  const int count = Count > 0 ? Count : system.count;  // 0 ... kMaxMaterials, checked by the callers

  // Materials with mass take part in the solve; list them and their couplings G = dt theta theta K.
  int present[kMaxMaterials];
  int np = 0;
  double total_weight = 0.0;
  bool coupled = false;
  for (int m = 0; m < count; ++m) {
    if (!isFinite(system.weight[m]) || !isFinite(system.volume_fraction[m]) ||
        !isFinite(system.rate_scale[m]))
      return ExchangeStatus::NonFinite;
    for (int c = 0; c < components; ++c)
      if (!isFinite(q[m][c])) return ExchangeStatus::NonFinite;
    if (system.weight[m] > 0.0) {
      present[np++] = m;
      total_weight += system.weight[m];
    }
    for (int n = 0; n < count && !coupled; ++n)
      if (n != m && K(m, n) != 0.0) coupled = true;
  }
  if (!coupled) return ExchangeStatus::Ok;  // no exchange: leave the values bit for bit
  if (!Loops && np == 2) {
    // Two present (a cell of the seed scene that no solid reaches: its water and air), written out.
    eliminatePair(system, K, q, components, present[0], present[1]);
    followPresent(system, K, q, components, count, present, np);
    return finiteValues(q, components, count);
  }

  double g[kMaxMaterials][kMaxMaterials];  // couplings among present materials (row i, column j)
  double excess[kMaxMaterials];            // row sums of S over the not yet eliminated columns
  double pivot[kMaxMaterials];
  double rhs[kMaxMaterials][MaxComponents];
  double mean[MaxComponents];

  // 1. The conserved weighted mean, and the right-hand side W (q - mean).
  for (int c = 0; c < components; ++c) {
    double sum = 0.0;
    for (int i = 0; i < np; ++i) sum += system.weight[present[i]] * q[present[i]][c];
    mean[c] = np > 0 ? sum / total_weight : 0.0;
  }
  for (int i = 0; i < np; ++i) {
    const int m = present[i];
    excess[i] = system.weight[m];
    for (int j = 0; j < np; ++j)
      g[i][j] = i == j ? 0.0 : system.dt * system.volume_fraction[m] * system.volume_fraction[present[j]] *
                                   K(m, present[j]);
    for (int c = 0; c < components; ++c) rhs[i][c] = system.weight[m] * (q[m][c] - mean[c]);
  }

  // 2. Subtraction-free elimination (GTH): pivot = row sum + couplings, all terms >= 0.
  for (int k = 0; k < np; ++k) {
    double p = excess[k];
    for (int j = k + 1; j < np; ++j) p += g[k][j];
    pivot[k] = p;
    for (int i = k + 1; i < np; ++i) {
      if (g[i][k] == 0.0) continue;
      const double l = g[i][k] / p;  // 0 < l <= 1
      excess[i] += l * excess[k];
      for (int j = k + 1; j < np; ++j)
        if (j != i) g[i][j] += l * g[k][j];
      for (int c = 0; c < components; ++c) rhs[i][c] += l * rhs[k][c];
    }
  }
  for (int k = np - 1; k >= 0; --k)
    for (int c = 0; c < components; ++c) {
      double x = rhs[k][c];
      for (int j = k + 1; j < np; ++j) x += g[k][j] * rhs[j][c];
      rhs[k][c] = x / pivot[k];
    }

  // 3. Project to sum w d = 0 and add the mean back.
  for (int c = 0; c < components; ++c) {
    double drift = 0.0;
    for (int i = 0; i < np; ++i) drift += system.weight[present[i]] * rhs[i][c];
    drift /= total_weight;
    for (int i = 0; i < np; ++i) q[present[i]][c] = mean[c] + (rhs[i][c] - drift);
  }

  followPresent(system, K, q, components, count, present, np);
  return finiteValues(q, components, count);
}

/// Applies the implicit exchange in place to `components` quantities q[m][c] (velocity components,
/// a temperature, a specific volume). Returns Ok unless something is not finite.
/// Count > 0 fixes the number of materials at compile time (it must equal system.count): Count = 2
/// takes the written-out elimination (implicitExchangeTwo), other counts the general one.
/// Loops = true: the general elimination's loops throughout (no written-out form; the tests'
/// reference for them).
template <int MaxComponents, int Count = 0, bool Loops = false>
KOKKOS_INLINE_FUNCTION ExchangeStatus implicitExchange(const ExchangeSystem& system,
                                                       const ExchangeCoefficients& K,
                                                       double (&q)[kMaxMaterials][MaxComponents],
                                                       int components)
{
  if constexpr (Loops)
    return implicitExchangeGeneral<MaxComponents, 0, true>(system, K, q, components);
  else if constexpr (Count == 2)
    return implicitExchangeTwo<MaxComponents>(system, K, q, components);
  else
    return implicitExchangeGeneral<MaxComponents, Count>(system, K, q, components);
}

}  // namespace detail

/// Cell-centred momentum exchange (Uintah addExch_Vel_Temp_CC, momentum part), in place.
///   mass_density[m] = Lagrangian mass_m/V_cell [kg/m^3] (the weight of the conserved momentum);
///   volume_fraction[m], specific_volume[m] [m^3/kg] from the equilibration; K [kg/(m^3 s)];
///   velocity[m] [m/s], Dim components, replaced by the exchanged velocity.
/// The symmetric form uses w_m = mass_density[m]; it equals Uintah's beta when
/// mass_density = volume_fraction/specific_volume, as after the equilibration.
/// Count > 0: the number of materials fixed at compile time (count must equal it; see implicitExchange,
/// also for Loops).
template <int Dim, int Count = 0, bool Loops = false>
KOKKOS_INLINE_FUNCTION ExchangeStatus exchangeMomentumCC(int count, double dt, const ExchangeCoefficients& K,
                                                         const MaterialArray<double>& mass_density,
                                                         const MaterialArray<double>& volume_fraction,
                                                         const MaterialArray<double>& specific_volume,
                                                         MaterialArray<Kokkos::Array<double, Dim>>& velocity)
{
  if (count < 0 || count > kMaxMaterials) return ExchangeStatus::InvalidInput;
  if (Count > 0 && count != Count) return ExchangeStatus::InvalidInput;
  const int n = Count > 0 ? Count : count;
  detail::ExchangeSystem system{n, mass_density, specific_volume, volume_fraction, dt};
  double q[kMaxMaterials][Dim];
  for (int m = 0; m < n; ++m)
    for (int d = 0; d < Dim; ++d) q[m][d] = velocity[m][d];
  const ExchangeStatus status = detail::implicitExchange<Dim, Count, Loops>(system, K, q, Dim);
  for (int m = 0; m < n; ++m)
    for (int d = 0; d < Dim; ++d) velocity[m][d] = q[m][d];
  return status;
}

/// Cell-centred heat exchange (Uintah addExch_Vel_Temp_CC, heat part), in place: conserves
/// sum_m mass_m cv_m T_m. H [W/(m^3 K)], specific_heat[m] = cv_m [J/(kg K)], temperature [K].
KOKKOS_INLINE_FUNCTION ExchangeStatus exchangeHeatCC(int count, double dt, const ExchangeCoefficients& H,
                                                     const MaterialArray<double>& mass_density,
                                                     const MaterialArray<double>& volume_fraction,
                                                     const MaterialArray<double>& specific_volume,
                                                     const MaterialArray<double>& specific_heat,
                                                     MaterialArray<double>& temperature)
{
  if (count < 0 || count > kMaxMaterials) return ExchangeStatus::InvalidInput;
  detail::ExchangeSystem system{count, {}, {}, volume_fraction, dt};
  double q[kMaxMaterials][1];
  for (int m = 0; m < count; ++m) {
    system.weight[m] = mass_density[m] * specific_heat[m];
    system.rate_scale[m] = specific_volume[m] / specific_heat[m];
    q[m][0] = temperature[m];
  }
  const ExchangeStatus status = detail::implicitExchange<1>(system, H, q, 1);
  for (int m = 0; m < count; ++m) temperature[m] = q[m][0];
  return status;
}

/// 2 a b / (a + b), the harmonic mean of two positive specific volumes, written so that it does not
/// overflow: a solid's equation of state, evaluated in a cell that the solid does not fill, at a
/// tension far beyond its range, gives ~1e308 (and 2 a overflows); then it is 2 / (1/a + 1/b), ~2 b.
/// Below 1e150 the first form, bit for bit as before.
KOKKOS_INLINE_FUNCTION double harmonicMean(double a, double b)
{
  if (a < 1e150 && b < 1e150) return 2.0 * a * b / (a + b);
  return 2.0 / (1.0 / a + 1.0 / b);
}

/// Face momentum exchange (Uintah vel_FC_exchange; Kashiwa 2000 above eq. 4.13), in place, for the
/// face-normal velocity of every material on one face between a left (L) and a right (R) cell.
/// On the face, v_m = 2 v_L v_R/(v_L + v_R) (harmonic mean) and theta_m = (theta_L + theta_R)/2, so
/// beta_mn = dt v_m theta_n K_mn and the conserved weight is theta_m/v_m.
/// face_specific_volume receives A^-1 v: the specific volume with which the pressure gradient acts
/// on each material's face velocity after the exchange (the pressure equation's coefficient). One
/// material, or K = 0, gives the harmonic mean itself; K -> infinity gives sum theta/sum(theta/v),
/// the mixture's specific volume, for every material.
/// Count > 0: the number of materials fixed at compile time, and Loops, as for exchangeMomentumCC.
template <int Count = 0, bool Loops = false>
KOKKOS_INLINE_FUNCTION ExchangeStatus exchangeMomentumFC(int count, double dt, const ExchangeCoefficients& K,
                                                         const MaterialArray<double>& volume_fraction_left,
                                                         const MaterialArray<double>& volume_fraction_right,
                                                         const MaterialArray<double>& specific_volume_left,
                                                         const MaterialArray<double>& specific_volume_right,
                                                         MaterialArray<double>& face_velocity,
                                                         MaterialArray<double>& face_specific_volume)
{
  if (count < 0 || count > kMaxMaterials) return ExchangeStatus::InvalidInput;
  if (Count > 0 && count != Count) return ExchangeStatus::InvalidInput;
  const int n = Count > 0 ? Count : count;
  detail::ExchangeSystem system{n, {}, {}, {}, dt};
  double q[kMaxMaterials][2];
  for (int m = 0; m < n; ++m) {
    const double vl = specific_volume_left[m];
    const double vr = specific_volume_right[m];
    const double v = harmonicMean(vl, vr);
    const double theta = 0.5 * (volume_fraction_left[m] + volume_fraction_right[m]);
    system.volume_fraction[m] = theta;
    system.rate_scale[m] = v;
    system.weight[m] = theta / v;
    q[m][0] = face_velocity[m];
    q[m][1] = v;
  }
  const ExchangeStatus status = detail::implicitExchange<2, Count, Loops>(system, K, q, 2);
  for (int m = 0; m < n; ++m) {
    face_velocity[m] = q[m][0];
    face_specific_volume[m] = q[m][1];
  }
  return status;
}

}  // namespace cfdmpm::ice
