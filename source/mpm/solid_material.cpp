#include "mpm/solid_material.hpp"

#include <Teuchos_Array.hpp>

namespace cfdmpm::mpm {

namespace {

double number(const Teuchos::ParameterList& list, const std::string& key, const std::string& path)
{
  if (!list.isParameter(key)) throw InputError(path + "." + key + ": required key is missing");
  if (list.isType<int>(key)) return double(list.get<int>(key));
  return list.get<double>(key);
}

ElasticModuli youngPoisson(const Teuchos::ParameterList& model, const std::string& path)
{
  return ElasticModuli::fromYoungPoisson(number(model, "youngs_modulus", path), number(model, "poisson_ratio", path));
}

}  // namespace

SolidModel solidModelFromParameters(const Teuchos::ParameterList& model, const std::string& material_name)
{
  const std::string path = "cfdmpm.materials." + material_name + ".model";
  const std::string type = model.get<std::string>("type");
  try {
    if (type == "linear_elastic") return LinearElastic(LinearElasticParameters{youngPoisson(model, path)});
    if (type == "neo_hookean")
      return NeoHookean(NeoHookeanParameters{ElasticModuli::fromBulkShear(number(model, "bulk_modulus", path),
                                                                          number(model, "shear_modulus", path))});
    if (type == "tresca") return Tresca(TrescaParameters{youngPoisson(model, path), number(model, "yield_stress", path)});
    if (type == "drucker_prager") {
      DruckerPragerParameters p;
      p.elastic = youngPoisson(model, path);
      p.friction_angle_degrees = number(model, "friction_angle", path);
      p.cohesion = model.isParameter("cohesion") ? number(model, "cohesion", path) : 0.0;
      p.dilatancy_angle_degrees = model.isParameter("dilatancy_angle") ? number(model, "dilatancy_angle", path) : 0.0;
      const std::string fit = model.isParameter("fit") ? model.get<std::string>("fit") : "plane_strain";
      p.fit = fit == "outer_cone"   ? DruckerPragerFit::OuterCone
              : fit == "inner_cone" ? DruckerPragerFit::InnerCone
                                    : DruckerPragerFit::PlaneStrain;
      return DruckerPrager(p);
    }
    if (type == "rigid") {
      RigidParameters p;
      if (model.isParameter("velocity")) {
        const auto& v = model.get<Teuchos::Array<double>>("velocity");
        for (int d = 0; d < int(v.size()) && d < 3; ++d) p.velocity[d] = v[d];
      }
      return Rigid(p);
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(path + ": " + e.what());
  }
  throw inputError(path + ".type", type, "allowed: linear_elastic, neo_hookean, tresca, drucker_prager, rigid");
}

std::vector<SolidMaterial> solidMaterials(const Scene& scene)
{
  std::vector<SolidMaterial> solids;
  for (int i = 0; i < int(scene.materials.size()); ++i) {
    const MaterialSpec& spec = scene.materials[i];
    if (spec.kind != "solid") continue;
    const std::string path = "cfdmpm.materials." + spec.name;
    const double density = number(spec.parameters, "density", path);
    if (!(density > 0)) throw inputError(path + ".density", std::to_string(density), "must be > 0 (kg/m^3)");
    const int ppc = spec.parameters.isParameter("particles_per_cell") ? spec.parameters.get<int>("particles_per_cell") : 2;
    if (ppc < 1) throw inputError(path + ".particles_per_cell", std::to_string(ppc), "must be >= 1");
    if (!spec.parameters.isSublist("model")) throw InputError(path + ".model: required key is missing");
    const Teuchos::ParameterList& model = spec.parameters.sublist("model");
    SolidMaterial solid{spec.name, i, density, ppc, solidModelFromParameters(model, spec.name)};
    const std::string type = model.get<std::string>("type");
    solid.rigid = type == "rigid";
    const std::string interior = spec.parameters.isParameter("interior_pressure")
                                     ? spec.parameters.get<std::string>("interior_pressure")
                                     : defaultInteriorPressure(type);
    solid.reference_pressure_inside = !solid.rigid && interior == "reference";
    if (solid.rigid)
      solid.bulk_modulus = kRigidBulkModulus;
    else if (type == "neo_hookean")
      solid.bulk_modulus = number(model, "bulk_modulus", path + ".model");
    else
      solid.bulk_modulus = youngPoisson(model, path + ".model").bulk_modulus;
    solids.push_back(solid);
  }
  return solids;
}

}  // namespace cfdmpm::mpm
