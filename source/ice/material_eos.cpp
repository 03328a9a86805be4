#include "ice/material_eos.hpp"

#include "input/parameter_rule.hpp"

namespace cfdmpm {

ice::Eos fluidEos(const MaterialSpec& material)
{
  const Teuchos::ParameterList& eos = material.parameters.sublist("equation_of_state");
  const std::string type = eos.get<std::string>("type");
  if (type == "ideal_gas")
    return ice::Eos(ice::IdealGas::fromGasConstant(eos.get<double>("gas_constant"), eos.get<double>("gamma")));
  if (type == "linear_water") {
    // The input's thermal_expansion is the drop of density per kelvin (positive for water above
    // 4 degC); eq. 5's beta enters with the opposite sign, hence the minus.
    const ice::LinearWater water = ice::LinearWater::fromBulkModulus(
        eos.get<double>("bulk_modulus"), eos.get<double>("reference_pressure"), eos.get<double>("reference_density"),
        eos.get<double>("reference_temperature"), -eos.get<double>("thermal_expansion"));
    const double p_c = eos.get<double>("cavitation_pressure");
    if (p_c == 0.0) return ice::Eos(water);
    const std::string key = "cfdmpm.materials." + material.name + ".equation_of_state.cavitation_pressure";
    if (!(p_c < water.reference_pressure))
      throw InputError(key + ": got " + showNumber(p_c) + " Pa; must be below reference_pressure (" +
                       showNumber(water.reference_pressure) + " Pa), or 0 for no cavitation");
    if (!(water.density(p_c, water.reference_temperature) > 0))
      throw InputError(key + ": got " + showNumber(p_c) +
                       " Pa, where the linear law gives the liquid no positive density; must be higher, or 0");
    return ice::Eos(water.withCavitation(p_c));
  }
  if (type == "tait") {
    const double rho0 = eos.get<double>("reference_density");
    return ice::Eos(ice::Tait(rho0, std::sqrt(eos.get<double>("bulk_modulus") / rho0), eos.get<double>("exponent"),
                    eos.get<double>("reference_pressure")));
  }
  throw InputError("materials." + material.name + ".equation_of_state.type: got '" + type +
                   "'; allowed: linear_water, ideal_gas, tait");
}

}  // namespace cfdmpm
