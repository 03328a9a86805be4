// A valid scene fills every field of Scene; keys left out take their defaults; integers are
// accepted where numbers are expected.
#include "scene_test_support.hpp"

#include <Teuchos_Array.hpp>
#include <Teuchos_Tuple.hpp>

namespace cfdmpm::test {
namespace {

using Teuchos::Array;

TEST_F(SceneTest, FullSceneFillsEveryField)
{
  const Scene scene = readScene(write(kFullScene));
  EXPECT_EQ(scene.title, "Test tank");

  const DomainSpec& domain = scene.domain;
  EXPECT_EQ(domain.dimension, 2);
  EXPECT_EQ(domain.lower, (std::array<double, 3>{0.0, -0.5, 0.0}));
  EXPECT_EQ(domain.upper, (std::array<double, 3>{1.0, 0.5, 1.0}));
  EXPECT_EQ(domain.cells, (std::array<long long, 3>{20, 10, 1}));
  EXPECT_EQ(domain.patch_cells, (std::array<long long, 3>{10, 5, 1}));
  EXPECT_EQ(domain.ghost_width, 3);
  EXPECT_EQ(domain.gravity, (std::array<double, 3>{0.0, -9.81, 0.0}));

  // Materials in file order, each with its validated sublist.
  ASSERT_EQ(scene.materials.size(), 3u);
  EXPECT_EQ(scene.materials[0].name, "water");
  EXPECT_EQ(scene.materials[0].kind, "fluid");
  EXPECT_EQ(scene.materials[1].name, "air");
  EXPECT_EQ(scene.materials[2].name, "sand");
  EXPECT_EQ(scene.materials[2].kind, "solid");
  EXPECT_EQ(scene.materialIndex("sand"), 2);
  EXPECT_THROW(scene.materialIndex("mud"), InputError);
  const auto& water = scene.materials[0].parameters;
  EXPECT_EQ(water.get<double>("viscosity"), 1.0e-3);
  EXPECT_EQ(water.get<double>("specific_heat"), 4200.0);
  EXPECT_EQ(water.get<double>("thermal_conductivity"), 0.6);
  const auto& eos = water.sublist("equation_of_state");
  EXPECT_EQ(eos.get<std::string>("type"), "linear_water");
  EXPECT_EQ(eos.get<double>("bulk_modulus"), 2.15e9);
  EXPECT_EQ(eos.get<double>("reference_density"), 999.8);
  EXPECT_EQ(eos.get<double>("reference_pressure"), 101000.0);
  EXPECT_EQ(eos.get<double>("reference_temperature"), 278.15);
  EXPECT_EQ(eos.get<double>("thermal_expansion"), 0.18);
  const auto& sand = scene.materials[2].parameters;
  EXPECT_EQ(sand.get<double>("density"), 1985.0);
  EXPECT_EQ(sand.get<int>("particles_per_cell"), 3);
  EXPECT_EQ(sand.sublist("model").get<std::string>("type"), "tresca");
  EXPECT_EQ(sand.sublist("model").get<double>("youngs_modulus"), 5.0e7);
  EXPECT_EQ(sand.sublist("model").get<double>("poisson_ratio"), 0.25);
  EXPECT_EQ(sand.sublist("model").get<double>("yield_stress"), 200.0);

  EXPECT_EQ(scene.initial.background_material, "air");
  EXPECT_EQ(scene.initial.temperature, 280.0);
  EXPECT_EQ(scene.initial.pressure, 100000.0);
  EXPECT_FALSE(scene.initial.hydrostatic);

  ASSERT_EQ(scene.regions.size(), 3u);
  const RegionSpec& pool = scene.regions[0];
  EXPECT_EQ(pool.name, "pool");
  EXPECT_EQ(pool.material, "water");
  EXPECT_EQ(pool.shape, "half_plane");
  EXPECT_EQ(pool.point, (std::array<double, 3>{0.0, 0.1, 0.0}));
  EXPECT_EQ(pool.normal, (std::array<double, 3>{0.0, 1.0, 0.0}));  // made unit length
  EXPECT_EQ(pool.velocity, (std::array<double, 3>{0.0, 0.0, 0.0}));
  EXPECT_EQ(pool.temperature, 280.0);  // initial_state.temperature
  const RegionSpec& block = scene.regions[1];
  EXPECT_EQ(block.shape, "box");
  EXPECT_EQ(block.lower, (std::array<double, 3>{0.2, -0.5, 0.0}));
  EXPECT_EQ(block.upper, (std::array<double, 3>{0.4, -0.3, 0.0}));
  EXPECT_EQ(block.velocity, (std::array<double, 3>{0.5, -0.25, 0.0}));
  EXPECT_EQ(block.temperature, 285.0);
  const RegionSpec& wedge = scene.regions[2];
  EXPECT_EQ(wedge.shape, "polygon");
  ASSERT_EQ(wedge.vertices.size(), 3u);
  EXPECT_EQ(wedge.vertices[2], (std::array<double, 2>{0.9, -0.2}));

  ASSERT_EQ(scene.boundaries.size(), 4u);
  EXPECT_EQ(scene.boundaries[0].face, "x-");
  EXPECT_EQ(scene.boundaries[0].velocity, "free_slip");
  EXPECT_EQ(scene.boundaries[0].temperature, "fixed");
  EXPECT_EQ(scene.boundaries[0].temperature_value, 290.0);
  EXPECT_EQ(scene.boundaries[1].face, "x+");
  EXPECT_EQ(scene.boundaries[1].velocity, "no_slip");
  EXPECT_EQ(scene.boundaries[3].face, "y+");
  EXPECT_EQ(scene.boundaries[3].velocity, "free_slip");
  EXPECT_EQ(scene.boundaries[3].temperature, "zero_gradient");

  EXPECT_EQ(scene.time.end_time, 0.5);
  EXPECT_EQ(scene.time.cfl, 0.4);
  EXPECT_EQ(scene.time.dt_initial, 1.0e-4);
  EXPECT_EQ(scene.time.dt_min, 1.0e-8);
  EXPECT_EQ(scene.time.dt_max, 1.0e-3);
  EXPECT_EQ(scene.time.max_steps, 1000);

  EXPECT_EQ(scene.output.directory, "out/test");
  EXPECT_EQ(scene.output.interval, 0.1);
  EXPECT_EQ(scene.output.fields, (std::vector<std::string>{"velocity", "pressure", "particle_stress"}));
  EXPECT_TRUE(scene.output.overwrite);
  EXPECT_EQ(scene.output.progress_interval, 5.0);

  // The ICE section is checked here and read by the ICE solver from the list; its linear_solver
  // sublist is passed on untouched to the pressure solver.
  ASSERT_FALSE(scene.parameters.is_null());
  const auto& ice = scene.parameters->sublist("ice");
  EXPECT_EQ(ice.get<double>("outer_tolerance"), 1e-9);
  EXPECT_EQ(ice.get<double>("solver_tolerance"), 1e-11);
  EXPECT_EQ(ice.get<double>("dt_growth"), 1.2);
  EXPECT_EQ(ice.sublist("linear_solver").get<int>("verbosity"), 1);
  EXPECT_TRUE(scene.parameters->isSublist("mpm"));
  EXPECT_EQ(scene.path, directory_.string() + "/scene.yaml");
}

TEST_F(SceneTest, MissingKeysTakeTheirDefaults)
{
  const Scene scene = readScene(write(kMinimalScene));
  EXPECT_EQ(scene.title, "");
  EXPECT_EQ(scene.domain.patch_cells, (std::array<long long, 3>{16, 10, 1}));  // 16, clipped to cells
  EXPECT_EQ(scene.domain.ghost_width, 2);
  EXPECT_EQ(scene.initial.temperature, 293.15);
  EXPECT_EQ(scene.initial.pressure, 101325.0);
  EXPECT_TRUE(scene.initial.hydrostatic);
  EXPECT_TRUE(scene.regions.empty());

  ASSERT_EQ(scene.boundaries.size(), 4u);
  const std::vector<std::string> faces{"x-", "x+", "y-", "y+"};
  for (size_t i = 0; i < faces.size(); ++i) {
    EXPECT_EQ(scene.boundaries[i].face, faces[i]);
    EXPECT_EQ(scene.boundaries[i].velocity, "no_slip");
    EXPECT_EQ(scene.boundaries[i].temperature, "zero_gradient");
    EXPECT_EQ(scene.boundaries[i].temperature_value, 293.15);
  }

  EXPECT_EQ(scene.time.cfl, 0.25);
  EXPECT_EQ(scene.time.dt_initial, 1.0e-5);
  EXPECT_EQ(scene.time.dt_min, 1.0e-10);
  EXPECT_EQ(scene.time.dt_max, 1.0e-2);
  EXPECT_EQ(scene.time.max_steps, -1);
  EXPECT_EQ(scene.output.fields,
            (std::vector<std::string>{"volume_fraction", "density", "velocity", "temperature", "pressure"}));
  EXPECT_FALSE(scene.output.overwrite);
  EXPECT_EQ(scene.output.progress_interval, 1.0);

  // Defaults are in the parameter list too, where the solvers read them.
  const auto& air = scene.materials.at(0).parameters;
  EXPECT_EQ(air.sublist("equation_of_state").get<double>("gas_constant"), 287.0);
  EXPECT_EQ(air.sublist("equation_of_state").get<double>("gamma"), 1.4);
  EXPECT_DOUBLE_EQ(air.get<double>("specific_heat"), 287.0 / 0.4);  // c_v = R / (gamma - 1)
  EXPECT_EQ(air.get<double>("thermal_conductivity"), 0.0);
  EXPECT_TRUE(scene.parameters->isSublist("ice"));
  EXPECT_EQ(scene.parameters->sublist("ice").get<double>("solver_tolerance"), 0.0);  // from outer_tolerance
  EXPECT_EQ(scene.parameters->sublist("ice").get<std::string>("pressure"), "implicit");
  EXPECT_TRUE(scene.parameters->isSublist("mpm"));
  EXPECT_EQ(scene.parameters->sublist("domain").get<int>("ghost_width"), 2);
  EXPECT_EQ(scene.mpm.shape_function, "gimp");
  EXPECT_EQ(scene.mpm.flip_fraction, 0.99);
  EXPECT_EQ(scene.mpm.stress_update, "usl");
  EXPECT_EQ(scene.mpm.wall_friction, 0.0);
  EXPECT_TRUE(scene.mpm.contact);
  EXPECT_EQ(scene.mpm.contact_friction, 0.0);
  EXPECT_EQ(scene.mpm.velocity_damping, 0.0);
}

TEST_F(SceneTest, MpmSectionIsRead)
{
  const Scene scene = readScene(write(replaced(
      kFullScene, "  mpm: {}\n",
      "  mpm: {shape_function: linear, flip_fraction: 1, stress_update: musl, wall_friction: 0.2, contact: false, "
      "contact_friction: 0.3, velocity_damping: 5.0}\n")));
  EXPECT_EQ(scene.mpm.shape_function, "linear");
  EXPECT_EQ(scene.mpm.flip_fraction, 1.0);  // an integer where a number is expected
  EXPECT_EQ(scene.mpm.stress_update, "musl");
  EXPECT_EQ(scene.mpm.wall_friction, 0.2);
  EXPECT_FALSE(scene.mpm.contact);
  EXPECT_EQ(scene.mpm.contact_friction, 0.3);
  EXPECT_EQ(scene.mpm.velocity_damping, 5.0);
}

TEST_F(SceneTest, IntegersAreAcceptedWhereNumbersAreExpected)
{
  const Scene scene = readScene(write(kMinimalScene));
  EXPECT_EQ(scene.domain.lower, (std::array<double, 3>{0.0, 0.0, 0.0}));
  EXPECT_EQ(scene.domain.upper, (std::array<double, 3>{1.0, 2.0, 1.0}));
  EXPECT_EQ(scene.domain.gravity, (std::array<double, 3>{0.0, -10.0, 0.0}));
  EXPECT_EQ(scene.time.end_time, 1.0);
  const auto& domain = scene.parameters->sublist("domain");
  EXPECT_TRUE(domain.isType<Array<double>>("upper"));  // converted in the list as well
  EXPECT_TRUE(scene.materials.at(0).parameters.isType<double>("viscosity"));

  const Scene with_polygon = readScene(write(replaced(kFullScene, "vertices: [[0.6, -0.5], [0.9, -0.5], [0.9, -0.2]]",
                                                      "vertices: [[0, 0], [1, 0], [1, 0.5]]")));
  EXPECT_EQ(with_polygon.regions[2].vertices[1], (std::array<double, 2>{1.0, 0.0}));
}

TEST_F(SceneTest, ThreeDimensionalSceneHasSixFacesAndThreeComponents)
{
  const std::string scene_text = R"(cfdmpm:
  domain:
    dimension: 3
    lower: [0, 0, 0]
    upper: [1, 1, 2]
    cells: [10, 20, 40]
    gravity: [0, 0, -9.81]
  materials:
    air: {kind: fluid, equation_of_state: {type: ideal_gas}, viscosity: 1.8e-5}
    rock: {kind: solid, density: 2600, model: {type: rigid}}
  initial_state: {background_material: air}
  regions:
    ledge: {material: rock, shape: polygon, vertices: [[0, 0], [1, 0], [0, 1]]}
    cube: {material: rock, shape: box, lower: [0.1, 0.1, 0.1], upper: [0.2, 0.2, 1.9], velocity: [0, 0, -1]}
  boundary_conditions:
    z+: {velocity: free_slip}
  time: {end_time: 1}
  output: {directory: out, interval: 0.5}
)";
  const Scene scene = readScene(write(scene_text));
  EXPECT_EQ(scene.domain.dimension, 3);
  EXPECT_EQ(scene.domain.cells, (std::array<long long, 3>{10, 20, 40}));
  EXPECT_EQ(scene.domain.patch_cells, (std::array<long long, 3>{10, 16, 16}));
  EXPECT_EQ(scene.domain.upper, (std::array<double, 3>{1.0, 1.0, 2.0}));
  ASSERT_EQ(scene.boundaries.size(), 6u);
  EXPECT_EQ(scene.boundaries[5].face, "z+");
  EXPECT_EQ(scene.boundaries[5].velocity, "free_slip");
  EXPECT_EQ(scene.regions[1].velocity, (std::array<double, 3>{0.0, 0.0, -1.0}));
  EXPECT_EQ(scene.regions[1].upper, (std::array<double, 3>{0.2, 0.2, 1.9}));
  // A rigid body without a velocity is at rest, with one entry per direction.
  EXPECT_EQ(scene.materials[1].parameters.sublist("model").get<Array<double>>("velocity"), Array<double>(3, 0.0));
}

// `cell_size` gives the DomainSpec (and the domain list) that the equivalent `cells` gives.
void expectSameDomain(const Scene& a, const Scene& b)
{
  EXPECT_EQ(a.domain.dimension, b.domain.dimension);
  EXPECT_EQ(a.domain.lower, b.domain.lower);
  EXPECT_EQ(a.domain.upper, b.domain.upper);
  EXPECT_EQ(a.domain.cells, b.domain.cells);
  EXPECT_EQ(a.domain.patch_cells, b.domain.patch_cells);
  EXPECT_EQ(a.domain.ghost_width, b.domain.ghost_width);
  EXPECT_EQ(a.domain.gravity, b.domain.gravity);
  EXPECT_EQ(a.domain.rebalance_interval, b.domain.rebalance_interval);
  EXPECT_EQ(a.parameters->sublist("domain").get<Array<int>>("cells"),
            b.parameters->sublist("domain").get<Array<int>>("cells"));
  EXPECT_EQ(a.parameters->sublist("domain").get<Array<int>>("patch_cells"),
            b.parameters->sublist("domain").get<Array<int>>("patch_cells"));
}

TEST_F(SceneTest, CellSizeGivesTheSameDomainAsCells)
{
  // The full scene's domain, [0, 1] x [-0.5, 0.5] m: cell_size 0.05 m is 20 x 20 cells.
  const std::string by_cells = replaced(kFullScene, "cells: [20, 10]", "cells: [20, 20]");
  const std::string by_size = replaced(kFullScene, "cells: [20, 10]", "cell_size: 0.05");
  const Scene a = readScene(write(by_cells, "cells.yaml"));
  const Scene b = readScene(write(by_size, "size.yaml"));
  EXPECT_EQ(b.domain.cells, (std::array<long long, 3>{20, 20, 1}));
  EXPECT_EQ(b.domain.patch_cells, (std::array<long long, 3>{10, 5, 1}));  // as given
  expectSameDomain(a, b);
  // The list keeps the key given and no stand-in for the other.
  EXPECT_FALSE(a.parameters->sublist("domain").isParameter("cell_size"));
  EXPECT_EQ(b.parameters->sublist("domain").get<double>("cell_size"), 0.05);

  // patch_cells left out: 16 per direction, clipped to the cells cell_size gives (40 x 10).
  const std::string minimal = replaced(kMinimalScene, "upper: [1, 2]", "upper: [1, 0.25]");
  const Scene c = readScene(write(minimal, "minimal-cells.yaml"));
  const Scene d = readScene(write(replaced(minimal, "cells: [40, 10]", "cell_size: 0.025"), "minimal-size.yaml"));
  EXPECT_EQ(d.domain.cells, (std::array<long long, 3>{40, 10, 1}));
  EXPECT_EQ(d.domain.patch_cells, (std::array<long long, 3>{16, 10, 1}));
  expectSameDomain(c, d);

  // An integer cell size is a number too.
  const Scene e = readScene(write(replaced(replaced(kMinimalScene, "cells: [40, 10]", "cell_size: 1"), "upper: [1, 2]",
                                           "upper: [3, 2]"),
                                  "integer.yaml"));
  EXPECT_EQ(e.domain.cells, (std::array<long long, 3>{3, 2, 1}));
}

TEST_F(SceneTest, CellSizeDividesExtentsWithinRoundOff)
{
  // The seed scene's domain, 3.52 m x 1.84 m, at 40, 20, 10 and 5 mm: the extents (differences of
  // doubles) divided by the size are whole numbers to within round-off.
  const std::string domain = replaced(replaced(kMinimalScene, "lower: [0, 0]", "lower: [-2.02, -0.04]"),
                                      "upper: [1, 2]", "upper: [1.5, 1.8]");
  const std::vector<std::pair<std::string, std::array<long long, 3>>> sizes{
      {"0.04", {88, 46, 1}}, {"0.02", {176, 92, 1}}, {"0.01", {352, 184, 1}}, {"0.005", {704, 368, 1}}};
  for (const auto& [size, cells] : sizes) {
    const Scene scene = readScene(write(replaced(domain, "cells: [40, 10]", "cell_size: " + size), size + ".yaml"));
    EXPECT_EQ(scene.domain.cells, cells) << "cell_size " << size;
    EXPECT_EQ(scene.domain.patch_cells, (std::array<long long, 3>{16, 16, 1})) << "cell_size " << size;
  }
  // 3-D: the third direction is divided too.
  const std::string three_d = R"(cfdmpm:
  domain: {dimension: 3, lower: [0, 0, 0], upper: [1, 0.5, 0.2], cell_size: 0.1, gravity: [0, 0, -9.81]}
  materials:
    air: {kind: fluid, equation_of_state: {type: ideal_gas}, viscosity: 1.8e-5}
  initial_state: {background_material: air}
  time: {end_time: 1}
  output: {directory: out, interval: 0.5}
)";
  const Scene scene = readScene(write(three_d, "3d.yaml"));
  EXPECT_EQ(scene.domain.cells, (std::array<long long, 3>{10, 5, 2}));
  EXPECT_EQ(scene.domain.patch_cells, (std::array<long long, 3>{10, 5, 2}));
}

TEST_F(SceneTest, RegionOnTheDomainBoundaryWithinRoundOffIsAccepted)
{
  // 1e-13 beyond a 1 m domain is round-off (the tolerance is 1e-12 of the domain size).
  const Scene scene = readScene(write(replaced(kFullScene, "upper: [0.4, -0.3]", "upper: [1.0000000000001, -0.3]")));
  EXPECT_EQ(scene.regions[1].upper[0], 1.0000000000001);
}

TEST_F(SceneTest, EveryMaterialKindAndModelTypeIsAccepted)
{
  const std::string materials = R"(  materials:
    water: {kind: fluid, equation_of_state: {type: tait, reference_density: 1000, bulk_modulus: 2.2e9}, viscosity: 1.0e-3, specific_heat: 4180}
    oil: {kind: fluid, equation_of_state: {type: linear_water, bulk_modulus: 1.5e9, reference_density: 850}, viscosity: 0.05, specific_heat: 1900}
    air: {kind: fluid, equation_of_state: {type: ideal_gas, gas_constant: 287, gamma: 1.4}, viscosity: 1.8e-5, specific_heat: 717.5}
    steel: {kind: solid, density: 7800, model: {type: linear_elastic, youngs_modulus: 2.0e11, poisson_ratio: 0.3}}
    rubber: {kind: solid, density: 1100, model: {type: neo_hookean, bulk_modulus: 2.0e9, shear_modulus: 1.0e6}}
    soil: {kind: solid, density: 1900, model: {type: drucker_prager, youngs_modulus: 1.0e7, poisson_ratio: 0.3, friction_angle: 30, dilatancy_angle: 5, fit: outer_cone}}
    clay: {kind: solid, density: 1800, model: {type: tresca, youngs_modulus: 1.0e7, poisson_ratio: 0.45, yield_stress: 1.0e3}}
    wall: {kind: solid, density: 2500, model: {type: rigid, velocity: [0.1, 0]}}
)";
  const std::string text = replaced(kMinimalScene, R"(  materials:
    air:
      kind: fluid
      equation_of_state: {type: ideal_gas}
      viscosity: 0
)",
                                    materials);
  const Scene scene = readScene(write(text));
  ASSERT_EQ(scene.materials.size(), 8u);
  const auto& water_eos = scene.materials[0].parameters.sublist("equation_of_state");
  EXPECT_EQ(water_eos.get<double>("exponent"), 7.0);
  EXPECT_EQ(water_eos.get<double>("reference_pressure"), 101325.0);
  const auto& oil_eos = scene.materials[1].parameters.sublist("equation_of_state");
  EXPECT_EQ(oil_eos.get<double>("reference_temperature"), 293.15);
  EXPECT_EQ(oil_eos.get<double>("thermal_expansion"), 0.0);
  const auto& soil = scene.materials[5].parameters.sublist("model");
  EXPECT_EQ(soil.get<double>("cohesion"), 0.0);
  EXPECT_EQ(soil.get<std::string>("fit"), "outer_cone");
  EXPECT_EQ(scene.materials[5].parameters.get<int>("particles_per_cell"), 2);
  EXPECT_EQ(scene.materials[7].parameters.sublist("model").get<Array<double>>("velocity"), Array<double>(Teuchos::tuple(0.1, 0.0)));
  // The pressure inside a solid: the cell's for the elastic models, the reference for the plastic ones.
  const std::vector<std::string> interior{"cell", "cell", "reference", "reference", "cell"};
  for (int m = 3; m < 8; ++m)
    EXPECT_EQ(scene.materials[m].parameters.get<std::string>("interior_pressure"), interior[m - 3]) << m;
}

TEST_F(SceneTest, CommentsDirectivesAndDocumentMarkersAroundTheRootAreAllowed)
{
  const Scene scene = readScene(write("%YAML 1.1\n---\n# comment\n" + kMinimalScene + "...\n"));
  EXPECT_EQ(scene.domain.cells[0], 40);
}

}  // namespace
}  // namespace cfdmpm::test
