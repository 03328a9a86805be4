#pragma once
// Small fixed-size matrices for pointwise MPM kernels (shape functions, constitutive updates).
//
// Mat<Dim> is a Dim x Dim matrix of doubles held by value (registers / stack), with the handful of
// operations a stress update needs: sums, products, transpose, trace, determinant, inverse,
// symmetric and skew parts, deviator, double contraction, a plane-strain embedding of 2 x 2 into
// 3 x 3, and the eigen-decomposition of a symmetric 3 x 3 matrix (cyclic Jacobi) for principal
// stresses. Everything is KOKKOS_INLINE_FUNCTION, allocation-free and branch-light, so it runs
// unchanged inside Kokkos kernels on the Serial and OpenMP back ends.
//
// Conventions: a(i, j) is row i, column j; operator* between two matrices is the matrix product;
// contract(A, B) = A : B = sum_ij A_ij B_ij.
#include <Kokkos_Core.hpp>

#include "common/kernel_math.hpp"

#include <cfloat>

namespace cfdmpm::mpm {

/// Dim x Dim matrix held by value; zero on default construction.
template <int Dim>
struct Mat {
  static_assert(Dim >= 1 && Dim <= 3, "Mat is for 1 to 3 dimensions");
  double a[Dim][Dim] = {};

  KOKKOS_INLINE_FUNCTION double& operator()(int i, int j) { return a[i][j]; }
  KOKKOS_INLINE_FUNCTION const double& operator()(int i, int j) const { return a[i][j]; }

  KOKKOS_INLINE_FUNCTION static Mat zero() { return Mat{}; }
  KOKKOS_INLINE_FUNCTION static Mat identity()
  {
    Mat m;
    for (int i = 0; i < Dim; ++i) m.a[i][i] = 1.0;
    return m;
  }
};

template <int Dim>
KOKKOS_INLINE_FUNCTION Mat<Dim> operator+(const Mat<Dim>& x, const Mat<Dim>& y)
{
  Mat<Dim> r;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) r.a[i][j] = x.a[i][j] + y.a[i][j];
  return r;
}

template <int Dim>
KOKKOS_INLINE_FUNCTION Mat<Dim> operator-(const Mat<Dim>& x, const Mat<Dim>& y)
{
  Mat<Dim> r;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) r.a[i][j] = x.a[i][j] - y.a[i][j];
  return r;
}

template <int Dim>
KOKKOS_INLINE_FUNCTION Mat<Dim> operator*(double s, const Mat<Dim>& x)
{
  Mat<Dim> r;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) r.a[i][j] = s * x.a[i][j];
  return r;
}

/// Matrix product x y.
template <int Dim>
KOKKOS_INLINE_FUNCTION Mat<Dim> operator*(const Mat<Dim>& x, const Mat<Dim>& y)
{
  Mat<Dim> r;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) {
      double sum = 0.0;
      for (int k = 0; k < Dim; ++k) sum += x.a[i][k] * y.a[k][j];
      r.a[i][j] = sum;
    }
  return r;
}

template <int Dim>
KOKKOS_INLINE_FUNCTION Mat<Dim> transpose(const Mat<Dim>& x)
{
  Mat<Dim> r;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) r.a[i][j] = x.a[j][i];
  return r;
}

template <int Dim>
KOKKOS_INLINE_FUNCTION double trace(const Mat<Dim>& x)
{
  double t = 0.0;
  for (int i = 0; i < Dim; ++i) t += x.a[i][i];
  return t;
}

/// A : B = sum_ij A_ij B_ij.
template <int Dim>
KOKKOS_INLINE_FUNCTION double contract(const Mat<Dim>& x, const Mat<Dim>& y)
{
  double s = 0.0;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) s += x.a[i][j] * y.a[i][j];
  return s;
}

template <int Dim>
KOKKOS_INLINE_FUNCTION double frobeniusNorm(const Mat<Dim>& x)
{
  return math::sqrt(contract(x, x));
}

/// (x + x^T) / 2.
template <int Dim>
KOKKOS_INLINE_FUNCTION Mat<Dim> symmetricPart(const Mat<Dim>& x)
{
  Mat<Dim> r;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) r.a[i][j] = 0.5 * (x.a[i][j] + x.a[j][i]);
  return r;
}

/// (x - x^T) / 2.
template <int Dim>
KOKKOS_INLINE_FUNCTION Mat<Dim> skewPart(const Mat<Dim>& x)
{
  Mat<Dim> r;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) r.a[i][j] = 0.5 * (x.a[i][j] - x.a[j][i]);
  return r;
}

/// x - tr(x)/Dim I. For a stress in plane strain, build the 3 x 3 tensor first (embedPlaneStrain).
template <int Dim>
KOKKOS_INLINE_FUNCTION Mat<Dim> deviator(const Mat<Dim>& x)
{
  Mat<Dim> r = x;
  const double mean = trace(x) / Dim;
  for (int i = 0; i < Dim; ++i) r.a[i][i] -= mean;
  return r;
}

KOKKOS_INLINE_FUNCTION double determinant(const Mat<1>& x) { return x.a[0][0]; }
KOKKOS_INLINE_FUNCTION double determinant(const Mat<2>& x)
{
  return x.a[0][0] * x.a[1][1] - x.a[0][1] * x.a[1][0];
}
KOKKOS_INLINE_FUNCTION double determinant(const Mat<3>& x)
{
  return x.a[0][0] * (x.a[1][1] * x.a[2][2] - x.a[1][2] * x.a[2][1]) -
         x.a[0][1] * (x.a[1][0] * x.a[2][2] - x.a[1][2] * x.a[2][0]) +
         x.a[0][2] * (x.a[1][0] * x.a[2][1] - x.a[1][1] * x.a[2][0]);
}

/// Inverse by the adjugate; the caller guarantees det(x) != 0.
KOKKOS_INLINE_FUNCTION Mat<2> inverse(const Mat<2>& x)
{
  const double inv_det = 1.0 / determinant(x);
  Mat<2> r;
  r.a[0][0] = x.a[1][1] * inv_det;
  r.a[0][1] = -x.a[0][1] * inv_det;
  r.a[1][0] = -x.a[1][0] * inv_det;
  r.a[1][1] = x.a[0][0] * inv_det;
  return r;
}
KOKKOS_INLINE_FUNCTION Mat<3> inverse(const Mat<3>& x)
{
  const double inv_det = 1.0 / determinant(x);
  Mat<3> r;
  r.a[0][0] = (x.a[1][1] * x.a[2][2] - x.a[1][2] * x.a[2][1]) * inv_det;
  r.a[0][1] = (x.a[0][2] * x.a[2][1] - x.a[0][1] * x.a[2][2]) * inv_det;
  r.a[0][2] = (x.a[0][1] * x.a[1][2] - x.a[0][2] * x.a[1][1]) * inv_det;
  r.a[1][0] = (x.a[1][2] * x.a[2][0] - x.a[1][0] * x.a[2][2]) * inv_det;
  r.a[1][1] = (x.a[0][0] * x.a[2][2] - x.a[0][2] * x.a[2][0]) * inv_det;
  r.a[1][2] = (x.a[0][2] * x.a[1][0] - x.a[0][0] * x.a[1][2]) * inv_det;
  r.a[2][0] = (x.a[1][0] * x.a[2][1] - x.a[1][1] * x.a[2][0]) * inv_det;
  r.a[2][1] = (x.a[0][1] * x.a[2][0] - x.a[0][0] * x.a[2][1]) * inv_det;
  r.a[2][2] = (x.a[0][0] * x.a[1][1] - x.a[0][1] * x.a[1][0]) * inv_det;
  return r;
}

/// Embeds a Dim x Dim tensor in 3 x 3. For Dim = 2 the out-of-plane diagonal entry is `zz` and the
/// xz, yz entries are zero (plane strain: a 2-D scene is a slice of a 3-D body with no motion and
/// no shear in z). For Dim = 3 it is the identity map and `zz` is ignored.
template <int Dim>
KOKKOS_INLINE_FUNCTION Mat<3> embedPlaneStrain(const Mat<Dim>& x, double zz)
{
  if constexpr (Dim == 3) {
    return x;
  } else {
    static_assert(Dim == 2, "plane strain embeds 2-D tensors");
    Mat<3> r;
    r.a[0][0] = x.a[0][0];
    r.a[0][1] = x.a[0][1];
    r.a[1][0] = x.a[1][0];
    r.a[1][1] = x.a[1][1];
    r.a[2][2] = zz;
    return r;
  }
}

/// Inverse of embedPlaneStrain: the leading Dim x Dim block goes to `x`; for Dim = 2 the zz entry
/// goes to `zz` (for Dim = 3, `zz` is left untouched).
template <int Dim>
KOKKOS_INLINE_FUNCTION void extractPlaneStrain(const Mat<3>& full, Mat<Dim>& x, double& zz)
{
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) x.a[i][j] = full.a[i][j];
  if constexpr (Dim == 2) zz = full.a[2][2];
}

/// Eigen-decomposition of a symmetric 3 x 3 matrix by the cyclic Jacobi method: on return
/// values[0] >= values[1] >= values[2] and column k of `vectors` is the unit eigenvector of
/// values[k], so x = V diag(values) V^T. Jacobi is used for its accuracy on nearly repeated
/// eigenvalues (Tresca corners) and because entries already zero stay exactly zero, so a
/// plane-strain tensor keeps e_z as an exact eigenvector. Converges quadratically; 3-5 sweeps.
KOKKOS_INLINE_FUNCTION void symmetricEigen(const Mat<3>& x, double values[3], Mat<3>& vectors)
{
  Mat<3> a = symmetricPart(x);
  Mat<3> v = Mat<3>::identity();
  const double scale = frobeniusNorm(a);
  constexpr int kMaxSweeps = 50;
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    const double off = a.a[0][1] * a.a[0][1] + a.a[0][2] * a.a[0][2] + a.a[1][2] * a.a[1][2];
    if (off <= (DBL_EPSILON * scale) * (DBL_EPSILON * scale) * 1e-4) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        const double apq = a.a[p][q];
        if (apq == 0.0) continue;
        // Rotation angle that zeroes a(p, q) (Golub & Van Loan, Algorithm 8.4.1).
        const double theta = (a.a[q][q] - a.a[p][p]) / (2.0 * apq);
        const double t = (theta >= 0.0 ? 1.0 : -1.0) /
                         (math::abs(theta) + (math::abs(theta) > 1e150
                                                  ? math::abs(theta)
                                                  : math::sqrt(theta * theta + 1.0)));
        const double c = 1.0 / math::sqrt(t * t + 1.0);
        const double s = t * c;
        // a <- J^T a J with J the rotation in the (p, q) plane.
        for (int k = 0; k < 3; ++k) {
          const double akp = a.a[k][p];
          const double akq = a.a[k][q];
          a.a[k][p] = c * akp - s * akq;
          a.a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const double apk = a.a[p][k];
          const double aqk = a.a[q][k];
          a.a[p][k] = c * apk - s * aqk;
          a.a[q][k] = s * apk + c * aqk;
        }
        a.a[p][q] = 0.0;
        a.a[q][p] = 0.0;
        for (int k = 0; k < 3; ++k) {
          const double vkp = v.a[k][p];
          const double vkq = v.a[k][q];
          v.a[k][p] = c * vkp - s * vkq;
          v.a[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  // Sort descending (three elements: a fixed sequence of compare-and-swap).
  int order[3] = {0, 1, 2};
  auto swap_if_less = [&](int i, int j) {
    if (a.a[order[i]][order[i]] < a.a[order[j]][order[j]]) {
      const int tmp = order[i];
      order[i] = order[j];
      order[j] = tmp;
    }
  };
  swap_if_less(0, 1);
  swap_if_less(1, 2);
  swap_if_less(0, 1);
  for (int k = 0; k < 3; ++k) {
    values[k] = a.a[order[k]][order[k]];
    for (int i = 0; i < 3; ++i) vectors.a[i][k] = v.a[i][order[k]];
  }
}

}  // namespace cfdmpm::mpm
