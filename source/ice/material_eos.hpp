#pragma once
// The equation of state of each scene material, built once from its validated input sublist.
#include "ice/eos.hpp"
#include "input/scene.hpp"

#include <vector>

namespace cfdmpm {

/// The EOS of a fluid material from its `equation_of_state` sublist (input keys in doc/input.md).
ice::Eos fluidEos(const MaterialSpec& material);

}  // namespace cfdmpm
