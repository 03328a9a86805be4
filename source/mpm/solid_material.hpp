#pragma once
// The solid (MPM) materials of a scene: density, particles per cell and the constitutive model,
// read once from each `kind: solid` material's validated parameter list (doc/input.md).
#include "input/scene.hpp"
#include "mpm/constitutive/solid_model.hpp"

#include <string>
#include <vector>

namespace cfdmpm::mpm {

struct SolidMaterial {
  std::string name;
  int scene_index = 0;         ///< index of the material in Scene::materials (output, regions)
  double density = 0.0;        ///< kg/m^3 at rest
  int particles_per_cell = 2;  ///< material points per cell in each direction
  SolidModel model;            ///< constitutive model (a value type; no virtual calls)
  /// Bulk modulus K (Pa) of the material's equation of state in the coupled step's equilibration
  /// pressure and pressure equation: the model's elastic K, or kRigidBulkModulus for a rigid body.
  double bulk_modulus = 0.0;
  bool rigid = false;          ///< moves at a prescribed velocity (model type rigid)
  /// Where it fills a cell, the fluids' hydrostatic reference pressure acts on it instead of the
  /// cell's own (`interior_pressure: reference`).
  bool reference_pressure_inside = false;
};

/// The stiffness a rigid material is given in the coupled step's equilibration and pressure
/// equation (it has no elastic constants of its own). Stiffer than water (2.15e9 Pa), so the share
/// of a cut cell that the body fills barely changes with the pressure; a rigid body has no wave
/// speed, so this stiffness never limits the time step.
constexpr double kRigidBulkModulus = 1.0e10;

/// The constitutive model described by a material's `model` sublist (keys of doc/input.md).
SolidModel solidModelFromParameters(const Teuchos::ParameterList& model, const std::string& material_name);

/// The scene's solid materials in scene order; the position in the returned list is the MPM
/// material index that particles carry. Throws InputError naming the key for bad parameters.
std::vector<SolidMaterial> solidMaterials(const Scene& scene);

}  // namespace cfdmpm::mpm
