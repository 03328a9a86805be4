#pragma once
// Helpers shared by the constitutive-model tests: kinematics builders, random matrices,
// rotations, principal stresses.
#include "mpm/constitutive/common.hpp"

#include <cmath>
#include <random>

namespace cfdmpm::mpm::testing {

/// Kinematics of one step with velocity gradient L and time step dt; F is (I + dt L) F_old.
template <int Dim>
StepKinematics<Dim> step(const Mat<Dim>& L, double dt, const Mat<Dim>& F_old = Mat<Dim>::identity())
{
  StepKinematics<Dim> k;
  k.velocity_gradient = L;
  k.dt = dt;
  k.deformation_gradient = (Mat<Dim>::identity() + dt * L) * F_old;
  return k;
}

template <int Dim>
Mat<Dim> randomMatrix(std::mt19937_64& rng, double scale)
{
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat<Dim> m;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) m(i, j) = scale * u(rng);
  return m;
}

/// Rotation by angle about a unit axis (Rodrigues).
inline Mat<3> rotation3(const double axis_in[3], double angle)
{
  const double n = std::sqrt(axis_in[0] * axis_in[0] + axis_in[1] * axis_in[1] +
                             axis_in[2] * axis_in[2]);
  const double a[3] = {axis_in[0] / n, axis_in[1] / n, axis_in[2] / n};
  Mat<3> K;
  K(0, 1) = -a[2];
  K(0, 2) = a[1];
  K(1, 0) = a[2];
  K(1, 2) = -a[0];
  K(2, 0) = -a[1];
  K(2, 1) = a[0];
  return Mat<3>::identity() + std::sin(angle) * K + (1.0 - std::cos(angle)) * (K * K);
}

inline Mat<2> rotation2(double angle)
{
  Mat<2> R;
  R(0, 0) = std::cos(angle);
  R(0, 1) = -std::sin(angle);
  R(1, 0) = std::sin(angle);
  R(1, 1) = std::cos(angle);
  return R;
}

/// Principal stresses (descending) of the full plane-strain / 3-D stress.
template <int Dim>
void principalStresses(const Mat<Dim>& stress, const MaterialState& state, double values[3])
{
  Mat<3> vectors;
  symmetricEigen(embedPlaneStrain(stress, state.out_of_plane_stress), values, vectors);
}

/// Maximum shear stress (sigma_1 - sigma_3) / 2.
template <int Dim>
double maxShearStress(const Mat<Dim>& stress, const MaterialState& state)
{
  double v[3];
  principalStresses(stress, state, v);
  return 0.5 * (v[0] - v[2]);
}

/// Mean stress tr(sigma)/3 of the full tensor (tension positive).
template <int Dim>
double meanStress(const Mat<Dim>& stress, const MaterialState& state)
{
  return trace(embedPlaneStrain(stress, state.out_of_plane_stress)) / 3.0;
}

template <int Dim>
double maxAbsDifference(const Mat<Dim>& a, const Mat<Dim>& b)
{
  double m = 0;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) m = std::max(m, std::abs(a(i, j) - b(i, j)));
  return m;
}

}  // namespace cfdmpm::mpm::testing
