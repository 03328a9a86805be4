#pragma once
// Dry MPM test scenes built in code (no YAML): a domain, an air background that MPM ignores, solid
// materials with the keys of doc/input.md, boxes, and boundary faces.
#include "grid/decomposition.hpp"
#include "grid/layout.hpp"
#include "input/scene.hpp"

#include <Teuchos_Array.hpp>
#include <Tpetra_Core.hpp>

#include <array>
#include <memory>
#include <string>

namespace cfdmpm::mpm::scenes {

template <int Dim>
Scene dryScene(const std::array<double, 3>& lower, const std::array<double, 3>& upper,
               const std::array<long long, 3>& cells, const std::array<long long, 3>& patch_cells,
               const std::array<double, 3>& gravity)
{
  Scene scene;
  scene.title = "dry MPM test";
  scene.domain.dimension = Dim;
  scene.domain.lower = lower;
  scene.domain.upper = upper;
  scene.domain.cells = cells;
  scene.domain.patch_cells = patch_cells;
  scene.domain.gravity = gravity;
  scene.domain.ghost_width = 1;
  Teuchos::ParameterList air;
  air.set("kind", std::string("fluid"));
  scene.materials.push_back(MaterialSpec{"air", "fluid", air});
  scene.initial.background_material = "air";
  for (const std::string& face : boundaryFaces(Dim)) scene.boundaries.push_back(BoundarySpec{face, "free_slip", "zero_gradient", 0});
  return scene;
}

inline void addLinearElastic(Scene& scene, const std::string& name, double density, double youngs_modulus,
                             double poisson_ratio, int particles_per_cell)
{
  Teuchos::ParameterList list;
  list.set("kind", std::string("solid"));
  list.set("density", density);
  list.set("particles_per_cell", particles_per_cell);
  Teuchos::ParameterList& model = list.sublist("model");
  model.set("type", std::string("linear_elastic"));
  model.set("youngs_modulus", youngs_modulus);
  model.set("poisson_ratio", poisson_ratio);
  scene.materials.push_back(MaterialSpec{name, "solid", list});
}

/// A rigid body in a 2-D scene (2 particles per cell and direction), at rest unless given its
/// prescribed velocity.
inline void addRigid(Scene& scene, const std::string& name, double density,
                     const std::array<double, 2>& velocity = {0.0, 0.0})
{
  Teuchos::ParameterList list;
  list.set("kind", std::string("solid"));
  list.set("density", density);
  list.set("particles_per_cell", 2);
  Teuchos::ParameterList& model = list.sublist("model");
  model.set("type", std::string("rigid"));
  model.set("velocity", Teuchos::Array<double>(velocity.begin(), velocity.end()));
  scene.materials.push_back(MaterialSpec{name, "solid", list});
}

inline void addNeoHookean(Scene& scene, const std::string& name, double density, double bulk_modulus,
                          double shear_modulus, int particles_per_cell)
{
  Teuchos::ParameterList list;
  list.set("kind", std::string("solid"));
  list.set("density", density);
  list.set("particles_per_cell", particles_per_cell);
  Teuchos::ParameterList& model = list.sublist("model");
  model.set("type", std::string("neo_hookean"));
  model.set("bulk_modulus", bulk_modulus);
  model.set("shear_modulus", shear_modulus);
  scene.materials.push_back(MaterialSpec{name, "solid", list});
}

inline void addBox(Scene& scene, const std::string& material, const std::array<double, 3>& lower,
                   const std::array<double, 3>& upper, const std::array<double, 3>& velocity = {0, 0, 0})
{
  RegionSpec region;
  region.name = material + "_box_" + std::to_string(scene.regions.size());
  region.material = material;
  region.shape = "box";
  region.lower = lower;
  region.upper = upper;
  region.velocity = velocity;
  region.temperature = 293.15;
  scene.regions.push_back(region);
}

inline void setWall(Scene& scene, const std::string& face, const std::string& velocity)
{
  for (BoundarySpec& b : scene.boundaries)
    if (b.face == face) b.velocity = velocity;
}

template <int Dim>
std::shared_ptr<const Layout<Dim>> layoutFor(const Scene& scene, Teuchos::RCP<const Teuchos::Comm<int>> comm)
{
  const Grid<Dim> grid(scene.domain);
  return std::make_shared<const Layout<Dim>>(grid, partitionPatches(grid, comm->getSize()), scene.domain.ghost_width,
                                             comm);
}

}  // namespace cfdmpm::mpm::scenes
