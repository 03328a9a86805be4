#pragma once
// Rigid material: particles move with a prescribed velocity and carry no stress. Used for the bed
// when it is meshed as particles but need not deform (the cheap alternative to the stiff
// Neo-Hookean bed, whose 440 m/s sound speed would set the time step). The grid-to-particle
// transfer sets the particle velocity to velocity(); the stress update writes zero.
#include "mpm/constitutive/common.hpp"

namespace cfdmpm::mpm {

struct RigidParameters {
  double velocity[3] = {0.0, 0.0, 0.0};  ///< prescribed velocity (m/s); entries beyond Dim ignored
};

class Rigid {
 public:
  explicit Rigid(const RigidParameters& parameters) : parameters_(parameters) {}

  /// Prescribed velocity component d (m/s).
  KOKKOS_INLINE_FUNCTION double velocity(int d) const { return parameters_.velocity[d]; }
  /// A rigid body carries no elastic wave that limits the time step.
  KOKKOS_INLINE_FUNCTION double waveSpeed(double /*density*/) const { return 0.0; }

  template <int Dim>
  KOKKOS_INLINE_FUNCTION void update(const StepKinematics<Dim>& /*kinematics*/,
                                     MaterialState& state, Mat<Dim>& stress) const
  {
    stress = Mat<Dim>::zero();
    state.out_of_plane_stress = 0.0;
  }

 private:
  RigidParameters parameters_;
};

}  // namespace cfdmpm::mpm
