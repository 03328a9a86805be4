#pragma once
// The equation of state of each scene material, built once from its validated input sublist.
#include "ice/eos.hpp"
#include "input/scene.hpp"
#include "mpmice/initial_state.hpp"

#include <vector>

namespace cfdmpm {

/// The EOS of a fluid material from its `equation_of_state` sublist (input keys in doc/input.md).
ice::Eos fluidEos(const MaterialSpec& material);

/// ρ_micro(p, T) for every material of the scene, in material order: a fluid's EOS solved for the
/// density; a solid's rest density (its bulk response is the MPM model's).
std::vector<DensityOfState> densityFunctions(const Scene& scene);

}  // namespace cfdmpm
