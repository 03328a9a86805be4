// The valid-parameter lists of a scene: every key with its type, default, rule and meaning.
// readScene validates against them and doc/input.md is generated from them (writeSceneReference).
#include "input/parameter_rule.hpp"
#include "input/scene.hpp"

#include <Teuchos_Array.hpp>
#include <Teuchos_Tuple.hpp>
#include <Teuchos_TwoDArray.hpp>

#include <map>
#include <stdexcept>

namespace cfdmpm {

namespace {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::RCP;

// --- Building blocks for rules: read as "required(perDirection(atLeast(1)))". ---
ParameterRule unit(std::string si_unit)
{
  ParameterRule rule;
  rule.unit = std::move(si_unit);
  return rule;
}

ParameterRule between(double min, bool min_open, double max, bool max_open, std::string si_unit = "")
{
  ParameterRule rule = unit(std::move(si_unit));
  rule.min = min;
  rule.min_open = min_open;
  rule.max = max;
  rule.max_open = max_open;
  return rule;
}

ParameterRule greaterThan(double min, std::string si_unit = "")
{
  ParameterRule rule = unit(std::move(si_unit));
  rule.min = min;
  rule.min_open = true;
  return rule;
}

ParameterRule positive(std::string si_unit = "") { return greaterThan(0, std::move(si_unit)); }

ParameterRule atLeast(double min, std::string si_unit = "")
{
  ParameterRule rule = unit(std::move(si_unit));
  rule.min = min;
  return rule;
}

ParameterRule oneOf(const std::vector<std::string>& choices)
{
  ParameterRule rule;
  rule.choices = choices;
  return rule;
}

ParameterRule required(ParameterRule rule)
{
  rule.required = true;
  return rule;
}

ParameterRule perDirection(ParameterRule rule)
{
  rule.per_direction = true;
  return rule;
}

ParameterRule derivedDefault(ParameterRule rule, std::string text)
{
  rule.derived_default = std::move(text);
  return rule;
}

template <class T>
void define(ParameterList& list, const std::string& key, const T& value, const std::string& doc,
            ParameterRule rule)
{
  list.set(key, value, doc, Teuchos::rcp(new ParameterRuleValidator(std::move(rule), typeid(T))));
}

// A sublist. Free-form sections are not recursed into by Teuchos: readScene checks their entries
// against a template chosen by a selector key, or leaves them to the module that owns them.
ParameterList& defineSection(ParameterList& list, const std::string& key, const std::string& doc,
                             bool is_required, bool free_form)
{
  ParameterList& section = list.sublist(key, false, doc);
  if (free_form) section.disableRecursiveValidation();
  ParameterRule rule;
  rule.required = is_required;
  list.getEntryPtr(key)->setValidator(
      Teuchos::rcp(new ParameterRuleValidator(rule, typeid(ParameterList))));
  return section;
}

Array<double> zeros(int n) { return Array<double>(n, 0.0); }

// --- The fixed sections. ---

void defineDomain(ParameterList& domain)
{
  define(domain, "dimension", 2, "Number of space dimensions; every per-direction list has this many entries.",
         required(between(2, false, 3, false)));
  define(domain, "lower", zeros(2), "Lower corner of the domain (x, y[, z]).", required(perDirection(unit("m"))));
  define(domain, "upper", zeros(2), "Upper corner of the domain; above `lower` in every direction.",
         required(perDirection(unit("m"))));
  // `cells` and `cell_size`: exactly one of the two is given (readDomain checks it, and derives
  // `cells` from `cell_size`).
  define(domain, "cells", Array<int>(2, 1),
         "Number of cells per direction. Give exactly one of `cells` and `cell_size`.",
         derivedDefault(perDirection(atLeast(1)), "required unless `cell_size` is given"));
  define(domain, "cell_size", 0.01,
         "Edge length of the cells, the same in every direction: `cells` is then (upper - lower) / cell_size, "
         "which must be a whole number in every direction. Give exactly one of `cells` and `cell_size`.",
         derivedDefault(positive("m"), "required unless `cells` is given"));
  define(domain, "patch_cells", Array<int>(2, 16),
         "Patch size in cells per direction; patches are the units of the domain decomposition. Values above "
         "`cells` are clipped to it.",
         derivedDefault(perDirection(atLeast(1)), "16 per direction, clipped to `cells`"));
  define(domain, "ghost_width", 2, "Layers of ghost cells around each rank's cells.", atLeast(1));
  define(domain, "gravity", zeros(2), "Gravitational acceleration, e.g. [0, -9.81] in 2-D with y up.",
         required(perDirection(unit("m/s^2"))));
  define(domain, "rebalance_interval", 0,
         "Every this many steps (from step 0) the patches are divided among the ranks again with METIS so that "
         "the cells' work and the particles' work are each balanced, and the run moves to the new division when "
         "that lowers the estimated imbalance by more than 2 % of the mean load (doc/scaling.md). 0: never; the "
         "division by cell counts of the start is kept.",
         atLeast(0));
}

void defineInitialState(ParameterList& initial)
{
  define(initial, "background_material", std::string("air"),
         "The fluid material that fills every cell no region claims.", required(ParameterRule{}));
  define(initial, "temperature", 293.15, "Temperature of the background, and of regions that give none.",
         positive("K"));
  define(initial, "pressure", 101325.0, "Pressure at the top of the domain.", positive("Pa"));
  define(initial, "hydrostatic", true,
         "true: integrate the pressure down from the top with the weight of the column above; false: uniform "
         "`pressure`.",
         ParameterRule{});
}

void defineTime(ParameterList& time)
{
  define(time, "end_time", 1.0, "Simulated time at which the run stops.", required(positive("s")));
  define(time, "cfl", 0.25, "Courant number that sets the time step.", between(0, true, 1, false));
  define(time, "dt_initial", 1.0e-5, "First time step; between `dt_min` and `dt_max`.", positive("s"));
  define(time, "dt_min", 1.0e-10, "Smallest time step; the run stops with an error if it needs a smaller one.",
         atLeast(0, "s"));
  define(time, "dt_max", 1.0e-2, "Largest time step.", positive("s"));
  define(time, "max_steps", -1LL, "Stop after this many steps; -1: no limit.", atLeast(-1));
  define(time, "step_retries", 3,
         "How often a failed step (values not finite, a pressure solve or outer iteration that does not converge, "
         "an outflux larger than a cell, an inverted particle) is undone and retried with half its time step "
         "before the run stops (doc/input.md, \"A failed step\").",
         between(0, false, 50, false));
}

void defineOutput(ParameterList& output)
{
  define(output, "directory", std::string("output"),
         "Directory the results are written to; an existing one is refused unless `overwrite` is true.",
         required(ParameterRule{}));
  define(output, "interval", 0.01, "Simulated time between output steps; 0: the initial state only.",
         required(atLeast(0, "s")));
  define(output, "fields",
         Array<std::string>(Teuchos::tuple<std::string>("volume_fraction", "density", "velocity", "temperature", "pressure")),
         "Fields written at each output step; cell fields per material, particle fields per particle.",
         oneOf(outputFieldNames()));
  define(output, "overwrite", false, "true: write into an existing `directory`, replacing its files.",
         ParameterRule{});
  define(output, "progress_interval", 1.0, "Wall-clock time between progress lines; 0: one line per step.",
         atLeast(0, "s"));
  define(output, "checkpoint_interval", 0.0,
         "Simulated time between checkpoints (the complete state, for `cfdmpm --restart`; doc/output.md); "
         "0: none by simulated time.",
         atLeast(0, "s"));
  define(output, "checkpoint_wall_interval", 0.0,
         "Wall-clock time between checkpoints; 0: none by wall-clock time. With either interval set, a run "
         "also writes a checkpoint when it stops.",
         atLeast(0, "s"));
  define(output, "checkpoints_kept", 2, "How many of the newest checkpoints are kept; older ones are removed.",
         atLeast(1));
}

void defineMpm(ParameterList& mpm)
{
  define(mpm, "shape_function", std::string("gimp"),
         "Particle-grid weights: `gimp` (uGIMP, no cell-crossing noise) or `linear` (hat functions, for comparison).",
         oneOf({"gimp", "linear"}));
  define(mpm, "flip_fraction", 0.99,
         "FLIP share of the particle velocity update (1: pure FLIP, 0: pure PIC, which damps strongly).",
         between(0, false, 1, false));
  define(mpm, "stress_update", std::string("usl"),
         "Where the strain rate comes from: `usl` (updated grid velocity, as Uintah) or `musl` (particle "
         "momenta mapped back to the grid: no systematic energy loss, ~1.45x the step cost; not yet right "
         "with contact between materials).",
         oneOf({"usl", "musl"}));
  define(mpm, "wall_friction", 0.0,
         "Coulomb friction coefficient between particles and the `free_slip` walls (`no_slip` walls stick).",
         atLeast(0, ""));
  define(mpm, "contact", true,
         "true: Coulomb friction contact with free separation between solid materials; false: each material "
         "moves through the others.",
         ParameterRule{});
  define(mpm, "contact_friction", 0.0, "Coulomb friction coefficient between solid materials.", atLeast(0, ""));
  define(mpm, "velocity_damping", 0.0,
         "Mass-proportional damping of the node velocities, to reach a static state; 0 for dynamics.",
         atLeast(0, "1/s"));
  define(mpm, "face_layer", 0.125,
         "Width, in cells, of the layers on either side of a cell face in which a solid's cover of the face is "
         "measured for the coupled pressure equation (doc/mpmice.md, \"A solid's share of a face\"): thin "
         "layers move the solid across a face only once it is there (fewer pressure jumps ahead of a sliding "
         "front; input/rzadkiewicz.yaml uses 1/128), h/8 suits a light body's added mass.",
         between(0, true, 0.5, false));
  define(mpm, "coupling", std::string("monolithic"),
         "How the solids meet the fluids' pressure: `monolithic` (their response to it is in the pressure "
         "equation) or `staggered` (their motion over a step is fixed before the pressure, which acts on them "
         "the next step: for comparison only, unstable for solids lighter than the fluid; doc/stability.md, "
         "case b).",
         oneOf({"monolithic", "staggered"}));
  define(mpm, "solid_volume", std::string("faces"),
         "How the monolithic pressure equation counts the solids' change of volume in a cell: `faces` (each "
         "solid's face velocities times its share of the faces) or `particles` (before every pressure "
         "correction the particles are moved, on a copy, with the velocity change the present pressure gives "
         "them, and their boxes measured: the volume the next step will find; pressure jumps 10-70x smaller on "
         "the seed scene, at 2x the step's cost at 20 mm and ~5x at 10 mm; doc/mpmice.md, \"The solids' volume "
         "from their particles\").",
         oneOf({"faces", "particles"}));
  define(mpm, "substeps", 1,
         "Most particle steps in one step of the fluids, in a scene with both. 1: one step for both, as long as "
         "the shorter of the fluids' and the particles' stable steps. N > 1: the fluids' step may be up to N "
         "particle steps long; the particles take as many steps of their own as their elastic wave needs inside "
         "it, with the fluids' force on them (pressure and exchange) spread evenly over those steps, and the "
         "fluids see the solids' velocity forecast from each particle's own acceleration of the last step; not "
         "with `solid_volume: particles` or `coupling: staggered` (doc/mpmice.md, \"Particle steps inside a "
         "fluid step\").",
         atLeast(1));
}

void defineIce(ParameterList& ice)
{
  define(ice, "enabled", true,
         "false: the fluids stay as they are, an inert background, and the solids run alone (a dry scene).",
         ParameterRule{});
  define(ice, "isothermal", true,
         "false: solve the energy equation (pressure work, conduction, heat exchange, advection of T). Fluids "
         "only: a scene with a solid material is refused with false (the coupled step does not carry the "
         "solids' temperature yet).",
         ParameterRule{});
  define(ice, "heat_exchange_coefficient", 0.0, "Heat exchange H between every pair of materials.",
         atLeast(0, "W/(m^3 K)"));
  define(ice, "pressure", std::string("implicit"), "Pressure scheme; `explicit` is for comparison only.",
         oneOf({"implicit", "explicit"}));
  define(ice, "exchange_coefficient", 1.0e15,
         "Momentum exchange K between every pair of materials (between a solid and a fluid: "
         "`solid_exchange_coefficient`). 0 leaves a trace of one fluid in the cells of another free of it: "
         "air in water's cells then accelerates at its own v ∇p.",
         atLeast(0, "kg/(m^3 s)"));
  define(ice, "solid_exchange_coefficient", 1.0e15,
         "Momentum exchange K between a solid and a fluid, in the cells and on the faces they share (two "
         "solids: none; MPM's contact acts between them). 0: the fluids slip along the solids, which the "
         "pressure alone moves (potential flow's added mass), while the fluids stay tied to each other by "
         "`exchange_coefficient`; a fluid alone with a solid in a cell (the air in a floating body's cells "
         "above the water) is then held by nothing and may race (doc/mpmice.md, \"Exchange\").",
         derivedDefault(atLeast(0, "kg/(m^3 s)"), "`exchange_coefficient`'s value"));
  define(ice, "max_outer_iterations", 20, "Outer iterations of the pressure equation per step at most.", atLeast(1));
  define(ice, "outer_tolerance", 1.0e-8,
         "The outer iterations stop once max |rhs| / V of the pressure equation is below this: the volume "
         "mismatch of a cell in one step, as a fraction of its volume, weighed in a cell softer than the "
         "stiffest fluid by how much softer it is and in a cell lighter than it by how much lighter, so that it "
         "bounds the pressure error by this over the stiffest fluid's compressibility (in water 1e-8 is ~20 Pa), "
         "and in a lighter cell by that times its density over the stiffest fluid's: the velocity error the "
         "pressure error leaves is bounded alike in every cell (doc/ice.md).",
         positive(""));
  define(ice, "solver_tolerance", 0.0,
         "Relative residual (2-norm) of each linear pressure solve. 0: each solve stops once every cell's "
         "residual, weighed as the outer test weighs it, is below 0.5 `outer_tolerance` V (doc/ice-pressure.md), "
         "or at 1e-10 of the largest weighted entry of the right-hand side if that comes first.",
         between(0, false, 1e-2, true));
  define(ice, "dt_growth", 1.2, "Largest ratio of successive time steps.", greaterThan(1));
  define(ice, "odd_even_filter", 0.0,
         "Share of the fluids' odd-even velocity mode (alternating from cell to cell, which a collocated "
         "pressure cannot see) that a momentum-conserving filter removes per step in each direction where the "
         "velocity zigzags (doc/mpmice.md); 0: off. input/rzadkiewicz.yaml uses 0.25.",
         between(0, false, 1, false));
  defineSection(ice, "linear_solver",
                "Settings of the pressure solver (preconditioner, MueLu reuse, ...), checked by it; keys given "
                "replace cfdmpm's defaults one by one (doc/ice-pressure.md).",
                false, true);
}

RCP<ParameterList> buildSceneParameters()
{
  auto scene = Teuchos::rcp(new ParameterList("cfdmpm"));
  define(*scene, "title", std::string(""), "A line describing the scene, copied into the output.",
         ParameterRule{});
  defineDomain(defineSection(*scene, "domain", "The box the grid covers and its cells.", true, false));
  defineSection(*scene, "materials",
                "Named materials; the order is the material index. Keys of each entry: see the templates for "
                "`kind: fluid` and `kind: solid`.",
                true, true);
  defineInitialState(defineSection(*scene, "initial_state", "What fills the domain at t = 0.", true, false));
  defineSection(*scene, "regions",
                "Named regions that place materials; later regions overwrite earlier ones. Keys of each entry: "
                "see the templates for each `shape`.",
                false, true);
  defineSection(*scene, "boundary_conditions",
                "One entry per face of the domain (x-, x+, y-, y+, and z-, z+ in 3-D); faces not given are "
                "no_slip / zero_gradient.",
                false, true);
  defineTime(defineSection(*scene, "time", "Time span and time-step control.", true, false));
  defineOutput(defineSection(*scene, "output", "What is written, where and how often.", true, false));
  defineIce(defineSection(*scene, "ice", "Settings of the fluid (ICE) solver.", false, false));
  defineMpm(defineSection(*scene, "mpm", "Settings of the particle (MPM) solver.", false, false));
  return scene;
}

// --- The templates of named entries. ---

RCP<ParameterList> buildMaterial(const std::string& kind)
{
  auto material = Teuchos::rcp(new ParameterList("material"));
  define(*material, "kind", kind, "fluid: moved by the ICE solver; solid: carried by MPM particles.",
         required(oneOf(materialKinds())));
  if (kind == "fluid") {
    defineSection(*material, "equation_of_state",
                  "Relation of pressure, density and temperature; keys depend on its `type`.", true, true);
    define(*material, "viscosity", 0.0, "Dynamic viscosity.", required(atLeast(0, "Pa s")));
    define(*material, "specific_heat", 1.0, "Specific heat at constant volume.",
           derivedDefault(positive("J/(kg K)"),
                          "gas_constant / (gamma - 1) for `ideal_gas`; required for other equations of state"));
    define(*material, "thermal_conductivity", 0.0, "Thermal conductivity.", atLeast(0, "W/(m K)"));
  } else {
    define(*material, "density", 1000.0, "Density of the solid at rest.", required(positive("kg/m^3")));
    defineSection(*material, "model", "Constitutive model; keys depend on its `type`.", true, true);
    define(*material, "particles_per_cell", 2, "Material points per cell in each direction.", atLeast(1));
    define(*material, "interior_pressure", std::string("cell"),
           "The pressure that acts on the solid, and on the fluid beside it, in the cells it fills (the fluids "
           "below 5-15 % of the fluid and solid volume): `cell`, the cell's own (the pressure the coupled pressure "
           "equation solved for, with the solid's motion in it: a body lighter than the fluid moves mostly by "
           "it), or `reference`, the still fluid's hydrostatic pressure, moved with the fluids' pressure where it "
           "changes everywhere alike (its gradient is the buoyancy), for a "
           "body whose particles shear off their lattice or that turns (a floating or tumbling block), so that "
           "their boxes cover a cell only to 1-4 % and the bulk modulus turns that into pressure (doc/mpmice.md, "
           "\"The pressure that acts where a solid fills the cell\", \"A body that turns\"). Not used by a rigid body; with `mpm.coupling: staggered` every deformable solid takes "
           "`reference` (that pressure equation holds no response of the solids).",
           derivedDefault(oneOf({"cell", "reference"}),
                          "`reference` for the plastic models (tresca, drucker_prager), `cell` for the elastic ones"));
  }
  return material;
}

RCP<ParameterList> buildEquationOfState(const std::string& type)
{
  auto eos = Teuchos::rcp(new ParameterList("equation_of_state"));
  define(*eos, "type", type,
         "linear_water: p - p0 = (K / rho0) ((rho - rho0) + beta (T - T0)) (seed paper eq. 5, beta the density "
         "drop per kelvin); ideal_gas: p = rho R T; tait: p = p0 + (K / n) ((rho / rho0)^n - 1).",
         required(oneOf(equationOfStateTypes())));
  if (type == "linear_water") {
    define(*eos, "bulk_modulus", 2.15e9, "Bulk modulus K.", required(positive("Pa")));
    define(*eos, "reference_density", 999.8, "Density at the reference pressure and temperature.",
           required(positive("kg/m^3")));
    define(*eos, "reference_pressure", 101325.0, "Reference pressure.", positive("Pa"));
    define(*eos, "reference_temperature", 293.15, "Reference temperature.", positive("K"));
    define(*eos, "thermal_expansion", 0.0,
           "beta: the drop of density per kelvin at constant pressure; positive for water above 4 C (seed paper: "
           "0.18).",
           unit("kg/(m^3 K)"));
    define(*eos, "cavitation_pressure", 0.0,
           "p_c: below it the water boils instead of stretching (p = p_c rho / rho_c below the liquid's density "
           "rho_c at p_c; the vapour pressure, 872 Pa at 5 C, 2339 Pa at 20 C). 0: no cavitation, the water holds "
           "any tension.",
           atLeast(0, "Pa"));
  } else if (type == "ideal_gas") {
    define(*eos, "gas_constant", 287.0, "Specific gas constant R.", positive("J/(kg K)"));
    define(*eos, "gamma", 1.4, "Ratio of specific heats.", greaterThan(1));
  } else {
    define(*eos, "reference_density", 999.8, "Density at the reference pressure.", required(positive("kg/m^3")));
    define(*eos, "reference_pressure", 101325.0, "Reference pressure p0.", positive("Pa"));
    define(*eos, "bulk_modulus", 2.15e9, "Bulk modulus K at the reference density.", required(positive("Pa")));
    define(*eos, "exponent", 7.0, "Exponent n.", positive());
  }
  return eos;
}

RCP<ParameterList> buildSolidModel(const std::string& type)
{
  auto model = Teuchos::rcp(new ParameterList("model"));
  define(*model, "type", type,
         "linear_elastic (small strain); neo_hookean (hyperelastic); tresca (elastic-perfectly plastic, no plastic "
         "volume change); drucker_prager (pressure-dependent plasticity); rigid (moves at a set velocity).",
         required(oneOf(solidModelTypes())));
  auto elasticity = [&]() {
    define(*model, "youngs_modulus", 1.0e7, "Young's modulus E.", required(positive("Pa")));
    define(*model, "poisson_ratio", 0.3, "Poisson's ratio.", required(between(-1, true, 0.5, true)));
  };
  if (type == "linear_elastic") {
    elasticity();
  } else if (type == "neo_hookean") {
    define(*model, "bulk_modulus", 1.0e9, "Bulk modulus K.", required(positive("Pa")));
    define(*model, "shear_modulus", 1.0e9, "Shear modulus G.", required(positive("Pa")));
  } else if (type == "tresca") {
    elasticity();
    define(*model, "yield_stress", 200.0,
           "Maximum shear stress at yield (undrained shear strength c; the seed paper's 200 Pa). A uniaxial "
           "yield stress sigma_y corresponds to sigma_y / 2.",
           required(positive("Pa")));
  } else if (type == "drucker_prager") {
    elasticity();
    define(*model, "friction_angle", 30.0, "Internal friction angle.",
           required(between(0, false, 90, true, "degree")));
    define(*model, "cohesion", 0.0, "Cohesion c; above 0 when `friction_angle` is 0.", atLeast(0, "Pa"));
    define(*model, "dilatancy_angle", 0.0, "Dilatancy angle; at most `friction_angle`.",
           between(0, false, 90, true, "degree"));
    define(*model, "fit", std::string("plane_strain"),
           "How the cone is fitted to Mohr-Coulomb: plane_strain (exact in plane strain, for 2-D), outer_cone "
           "(through triaxial compression), inner_cone (through triaxial extension).",
           oneOf({"plane_strain", "outer_cone", "inner_cone"}));
  } else {
    define(*model, "velocity", zeros(2), "Velocity of the rigid body.",
           derivedDefault(perDirection(unit("m/s")), "zero"));
  }
  return model;
}

RCP<ParameterList> buildRegion(const std::string& shape)
{
  auto region = Teuchos::rcp(new ParameterList("region"));
  define(*region, "material", std::string("water"), "The material the region holds.", required(ParameterRule{}));
  define(*region, "shape", shape,
         "box: between two corners; polygon: inside a closed polygon in the x-y plane (extruded over z in 3-D); "
         "half_plane: the side of a plane opposite to its normal.",
         required(oneOf(regionShapes())));
  if (shape == "box") {
    define(*region, "lower", zeros(2), "Lower corner; inside the domain.", required(perDirection(unit("m"))));
    define(*region, "upper", zeros(2), "Upper corner; inside the domain and above `lower`.",
           required(perDirection(unit("m"))));
  } else if (shape == "polygon") {
    define(*region, "vertices", Teuchos::TwoDArray<double>(3, 2, 0.0),
           "Corners [x, y] in order (either sense), at least 3, inside the domain; the polygon closes itself.",
           required(unit("m")));
  } else {
    define(*region, "point", zeros(2), "A point on the plane.", required(perDirection(unit("m"))));
    define(*region, "normal", zeros(2),
           "Normal of the plane (any length, not zero); the region is the side it points away from.",
           required(perDirection(ParameterRule{})));
  }
  define(*region, "velocity", zeros(2), "Initial velocity.", derivedDefault(perDirection(unit("m/s")), "zero"));
  define(*region, "temperature", 293.15, "Initial temperature.",
         derivedDefault(positive("K"), "`initial_state.temperature`"));
  return region;
}

RCP<ParameterList> buildBoundary()
{
  auto face = Teuchos::rcp(new ParameterList("face"));
  define(*face, "velocity", std::string("no_slip"),
         "no_slip: every velocity component is zero on the face; free_slip: only the normal one.",
         oneOf({"no_slip", "free_slip"}));
  define(*face, "temperature", std::string("zero_gradient"),
         "zero_gradient: no heat flux through the face; fixed: the face is held at `temperature_value`.",
         oneOf({"zero_gradient", "fixed"}));
  define(*face, "temperature_value", 293.15, "Face temperature when `temperature` is fixed.",
         derivedDefault(positive("K"), "`initial_state.temperature`"));
  return face;
}

// One template per name, built once.
RCP<const ParameterList> lookUp(const std::map<std::string, RCP<const ParameterList>>& templates,
                                const std::string& name, const std::string& what)
{
  auto found = templates.find(name);
  if (found == templates.end()) throw std::invalid_argument("no " + what + " named '" + name + "'");
  return found->second;
}

template <class Build>
std::map<std::string, RCP<const ParameterList>> buildAll(const std::vector<std::string>& names, Build build)
{
  std::map<std::string, RCP<const ParameterList>> templates;
  for (const auto& name : names) templates[name] = build(name);
  return templates;
}

}  // namespace

const std::vector<std::string>& materialKinds()
{
  static const std::vector<std::string> names{"fluid", "solid"};
  return names;
}

const std::vector<std::string>& equationOfStateTypes()
{
  static const std::vector<std::string> names{"linear_water", "ideal_gas", "tait"};
  return names;
}

const std::vector<std::string>& solidModelTypes()
{
  static const std::vector<std::string> names{"linear_elastic", "neo_hookean", "tresca", "drucker_prager", "rigid"};
  return names;
}

const std::vector<std::string>& regionShapes()
{
  static const std::vector<std::string> names{"box", "polygon", "half_plane"};
  return names;
}

const std::vector<std::string>& outputFieldNames()
{
  static const std::vector<std::string> names{
      "volume_fraction", "density", "velocity", "temperature", "pressure", "specific_volume",
      "particle_velocity", "particle_stress", "plastic_strain", "particle_volume", "particle_material"};
  return names;
}

std::vector<std::string> boundaryFaces(int dimension)
{
  std::vector<std::string> faces{"x-", "x+", "y-", "y+"};
  if (dimension == 3) {
    faces.push_back("z-");
    faces.push_back("z+");
  }
  return faces;
}

Teuchos::RCP<const Teuchos::ParameterList> validSceneParameters()
{
  static const RCP<const ParameterList> scene = buildSceneParameters();
  return scene;
}

Teuchos::RCP<const Teuchos::ParameterList> validMaterialParameters(const std::string& kind)
{
  static const auto templates = buildAll(materialKinds(), buildMaterial);
  return lookUp(templates, kind, "material kind");
}

Teuchos::RCP<const Teuchos::ParameterList> validEquationOfStateParameters(const std::string& type)
{
  static const auto templates = buildAll(equationOfStateTypes(), buildEquationOfState);
  return lookUp(templates, type, "equation of state type");
}

Teuchos::RCP<const Teuchos::ParameterList> validSolidModelParameters(const std::string& type)
{
  static const auto templates = buildAll(solidModelTypes(), buildSolidModel);
  return lookUp(templates, type, "solid model type");
}

Teuchos::RCP<const Teuchos::ParameterList> validRegionParameters(const std::string& shape)
{
  static const auto templates = buildAll(regionShapes(), buildRegion);
  return lookUp(templates, shape, "region shape");
}

Teuchos::RCP<const Teuchos::ParameterList> validBoundaryParameters()
{
  static const RCP<const ParameterList> face = buildBoundary();
  return face;
}

}  // namespace cfdmpm
