#include "mpm/particles.hpp"

#include "grid/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace cfdmpm::mpm {

template <int Dim>
void Particles<Dim>::resize(int n)
{
  if (n > capacity() || capacity() == 0) {
    const int grown = std::max({n, capacity() + capacity() / 2, 16});
    if (capacity() == 0) {
      position = VectorView("particle position", grown);
      velocity = VectorView("particle velocity", grown);
      mass = ScalarView("particle mass", grown);
      volume = ScalarView("particle volume", grown);
      initial_volume = ScalarView("particle initial volume", grown);
      deformation_gradient = TensorView("particle deformation gradient", grown);
      stress = TensorView("particle stress", grown);
      state = Kokkos::View<MaterialState*, MemorySpace>("particle material state", grown);
      material = Kokkos::View<int*, MemorySpace>("particle material", grown);
      half_width = VectorView("particle half-width", grown);
      id = Kokkos::View<long long*, MemorySpace>("particle id", grown);
      velocity_gradient = TensorView("particle velocity gradient", grown);
      velocity_change = VectorView("particle velocity change", grown);
      own_acceleration = VectorView("particle own acceleration", grown);
    } else {
      Kokkos::resize(position, grown);
      Kokkos::resize(velocity, grown);
      Kokkos::resize(mass, grown);
      Kokkos::resize(volume, grown);
      Kokkos::resize(initial_volume, grown);
      Kokkos::resize(deformation_gradient, grown);
      Kokkos::resize(stress, grown);
      Kokkos::resize(state, grown);
      Kokkos::resize(material, grown);
      Kokkos::resize(half_width, grown);
      Kokkos::resize(id, grown);
      Kokkos::resize(velocity_gradient, grown);
      Kokkos::resize(velocity_change, grown);
      Kokkos::resize(own_acceleration, grown);
    }
  }
  count = n;
}

namespace {

/// Initial velocity at x: that of the last region (file order) containing x, else zero; the same
/// rule as MaterialRegions::materialAt uses for the material.
std::array<double, 3> regionVelocity(const Scene& scene, const std::array<double, 3>& x)
{
  for (int r = int(scene.regions.size()) - 1; r >= 0; --r)
    if (regionContains(scene.regions[r], scene.domain.dimension, x)) return scene.regions[r].velocity;
  return {0, 0, 0};
}

}  // namespace

template <int Dim>
Particles<Dim> seedParticles(const Scene& scene, const Layout<Dim>& layout, const std::vector<SolidMaterial>& solids)
{
  const Grid<Dim>& grid = layout.grid();
  const MaterialRegions regions(scene);
  int max_ppc = 1;
  for (const SolidMaterial& s : solids) max_ppc = std::max(max_ppc, s.particles_per_cell);
  long long lattice_size = 1;
  for (int d = 0; d < Dim; ++d) lattice_size *= max_ppc;

  struct Seed {
    std::array<double, 3> x, v;
    int material;
    long long id;
  };
  std::vector<Seed> seeds;
  for (const Box& box : layout.ownedCellBoxes())
    for (long long k = box.lower[2]; k < box.upper[2]; ++k)
      for (long long j = box.lower[1]; j < box.upper[1]; ++j)
        for (long long i = box.lower[0]; i < box.upper[0]; ++i) {
          const std::array<long long, 3> cell{i, j, k};
          for (int s = 0; s < int(solids.size()); ++s) {
            const int n = solids[s].particles_per_cell;
            const int points = Dim == 2 ? n * n : n * n * n;
            for (int q = 0; q < points; ++q) {
              std::array<double, 3> x{0, 0, 0};
              long long lattice = 0, stride = 1;
              int rest = q;
              for (int d = 0; d < Dim; ++d) {
                const int a = rest % n;
                rest /= n;
                x[d] = grid.nodePosition(d, cell[d]) + (a + 0.5) / n * grid.spacing()[d];
                lattice += a * stride;
                stride *= max_ppc;
              }
              if (regions.materialAt(x) != solids[s].scene_index) continue;
              const long long id = (grid.cellId(cell) * static_cast<long long>(solids.size()) + s) * lattice_size + lattice;
              // A rigid material moves with its prescribed velocity from the start.
              const Rigid* rigid = solids[s].model.getIf<Rigid>();
              const std::array<double, 3> v =
                  rigid ? std::array<double, 3>{rigid->velocity(0), rigid->velocity(1), rigid->velocity(2)}
                        : regionVelocity(scene, x);
              seeds.push_back(Seed{x, v, s, id});
            }
          }
        }

  Particles<Dim> particles;
  particles.resize(int(seeds.size()));
  auto position = Kokkos::create_mirror_view(particles.position);
  auto velocity = Kokkos::create_mirror_view(particles.velocity);
  auto mass = Kokkos::create_mirror_view(particles.mass);
  auto volume = Kokkos::create_mirror_view(particles.volume);
  auto initial_volume = Kokkos::create_mirror_view(particles.initial_volume);
  auto F = Kokkos::create_mirror_view(particles.deformation_gradient);
  auto stress = Kokkos::create_mirror_view(particles.stress);
  auto state = Kokkos::create_mirror_view(particles.state);
  auto material = Kokkos::create_mirror_view(particles.material);
  auto half_width = Kokkos::create_mirror_view(particles.half_width);
  auto id = Kokkos::create_mirror_view(particles.id);
  for (std::size_t p = 0; p < seeds.size(); ++p) {
    const Seed& seed = seeds[p];
    const SolidMaterial& solid = solids[seed.material];
    const int n = solid.particles_per_cell;
    const double share = 1.0 / std::pow(double(n), Dim);
    for (int d = 0; d < Dim; ++d) {
      position(p, d) = seed.x[d];
      velocity(p, d) = seed.v[d];
      half_width(p, d) = grid.spacing()[d] / (2.0 * n);  // uGIMP: l_p = h / (2 ppc)
      for (int e = 0; e < Dim; ++e) {
        F(p, d, e) = d == e ? 1.0 : 0.0;
        stress(p, d, e) = 0.0;
      }
    }
    volume(p) = initial_volume(p) = grid.cellVolume() * share;
    mass(p) = solid.density * volume(p);
    state(p) = MaterialState{};
    material(p) = seed.material;
    id(p) = seed.id;
  }
  Kokkos::deep_copy(particles.position, position);
  Kokkos::deep_copy(particles.velocity, velocity);
  Kokkos::deep_copy(particles.mass, mass);
  Kokkos::deep_copy(particles.volume, volume);
  Kokkos::deep_copy(particles.initial_volume, initial_volume);
  Kokkos::deep_copy(particles.deformation_gradient, F);
  Kokkos::deep_copy(particles.stress, stress);
  Kokkos::deep_copy(particles.state, state);
  Kokkos::deep_copy(particles.material, material);
  Kokkos::deep_copy(particles.half_width, half_width);
  Kokkos::deep_copy(particles.id, id);
  return particles;
}

template struct Particles<2>;
template struct Particles<3>;
template Particles<2> seedParticles(const Scene&, const Layout<2>&, const std::vector<SolidMaterial>&);
template Particles<3> seedParticles(const Scene&, const Layout<3>&, const std::vector<SolidMaterial>&);

}  // namespace cfdmpm::mpm
