// readScene refuses bad scenes with an InputError whose message names the full key, the value
// given and what is allowed. One test per kind of mistake; each breaks one thing in kFullScene.
#include "scene_test_support.hpp"

namespace cfdmpm::test {
namespace {

// --- The file --------------------------------------------------------------------------------

TEST_F(SceneTest, MissingFileNamesPathAndReason)
{
  const std::string path = (directory_ / "no-such-scene.yaml").string();
  try {
    readScene(path);
    FAIL() << "readScene read a missing file";
  } catch (const InputError& error) {
    expectMentions(error.what(), {path, "No such file or directory"});
  }
}

TEST_F(SceneTest, DirectoryInsteadOfFileNamesPathAndReason)
{
  try {
    readScene(directory_.string());
    FAIL() << "readScene read a directory";
  } catch (const InputError& error) {
    expectMentions(error.what(), {directory_.string(), "Is a directory"});
  }
}

TEST_F(SceneTest, YamlSyntaxErrorKeepsLineAndColumn)
{
  // An unclosed flow list on line 10 of the file.
  const std::string message = errorOf(replaced(kFullScene, "cells: [20, 10]", "cells: [20, 10"));
  expectMentions(message, {"scene.yaml", "YAML syntax error", "line", "column", "on one line"});
  EXPECT_EQ(message.find("Throw number"), std::string::npos) << message;
}

TEST_F(SceneTest, KeyGivenTwiceIsRefusedWithBothLines)
{
  const std::string message = errorOf(replaced(kFullScene, "    ghost_width: 3\n", "    ghost_width: 3\n    ghost_width: 4\n"));
  expectMentions(message, {"scene.yaml:11:5: key 'ghost_width' of cfdmpm.domain given twice (first on line 10)"});
}

TEST_F(SceneTest, MpmSettingsAreChecked)
{
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {stress_update: usf}\n")),
                 {"cfdmpm.mpm.stress_update", "usf", "usl", "musl"});
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {flip_fraction: 1.5}\n")),
                 {"cfdmpm.mpm.flip_fraction", "1.5", "[0, 1]"});
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {wall_friction: -0.1}\n")),
                 {"cfdmpm.mpm.wall_friction", "-0.1", ">= 0"});
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {friction: 0.2}\n")),
                 {"cfdmpm.mpm.friction", "wall_friction"});
}

TEST_F(SceneTest, IceSettingsAreChecked)
{
  const std::string ice = "  ice: {outer_tolerance: 1.0e-9, solver_tolerance: 1.0e-11, linear_solver: {verbosity: 1}}\n";
  expectMentions(errorOf(replaced(kFullScene, ice, "  ice: {pressure: semi}\n")),
                 {"cfdmpm.ice.pressure", "semi", "implicit", "explicit"});
  expectMentions(errorOf(replaced(kFullScene, ice, "  ice: {solver_tolerance: 0.5}\n")),
                 {"cfdmpm.ice.solver_tolerance", "0.5", "[0, 0.01)"});
  expectMentions(errorOf(replaced(kFullScene, ice, "  ice: {dt_growth: 1}\n")),
                 {"cfdmpm.ice.dt_growth", "1", "> 1"});
  expectMentions(errorOf(replaced(kFullScene, ice, "  ice: {isothermal: yes please}\n")),
                 {"cfdmpm.ice.isothermal", "yes please", "true or false"});
  expectMentions(errorOf(replaced(kFullScene, ice, "  ice: {outer_tolerence: 1.0e-9}\n")),
                 {"cfdmpm.ice.outer_tolerence", "unknown key", "outer_tolerance"});
}

TEST_F(SceneTest, SecondTopLevelKeyIsRefusedWithItsLine)
{
  // Teuchos would drop this section without a word.
  const std::string message = errorOf(kFullScene + "time:\n  end_time: 3\n");
  expectMentions(message, {"scene.yaml:44: top-level key", "got 'time'", "exactly one top-level key, `cfdmpm:`"});
}

TEST_F(SceneTest, TopLevelKeyOtherThanCfdmpmIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "\ncfdmpm:\n", "\nscene:\n"));
  expectMentions(message, {"scene.yaml:2: top-level key", "got 'scene'", "`cfdmpm:`"});
}

TEST_F(SceneTest, RootThatIsNotASectionIsRefused)
{
  expectMentions(errorOf("cfdmpm: 3\n"), {"cfdmpm", "got '3'", "must hold the scene's sections"});
}

TEST_F(SceneTest, EmptyFileIsRefused)
{
  expectMentions(errorOf("# nothing here\n"), {"scene.yaml", "no top-level key", "`cfdmpm:`"});
}

// --- Keys and types ----------------------------------------------------------------------------

TEST_F(SceneTest, MissingRequiredKeyNamesKeyAndExpectation)
{
  const std::string message = errorOf(replaced(kFullScene, "    gravity: [0.0, -9.81]\n", ""));
  expectMentions(message, {"cfdmpm.domain.gravity", "required key is missing", "a list of 2 numbers"});
}

TEST_F(SceneTest, CellsAndCellSizeTogetherOrNeitherAreRefused)
{
  const std::string both = errorOf(replaced(kFullScene, "    cells: [20, 10]\n", "    cells: [20, 10]\n    cell_size: 0.05\n"));
  expectMentions(both, {"scene.yaml", "cfdmpm.domain: both `cells` ([20, 10]) and `cell_size` (0.05) are given",
                        "give exactly one of them", "cfdmpm.domain.cells", "cfdmpm.domain.cell_size", "> 0 (m)"});
  const std::string neither = errorOf(replaced(kFullScene, "    cells: [20, 10]\n", ""));
  expectMentions(neither, {"scene.yaml", "cfdmpm.domain: neither `cells` nor `cell_size` is given",
                           "give exactly one of them", "cfdmpm.domain.cells, 2 integers (the cells per direction)",
                           "cfdmpm.domain.cell_size, a number > 0 (m)"});
}

TEST_F(SceneTest, CellSizeThatDoesNotDivideTheDomainIsRefused)
{
  // x: 1 m / 0.3 m = 3.33 cells.
  const std::string in_x = errorOf(replaced(kFullScene, "cells: [20, 10]", "cell_size: 0.3"));
  expectMentions(in_x, {"cfdmpm.domain.cell_size: got '0.3'", "does not divide the domain in x",
                        "upper - lower = 1 m holds 3.333333333 cells of 0.3 m, not a whole number",
                        "must divide the extent upper - lower = [1, 1] m into a whole number of cells in every "
                        "direction", "or give `cells`"});
  // y: 1.05 m / 0.1 m = 10.5 cells (x divides: 10 cells).
  const std::string in_y = errorOf(
      replaced(replaced(kFullScene, "cells: [20, 10]", "cell_size: 1.0e-1"), "upper: [1.0, 0.5]", "upper: [1.0, 0.55]"));
  expectMentions(in_y, {"cfdmpm.domain.cell_size: got '1.0e-1'", "does not divide the domain in y",
                        "upper - lower = 1.05 m holds 10.5 cells of 0.1 m", "[1, 1.05] m", "or give `cells`"});
  // Larger than the domain: less than one cell.
  expectMentions(errorOf(replaced(kFullScene, "cells: [20, 10]", "cell_size: 2.0")),
                 {"cfdmpm.domain.cell_size: got '2.0'", "in x", "holds 0.5 cells of 2 m"});
}

TEST_F(SceneTest, CellSizeOutOfRangeIsRefused)
{
  expectMentions(errorOf(replaced(kFullScene, "cells: [20, 10]", "cell_size: 0")),
                 {"cfdmpm.domain.cell_size", "got '0'", "> 0 (m)"});
  expectMentions(errorOf(replaced(kFullScene, "cells: [20, 10]", "cell_size: -0.05")),
                 {"cfdmpm.domain.cell_size", "got '-0.05'", "> 0 (m)"});
  expectMentions(errorOf(replaced(kFullScene, "cells: [20, 10]", "cell_size: [0.05, 0.1]")),
                 {"cfdmpm.domain.cell_size", "[0.05, 0.1]", "expected a number"});
  expectMentions(errorOf(replaced(kFullScene, "cells: [20, 10]", "cell_size: 1.0e-10")),
                 {"cfdmpm.domain.cell_size: got '1.0e-10'", "it makes 1e+10 cells in x", "more than the 2147483647",
                  "larger cell_size"});
}

TEST_F(SceneTest, MissingRequiredSectionNamesIt)
{
  const std::string message = errorOf(replaced(kFullScene, "  time: {end_time: 0.5, cfl: 0.4, dt_initial: 1.0e-4, dt_min: 1.0e-8, dt_max: 1.0e-3, max_steps: 1000}\n", ""));
  expectMentions(message, {"cfdmpm.time", "required key is missing", "a section"});
}

TEST_F(SceneTest, MissingRequiredKeyOfAModelNamesKey)
{
  const std::string message = errorOf(replaced(kFullScene, ", yield_stress: 200.0}", "}"));
  expectMentions(message, {"cfdmpm.materials.sand.model.yield_stress", "required key is missing", "> 0 (Pa)"});
}

TEST_F(SceneTest, MissingSpecificHeatOfALiquidNamesKeyAndType)
{
  const std::string message = errorOf(replaced(kFullScene, "      specific_heat: 4200.0\n", ""));
  expectMentions(message, {"cfdmpm.materials.water.specific_heat", "required key is missing", "linear_water", "> 0"});
}

TEST_F(SceneTest, UnknownKeyListsAllowedKeys)
{
  const std::string message = errorOf(replaced(kFullScene, "ghost_width: 3", "ghost_widht: 3"));
  expectMentions(message, {"cfdmpm.domain.ghost_widht", "unknown key",
                           "dimension, lower, upper, cells, cell_size, patch_cells, ghost_width, gravity"});
}

TEST_F(SceneTest, UnknownKeyInsideAMaterialIsCaught)
{
  const std::string message = errorOf(replaced(kFullScene, "viscosity: 1.0e-3", "viscocity: 1.0e-3"));
  expectMentions(message, {"cfdmpm.materials.water.viscocity", "unknown key",
                           "kind, equation_of_state, viscosity, specific_heat, thermal_conductivity"});
}

TEST_F(SceneTest, UnknownKeyOfAnotherModelTypeIsCaught)
{
  // friction_angle belongs to drucker_prager, not to tresca.
  const std::string message = errorOf(replaced(kFullScene, "yield_stress: 200.0}", "yield_stress: 200.0, friction_angle: 30}"));
  expectMentions(message, {"cfdmpm.materials.sand.model.friction_angle", "unknown key",
                           "type, youngs_modulus, poisson_ratio, yield_stress"});
}

TEST_F(SceneTest, UnknownTopLevelSectionListsAllowedOnes)
{
  const std::string message = errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {}\n  solver: {}\n"));
  expectMentions(message, {"cfdmpm.solver", "unknown key", "domain, materials, initial_state", "ice, mpm"});
}

TEST_F(SceneTest, WrongTypeNamesExpectedType)
{
  const std::string message = errorOf(replaced(kFullScene, "cfl: 0.4", "cfl: fast"));
  expectMentions(message, {"cfdmpm.time.cfl", "got 'fast' (a string)", "expected a number", "(0, 1]"});
}

TEST_F(SceneTest, NumberWhereAnIntegerIsExpectedIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "ghost_width: 3", "ghost_width: 2.5"));
  expectMentions(message, {"cfdmpm.domain.ghost_width", "got '2.5' (a number)", "expected an integer"});
}

TEST_F(SceneTest, ScalarWhereASectionIsExpectedIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "  mpm: {}", "  mpm: 3"));
  expectMentions(message, {"cfdmpm.mpm", "got '3' (an integer)", "expected a section"});
}

TEST_F(SceneTest, MaterialThatIsNotASectionIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "  materials:\n", "  materials:\n    mud: 3\n"));
  expectMentions(message, {"cfdmpm.materials.mud", "got '3'", "expected a section with the material's keys"});
}

TEST_F(SceneTest, MaterialNameWithOddCharactersIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "    sand:\n", "    sand/wet:\n"));
  expectMentions(message, {"cfdmpm.materials.sand/wet", "got 'sand/wet'", "start with a letter"});
}

// --- Values ------------------------------------------------------------------------------------

TEST_F(SceneTest, NegativeViscosityNamesKeyAndLimit)
{
  const std::string message = errorOf(replaced(kFullScene, "viscosity: 1.0e-3", "viscosity: -1.0e-3"));
  expectMentions(message, {"cfdmpm.materials.water.viscosity", "got '-1.0e-3'", "must be >= 0 (Pa s)"});
}

TEST_F(SceneTest, NegativeDensityNamesKeyAndLimit)
{
  const std::string message = errorOf(replaced(kFullScene, "density: 1985.0", "density: -1985.0"));
  expectMentions(message, {"cfdmpm.materials.sand.density", "got '-1985.0'", "must be > 0 (kg/m^3)"});
}

TEST_F(SceneTest, ZeroTemperatureNamesKeyAndLimit)
{
  const std::string message = errorOf(replaced(kFullScene, "temperature: 280.0", "temperature: 0"));
  expectMentions(message, {"cfdmpm.initial_state.temperature", "got '0'", "must be > 0 (K)"});
}

TEST_F(SceneTest, ZeroCellsNamesKeyAndLimit)
{
  const std::string message = errorOf(replaced(kFullScene, "cells: [20, 10]", "cells: [20, 0]"));
  expectMentions(message, {"cfdmpm.domain.cells", "got '[20, 0]'", "every entry must be >= 1"});
}

TEST_F(SceneTest, PoissonRatioOfOneHalfIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "poisson_ratio: 0.25", "poisson_ratio: 0.5"));
  expectMentions(message, {"cfdmpm.materials.sand.model.poisson_ratio", "got '0.5'", "must be in (-1, 0.5)"});
}

TEST_F(SceneTest, ArrayLengthOtherThanDimensionIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "gravity: [0.0, -9.81]", "gravity: [0.0, -9.81, 0.0]"));
  expectMentions(message, {"cfdmpm.domain.gravity", "got '[0.0, -9.81, 0.0]'", "must have 2 entries"});
}

TEST_F(SceneTest, RegionVelocityLengthOtherThanDimensionIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "velocity: [0.5, -0.25]", "velocity: [0.5]"));
  expectMentions(message, {"cfdmpm.regions.block.velocity", "got '[0.5]'", "must have 2 entries"});
}

TEST_F(SceneTest, DomainLowerNotBelowUpperIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "upper: [1.0, 0.5]", "upper: [1.0, -0.5]"));
  expectMentions(message, {"cfdmpm.domain.upper", "got '[1, -0.5]'", "must be above lower = [0, -0.5]"});
}

TEST_F(SceneTest, BoxLowerNotBelowUpperIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "upper: [0.4, -0.3]", "upper: [0.1, -0.3]"));
  expectMentions(message, {"cfdmpm.regions.block.upper", "got '[0.1, -0.3]'", "must be above lower = [0.2, -0.5]"});
}

TEST_F(SceneTest, BoxOutsideTheDomainIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "upper: [0.4, -0.3]", "upper: [1.2, -0.3]"));
  expectMentions(message, {"cfdmpm.regions.block.upper", "got '[1.2, -0.3]'", "x in [0, 1], y in [-0.5, 0.5]"});
}

TEST_F(SceneTest, BoxJustBeyondRoundOffIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "upper: [0.4, -0.3]", "upper: [1.000000001, -0.3]"));
  expectMentions(message, {"cfdmpm.regions.block.upper", "1.000000001", "must lie inside the domain"});
}

TEST_F(SceneTest, PolygonVertexOutsideTheDomainIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "[0.9, -0.2]]", "[0.9, 0.7]]"));
  expectMentions(message, {"cfdmpm.regions.wedge.vertices", "got '[0.9, 0.7]'", "vertex 3", "y in [-0.5, 0.5]"});
}

TEST_F(SceneTest, PolygonWithTwoVerticesIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "[[0.6, -0.5], [0.9, -0.5], [0.9, -0.2]]", "[[0.6, -0.5], [0.9, -0.5]]"));
  expectMentions(message, {"cfdmpm.regions.wedge.vertices", "[[0.6, -0.5], [0.9, -0.5]]", "at least 3 points [x, y]"});
}

TEST_F(SceneTest, HalfPlaneWithZeroNormalIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "normal: [0.0, 2.0]", "normal: [0, 0]"));
  expectMentions(message, {"cfdmpm.regions.pool.normal", "got '[0, 0]'", "must not be zero"});
}

TEST_F(SceneTest, CflAboveOneIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "cfl: 0.4", "cfl: 1.5"));
  expectMentions(message, {"cfdmpm.time.cfl", "got '1.5'", "must be in (0, 1]"});
}

TEST_F(SceneTest, CflOfZeroIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "cfl: 0.4", "cfl: 0"));
  expectMentions(message, {"cfdmpm.time.cfl", "got '0'", "must be in (0, 1]"});
}

TEST_F(SceneTest, DtMinAboveDtMaxIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "dt_min: 1.0e-8", "dt_min: 0.01"));
  expectMentions(message, {"cfdmpm.time.dt_min", "got '0.01'", "must be <= dt_max (0.001 s)"});
}

TEST_F(SceneTest, DtInitialOutsideItsBoundsIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "dt_initial: 1.0e-4", "dt_initial: 0.1"));
  expectMentions(message, {"cfdmpm.time.dt_initial", "got '0.1'", "must be in [dt_min, dt_max] = [1e-08, 0.001]"});
}

TEST_F(SceneTest, NegativeEndTimeIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "end_time: 0.5", "end_time: -1"));
  expectMentions(message, {"cfdmpm.time.end_time", "got '-1'", "must be > 0 (s)"});
}

// --- Names ---------------------------------------------------------------------------------------

TEST_F(SceneTest, UnknownMaterialKindListsKinds)
{
  const std::string message = errorOf(replaced(kFullScene, "kind: solid", "kind: granular"));
  expectMentions(message, {"cfdmpm.materials.sand.kind", "got 'granular'", "allowed: fluid, solid"});
}

TEST_F(SceneTest, MissingMaterialKindIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "      kind: solid\n", ""));
  expectMentions(message, {"cfdmpm.materials.sand.kind", "required key is missing", "fluid, solid"});
}

TEST_F(SceneTest, UnknownEquationOfStateListsTypes)
{
  const std::string message = errorOf(replaced(kFullScene, "type: ideal_gas", "type: perfect_gas"));
  expectMentions(message, {"cfdmpm.materials.air.equation_of_state.type", "got 'perfect_gas'",
                           "allowed: linear_water, ideal_gas, tait"});
}

TEST_F(SceneTest, CavitationPressureIsChecked)
{
  const std::string water = "thermal_expansion: 0.18}";
  expectMentions(errorOf(replaced(kFullScene, water, "thermal_expansion: 0.18, cavitation_pressure: 2.0e5}")),
                 {"cfdmpm.materials.water.equation_of_state.cavitation_pressure", "got 2e+05 Pa",
                  "below reference_pressure (101000 Pa)", "or 0 for no cavitation"});
  expectMentions(errorOf(replaced(kFullScene, water, "thermal_expansion: 0.18, cavitation_pressure: -5.0}")),
                 {"cfdmpm.materials.water.equation_of_state.cavitation_pressure", "-5", ">= 0"});
  EXPECT_NO_THROW(readScene(write(replaced(kFullScene, water, "thermal_expansion: 0.18, cavitation_pressure: 872.0}"))));
}

TEST_F(SceneTest, UnknownSolidModelListsTypes)
{
  const std::string message = errorOf(replaced(kFullScene, "type: tresca", "type: mohr_coulomb"));
  expectMentions(message, {"cfdmpm.materials.sand.model.type", "got 'mohr_coulomb'",
                           "allowed: linear_elastic, neo_hookean, tresca, drucker_prager, rigid"});
}

TEST_F(SceneTest, UnknownInteriorPressureListsChoices)
{
  const std::string message =
      errorOf(replaced(kFullScene, "model: {type: tresca", "interior_pressure: fluid\n      model: {type: tresca"));
  expectMentions(message, {"cfdmpm.materials.sand.interior_pressure", "got 'fluid'", "cell, reference"});
}

TEST_F(SceneTest, UnknownRegionShapeListsShapes)
{
  const std::string message = errorOf(replaced(kFullScene, "shape: box", "shape: sphere"));
  expectMentions(message, {"cfdmpm.regions.block.shape", "got 'sphere'", "allowed: box, polygon, half_plane"});
}

TEST_F(SceneTest, UnknownBoundaryChoiceListsChoices)
{
  const std::string message = errorOf(replaced(kFullScene, "y+: {velocity: free_slip}", "y+: {velocity: slip}"));
  expectMentions(message, {"cfdmpm.boundary_conditions.y+.velocity", "got 'slip'", "allowed: no_slip, free_slip"});
}

TEST_F(SceneTest, ThirdDimensionFaceInTwoDimensionsIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "    y+: {velocity: free_slip}\n",
                                               "    y+: {velocity: free_slip}\n    z-: {velocity: free_slip}\n"));
  expectMentions(message, {"cfdmpm.boundary_conditions.z-", "unknown key", "x-, x+, y-, y+"});
}

TEST_F(SceneTest, RegionWithUnknownMaterialListsKnownOnes)
{
  const std::string message = errorOf(replaced(kFullScene, "material: water, shape: half_plane", "material: sea, shape: half_plane"));
  expectMentions(message, {"cfdmpm.regions.pool.material", "got 'sea'", "known materials: water, air, sand"});
}

TEST_F(SceneTest, BackgroundWithUnknownMaterialListsKnownOnes)
{
  const std::string message = errorOf(replaced(kFullScene, "background_material: air", "background_material: vacuum"));
  expectMentions(message, {"cfdmpm.initial_state.background_material", "got 'vacuum'", "known materials: water, air, sand"});
}

TEST_F(SceneTest, SolidBackgroundIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "background_material: air", "background_material: sand"));
  expectMentions(message, {"cfdmpm.initial_state.background_material", "got 'sand'", "fluids: water, air"});
}

TEST_F(SceneTest, NoMaterialsIsRefused)
{
  const std::string text = replaced(kMinimalScene, R"(  materials:
    air:
      kind: fluid
      equation_of_state: {type: ideal_gas}
      viscosity: 0
)",
                                    "  materials: {}\n");
  expectMentions(errorOf(text), {"cfdmpm.materials", "got '{}'", "at least one material"});
}

TEST_F(SceneTest, UnknownOutputFieldListsAllowedOnes)
{
  const std::string message = errorOf(replaced(kFullScene, "fields: [velocity, pressure, particle_stress]", "fields: [velocity, presure]"));
  expectMentions(message, {"cfdmpm.output.fields", "got '[velocity, presure]'", "'presure' is not allowed",
                           "volume_fraction, density, velocity, temperature, pressure, specific_volume, "
                           "particle_velocity, particle_stress, plastic_strain, particle_volume, particle_material"});
}

TEST_F(SceneTest, OutputFieldListedTwiceIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "fields: [velocity, pressure, particle_stress]", "fields: [velocity, velocity]"));
  expectMentions(message, {"cfdmpm.output.fields", "'velocity' is listed twice"});
}

// --- Consistency between keys -------------------------------------------------------------------

TEST_F(SceneTest, IdealGasSpecificHeatAtOddsWithGasConstantIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "      viscosity: 1.8e-5\n", "      viscosity: 1.8e-5\n      specific_heat: 1000\n"));
  expectMentions(message, {"cfdmpm.materials.air.specific_heat", "got '1000'", "gas_constant / (gamma - 1) = 717.5"});
}

TEST_F(SceneTest, DilatancyAboveFrictionAngleIsRefused)
{
  const std::string message = errorOf(replaced(kFullScene, "model: {type: tresca, youngs_modulus: 5.0e7, poisson_ratio: 0.25, yield_stress: 200.0}",
                                               "model: {type: drucker_prager, youngs_modulus: 5.0e7, poisson_ratio: 0.25, friction_angle: 20, dilatancy_angle: 25}"));
  expectMentions(message, {"cfdmpm.materials.sand.model.dilatancy_angle", "got '25'", "must be <= friction_angle (20 degree)"});
}

}  // namespace
}  // namespace cfdmpm::test
