#pragma once
// The state at t = 0 from the scene's regions: volume fractions by sampling the geometry, the
// pressure (uniform, or hydrostatic from the top of the domain down), and each material's density
// from its equation of state at that pressure and the initial temperature.
#include "input/scene.hpp"
#include "mpmice/cell_state.hpp"

#include <functional>
#include <vector>

namespace cfdmpm {

/// ρ_micro(p, T) of one material: its equation of state solved for the density.
using DensityOfState = std::function<double(double pressure, double temperature)>;

template <int Dim>
void setInitialState(const Scene& scene, const std::vector<DensityOfState>& density_of, CellState<Dim>& state);

}  // namespace cfdmpm
