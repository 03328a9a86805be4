// The checks of a scene as a whole (input/scene_checks.hpp), run by readScene: what regions
// place, polygons, the solvers' own settings, derived quantities and the grid's size. Each test
// breaks one thing in kFullScene and expects the key, the value and the reason in the message.
#include "grid/geometry.hpp"
#include "input/scene_checks.hpp"
#include "scene_test_support.hpp"

#include <cmath>

namespace cfdmpm::test {
namespace {

const std::string kBlock =
    "block: {material: sand, shape: box, lower: [0.2, -0.5], upper: [0.4, -0.3], velocity: [0.5, -0.25], "
    "temperature: 285.0}";
const std::string kWedge = "wedge: {material: sand, shape: polygon, vertices: [[0.6, -0.5], [0.9, -0.5], [0.9, -0.2]]}";
const std::string kPool = "pool: {material: water, shape: half_plane, point: [0.0, 0.1], normal: [0.0, 2.0]}";

/// kFullScene without its solid: the fluid solver runs only in scenes without solids, and only then
/// does the compressibility enter a pressure equation.
std::string fluidsOnly(const std::string& text)
{
  std::string fluids = replaced(text, kBlock, "");
  fluids = replaced(fluids, kWedge, "");
  return replaced(fluids,
                  "    sand:\n      kind: solid\n      density: 1985.0\n      model: {type: tresca, youngs_modulus: 5.0e7, "
                  "poisson_ratio: 0.25, yield_stress: 200.0}\n      particles_per_cell: 3\n",
                  "");
}

// --- Regions that place nothing ----------------------------------------------------------------

TEST_F(SceneTest, SolidRegionTooSmallForAParticleIsRefusedByName)
{
  // 0.1 mm wide in 50 mm cells with 3 particles per cell and direction (16.7 mm apart).
  const std::string message = errorOf(replaced(kFullScene, kBlock,
                                               "block: {material: sand, shape: box, lower: [0.2, -0.5], upper: "
                                               "[0.2001, -0.3]}"));
  expectMentions(message, {"cfdmpm.regions.block", "no particle", "sand", "[0.2, -0.5]", "[0.2001, -0.3]",
                           "16.7 mm apart", "particles_per_cell"});
}

TEST_F(SceneTest, FluidRegionBetweenSamplePointsIsRefused)
{
  // Sample points sit at 6.25, 18.75, 31.25, 43.75 mm within each 50 mm cell: x in [0.132, 0.142]
  // (between 0.13125 and 0.14375) holds none.
  const std::string message = errorOf(replaced(kFullScene, kPool,
                                               "pool: {material: water, shape: box, lower: [0.132, -0.5], "
                                               "upper: [0.142, 0.5]}"));
  expectMentions(message, {"cfdmpm.regions.pool", "places no water", "12.5 mm apart"});
}

TEST_F(SceneTest, HalfPlaneInFrontOfTheWholeDomainIsRefused)
{
  // The domain is y in [-0.5, 0.5]; everything below y = -0.6 is outside it.
  const std::string message = errorOf(replaced(kFullScene, kPool,
                                               "pool: {material: water, shape: half_plane, point: [0.0, -0.6], "
                                               "normal: [0.0, 1.0]}"));
  expectMentions(message, {"cfdmpm.regions.pool", "places no water", "half-plane", "[0, -0.6]", "normal"});
}

TEST_F(SceneTest, CollinearOrRepeatedPolygonPointsAreRefused)
{
  for (const std::string vertices : {"[[0.6, -0.5], [0.7, -0.4], [0.8, -0.3]]", "[[0.6, -0.5], [0.6, -0.5], [0.6, -0.5]]",
                                     "[[0.6, -0.5], [0.9, -0.5], [0.7, -0.5], [0.8, -0.5]]"}) {
    const std::string message = errorOf(replaced(kFullScene, kWedge,
                                                 "wedge: {material: sand, shape: polygon, vertices: " + vertices + "}"));
    expectMentions(message, {"cfdmpm.regions.wedge.vertices", vertices, "enclose no area"});
  }
}

TEST_F(SceneTest, SelfIntersectingPolygonIsRefusedNamingTheEdges)
{
  // A figure eight: the edges 1-2 and 3-4 cross at (0.75, -0.35).
  const std::string vertices = "[[0.6, -0.5], [0.9, -0.2], [0.9, -0.5], [0.6, -0.2]]";
  const std::string message =
      errorOf(replaced(kFullScene, kWedge, "wedge: {material: sand, shape: polygon, vertices: " + vertices + "}"));
  expectMentions(message, {"cfdmpm.regions.wedge.vertices", vertices, "vertex 1 to 2", "vertex 3 to 4",
                           "must not cross itself"});
}

TEST_F(SceneTest, PolygonWithTheFirstPointRepeatedAtTheEndIsAccepted)
{
  // A closed outline as GIS tools write it: the same triangle as kWedge, same particles.
  const Scene scene = readScene(write(replaced(
      kFullScene, kWedge,
      "wedge: {material: sand, shape: polygon, vertices: [[0.6, -0.5], [0.9, -0.5], [0.9, -0.2], [0.6, -0.5]]}")));
  const Scene reference = readScene(write(kFullScene, "reference.yaml"));
  EXPECT_EQ(regionPlacements(scene).at(2).points, regionPlacements(reference).at(2).points);
}

// What a region places, against a count of every lattice point with the run's own test
// (regionContains) at the positions the run uses (Grid::nodePosition + (a + 0.5) / n h).
double bruteForceCount(const Scene& scene, const RegionSpec& region, int n)
{
  const DomainSpec& domain = scene.domain;
  double count = 0;
  for (long long i = 0; i < domain.cells[0] * n; ++i)
    for (long long j = 0; j < domain.cells[1] * n; ++j) {
      std::array<double, 3> x{0, 0, 0};
      const long long ij[2] = {i, j};
      for (int d = 0; d < 2; ++d) {
        const double h = (domain.upper[d] - domain.lower[d]) / double(domain.cells[d]);
        x[d] = domain.lower[d] + double(ij[d] / n) * h + (double(ij[d] % n) + 0.5) / n * h;
      }
      count += regionContains(region, 2, x) ? 1 : 0;
    }
  return count;
}

TEST_F(SceneTest, PlacementCountsEqualTheRunsLattice)
{
  // A tilted half-plane and a polygon whose vertices lie off the lattice lines, so that no point
  // lies on an outline (where the column count and the run's ray test may differ).
  std::string text = replaced(kFullScene, kPool,
                              "pool: {material: water, shape: half_plane, point: [0.0, 0.1], normal: [0.3, 2.0]}");
  text = replaced(text, kWedge,
                  "wedge: {material: sand, shape: polygon, vertices: [[0.61, -0.49], [0.93, -0.47], [0.88, -0.21], "
                  "[0.75, -0.33]]}");
  const Scene scene = readScene(write(text));
  const std::vector<RegionPlacement> placements = regionPlacements(scene);
  ASSERT_EQ(placements.size(), 3u);
  const int per_direction[3] = {4, 3, 3};  // water samples 4 per cell; sand particles_per_cell 3
  for (int r = 0; r < 3; ++r) {
    EXPECT_EQ(placements[r].per_direction, per_direction[r]) << placements[r].region;
    EXPECT_EQ(placements[r].points, bruteForceCount(scene, scene.regions[r], per_direction[r])) << placements[r].region;
    EXPECT_GT(placements[r].points, 0) << placements[r].region;  // a count of 0 would prove nothing
  }
  // The block covers 4 x 2 cells (0.05 m x 0.1 m) of 3 x 3 particles exactly.
  EXPECT_EQ(placements[1].points, 72);
  EXPECT_EQ(placements[1].cells, 8);
}

// --- Settings the solvers check when they are built -------------------------------------------

const std::string kIce = "  ice: {outer_tolerance: 1.0e-9, solver_tolerance: 1.0e-11, linear_solver: {verbosity: 1}}\n";

TEST_F(SceneTest, LinearSolverKeysAreCheckedWithTheScene)
{
  expectMentions(errorOf(replaced(kFullScene, kIce, "  ice: {linear_solver: {preconditionner: jacobi}}\n")),
                 {"cfdmpm.ice.linear_solver.preconditionner", "unknown key", "preconditioner", "reuse mode"});
  expectMentions(errorOf(replaced(kFullScene, kIce, "  ice: {linear_solver: {reuse mode: sometimes}}\n")),
                 {"cfdmpm.ice.linear_solver.reuse mode", "sometimes", "RAP, RP, tP, frozen"});
  expectMentions(errorOf(replaced(kFullScene, kIce, "  ice: {linear_solver: {verbosity: loud}}\n")),
                 {"cfdmpm.ice.linear_solver.verbosity", "integer"});
  expectMentions(errorOf(replaced(kFullScene, kIce, "  ice: {linear_solver: {refresh corrections: maybe}}\n")),
                 {"cfdmpm.ice.linear_solver.refresh corrections", "true or false"});
}

// ice.solid_exchange_coefficient follows ice.exchange_coefficient unless given, and a wrong type for
// the one it follows is named as any other key's (it is read only after the section's keys pass).
TEST_F(SceneTest, SolidExchangeCoefficientFollowsTheFluidsUnlessGiven)
{
  const auto coefficients = [&](const std::string& ice) {
    const Scene scene = readScene(write(replaced(kFullScene, kIce, ice)));
    const auto& list = scene.parameters->sublist("ice");
    return std::pair{list.get<double>("exchange_coefficient"), list.get<double>("solid_exchange_coefficient")};
  };
  EXPECT_EQ(coefficients("  ice: {}\n"), (std::pair{1e15, 1e15}));
  EXPECT_EQ(coefficients("  ice: {exchange_coefficient: 1.0e3}\n"), (std::pair{1e3, 1e3}));
  EXPECT_EQ(coefficients("  ice: {exchange_coefficient: 0}\n"), (std::pair{0.0, 0.0}));
  EXPECT_EQ(coefficients("  ice: {solid_exchange_coefficient: 0.0}\n"), (std::pair{1e15, 0.0}));
  EXPECT_EQ(coefficients("  ice: {exchange_coefficient: 1.0e3, solid_exchange_coefficient: 5.0}\n"), (std::pair{1e3, 5.0}));
  expectMentions(errorOf(replaced(kFullScene, kIce, "  ice: {exchange_coefficient: strong}\n")),
                 {"cfdmpm.ice.exchange_coefficient", "strong", "a number"});
  expectMentions(errorOf(replaced(kFullScene, kIce, "  ice: {solid_exchange_coefficient: -1}\n")),
                 {"cfdmpm.ice.solid_exchange_coefficient", ">= 0"});
}

TEST_F(SceneTest, EnergyEquationWithSolidsIsRefusedWithTheScene)
{
  // The coupled step does not carry the solids' temperature: the fluid solver refuses it, and so
  // does the scene reader.
  expectMentions(errorOf(replaced(kFullScene, kIce, "  ice: {isothermal: false}\n")),
                 {"cfdmpm.ice.isothermal", "false", "sand"});
  EXPECT_NO_THROW(readScene(write(replaced(fluidsOnly(kFullScene), kIce, "  ice: {isothermal: false}\n"))));
}

TEST_F(SceneTest, SolidVolumeFromParticlesNeedsTheMonolithicImplicitPressure)
{
  // The particles' trial moves run inside the implicit pressure's outer iterations, and the
  // staggered coupling fixes the solids' motion before the pressure.
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {solid_volume: particles, coupling: staggered}\n")),
                 {"cfdmpm.mpm.solid_volume", "particles", "monolithic"});
  expectMentions(errorOf(replaced(replaced(kFullScene, "  mpm: {}\n", "  mpm: {solid_volume: particles}\n"), kIce,
                                  "  ice: {pressure: explicit}\n")),
                 {"cfdmpm.mpm.solid_volume", "particles", "implicit"});
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {solid_volume: nodes}\n")),
                 {"cfdmpm.mpm.solid_volume", "nodes", "faces", "particles"});
  EXPECT_NO_THROW(readScene(write(replaced(kFullScene, "  mpm: {}\n", "  mpm: {solid_volume: particles}\n"))));
  // Particle steps inside the fluids' step need the monolithic coupling and the solids' volume from
  // their face velocities.
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {substeps: 4, coupling: staggered}\n")),
                 {"cfdmpm.mpm.substeps", "4", "monolithic"});
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {substeps: 4, solid_volume: particles}\n")),
                 {"cfdmpm.mpm.substeps", "4", "faces"});
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {substeps: 0}\n")), {"cfdmpm.mpm.substeps", "0"});
  EXPECT_NO_THROW(readScene(write(replaced(kFullScene, "  mpm: {}\n", "  mpm: {substeps: 4}\n"))));
}

TEST_F(SceneTest, HydrostaticWithGravityOffAxisIsRefusedWithTheScene)
{
  std::string text = replaced(kFullScene, "hydrostatic: false", "hydrostatic: true");
  text = replaced(text, "gravity: [0.0, -9.81]", "gravity: [1.0, -9.81]");
  expectMentions(errorOf(text), {"cfdmpm.initial_state.hydrostatic", "[1, -9.81]", "one axis"});
}

// --- Derived quantities --------------------------------------------------------------------------

TEST_F(SceneTest, BulkModulusThatMakesTheCompressibilityUnderflowIsRefused)
{
  const std::string text = replaced(fluidsOnly(kFullScene), "bulk_modulus: 2.15e9", "bulk_modulus: 1.0e308");
  expectMentions(errorOf(text), {"cfdmpm.materials.water.equation_of_state.bulk_modulus", "1e+308",
                                 "compressibility", "reference pressure"});
}

TEST_F(SceneTest, InitialPressureThatMakesTheCompressibilityUnderflowIsRefused)
{
  const std::string text = replaced(fluidsOnly(kFullScene), "pressure: 100000.0", "pressure: 1.0e308");
  expectMentions(errorOf(text), {"cfdmpm.initial_state.pressure", "1e+308", "compressibility"});
}

TEST_F(SceneTest, HydrostaticColumnThatOverflowsNamesGravity)
{
  // 1e300 m/s^2 over 1 m of water: the bottom pressure is ~1e303 Pa, where the compressibility of
  // air, 1/(1.4 p) = 7e-304 1/Pa, times 1e-12 and the cell volume 0.0025 underflows. dt_initial and
  // dt_min go down to 1e-160 and 1e-170 s so that the first step (g dt^2 = 1e-20 m) passes.
  std::string text = replaced(fluidsOnly(kFullScene), "hydrostatic: false", "hydrostatic: true");
  text = replaced(text, "gravity: [0.0, -9.81]", "gravity: [0.0, -1.0e300]");
  text = replaced(text, "dt_initial: 1.0e-4, dt_min: 1.0e-8", "dt_initial: 1.0e-160, dt_min: 1.0e-170");
  expectMentions(errorOf(text), {"cfdmpm.domain.gravity", "[0, -1e+300]", "hydrostatic column"});
}

TEST_F(SceneTest, GravityTooStrongForAnyTimeStepIsRefused)
{
  // -1e308 m/s^2: a body falls a 50 mm cell in ~2e-155 s, far below dt_min = 1e-8 s.
  const std::string message = errorOf(replaced(kFullScene, "gravity: [0.0, -9.81]", "gravity: [0.0, -1.0e308]"));
  expectMentions(message, {"cfdmpm.domain.gravity", "[0, -1e+308]", "dt_min", "at most"});
}

TEST_F(SceneTest, FirstStepThatMovesABodyMoreThanACellNamesDtInitial)
{
  // Cells of 0.25 mm in x: 9.81 m/s^2 x (0.01 s)^2 = 0.98 mm in the first step.
  std::string text = replaced(kFullScene, "cells: [20, 10]", "cells: [4000, 10]");
  text = replaced(text, "patch_cells: [10, 5]", "patch_cells: [100, 5]");
  text = replaced(text, "dt_initial: 1.0e-4", "dt_initial: 1.0e-2");
  text = replaced(text, "dt_max: 1.0e-3", "dt_max: 1.0e-2");
  expectMentions(errorOf(text), {"cfdmpm.time.dt_initial", "0.01", "more than a cell", "0.25 mm"});
}

TEST_F(SceneTest, SolidWaveSpeedThatOverflowsNamesTheModulus)
{
  const std::string message = errorOf(replaced(kFullScene, "youngs_modulus: 5.0e7", "youngs_modulus: 1.0e308"));
  expectMentions(message, {"cfdmpm.materials.sand.model.youngs_modulus", "1e+308", "wave speed"});
}

// --- The grid's size ---------------------------------------------------------------------------

TEST_F(SceneTest, PatchCountBeyond32BitsIsRefused)
{
  // 10^12 cells in patches of 10 x 5 cells: 2e10 patches, more than 2^31 - 1.
  const std::string message = errorOf(replaced(kFullScene, "cells: [20, 10]", "cells: [1000000, 1000000]"));
  expectMentions(message, {"cfdmpm.domain.cells", "[1000000, 1000000]", "2e+10 patches", "[10, 5]",
                           "2147483647"});
}

TEST_F(SceneTest, MemoryEstimateNamesCellsAndParticles)
{
  const Scene scene = readScene(write(kFullScene));
  const MemoryEstimate estimate = estimateMemory(scene);
  EXPECT_EQ(estimate.cells, 200);
  // The solid regions' particles: the block's 72 and the wedge's.
  const std::vector<RegionPlacement> placements = regionPlacements(scene);
  EXPECT_EQ(estimate.particles, placements[1].points + placements[2].points);
  expectMentions(estimate.detail, {"200 cells (domain.cells)", "3 materials", "particles"});
}

// --- The file before the YAML reader -------------------------------------------------------------

TEST_F(SceneTest, FileLargerThanTheBoundIsRefusedBeforeParsing)
{
  // 1 MiB + a comment line: refused by its size (the reader would take ~12 s per MB).
  const std::string message = errorOf(kFullScene + "# " + std::string(1 << 20, 'x') + "\n");
  expectMentions(message, {"scene.yaml", "bytes", "at most 1048576"});
}

TEST_F(SceneTest, BinaryFileIsRefusedWithoutPrintingItsBytes)
{
  const std::string binary = std::string("\x7f" "ELF\x02\x01\x01\0\0\0", 10) + "cfdmpm:\x01\xff\xfe";
  const std::string message = errorOf(binary);
  expectMentions(message, {"is not a text file", "byte 0"});
  EXPECT_EQ(message.find("ELF"), std::string::npos) << message;
}

TEST_F(SceneTest, NonAsciiCharacterIsNamedWithLineAndColumn)
{
  // Line 13 of kFullScene is "    water:"; the name becomes "wäter".
  const std::string message = errorOf(replaced(kFullScene, "    water:\n", "    w\xc3\xa4ter:\n"));
  expectMentions(message, {"scene.yaml:13:6:", "U+00E4", "not ASCII"});
}

TEST_F(SceneTest, NonAsciiCharactersInCommentsAreAccepted)
{
  const Scene scene = readScene(write(replaced(kFullScene, "# A scene for the tests", "# Barrage \xc3\xa9t\xc3\xa9, 5 \xc2\xb0" "C")));
  EXPECT_EQ(scene.title, "Test tank");
}

TEST_F(SceneTest, NegativeInfinityIsRefusedLikeInfinity)
{
  // .inf reads as a string and is refused as not a number; -.inf used to be a syntax error.
  expectMentions(errorOf(replaced(kFullScene, "viscosity: 1.0e-3", "viscosity: .inf")),
                 {"cfdmpm.materials.water.viscosity", "'.inf'", "expected a number"});
  expectMentions(errorOf(replaced(kFullScene, "viscosity: 1.0e-3", "viscosity: -.inf")),
                 {"scene.yaml:16:18:", "viscosity: got '-.inf'", "must be finite"});
  expectMentions(errorOf(replaced(kFullScene, "cfl: 0.4", "cfl: -.Inf")), {"cfl: got '-.Inf'", "must be finite"});
}

TEST_F(SceneTest, ValuesAreEchoedAsWritten)
{
  // In the file's spelling, not as the double it became (40.0, not 40).
  expectMentions(errorOf(replaced(kFullScene, "cfl: 0.4", "cfl: 40.0")), {"cfdmpm.time.cfl: got '40.0'; must be in (0, 1]"});
  expectMentions(errorOf(replaced(kFullScene, "viscosity: 1.0e-3", "viscosity: -1.50e-3")),
                 {"cfdmpm.materials.water.viscosity: got '-1.50e-3'; must be >= 0"});
  expectMentions(errorOf(replaced(kFullScene, "cells: [20, 10]", "cells: [20.0, 10]")),
                 {"cfdmpm.domain.cells: got '[20.0, 10]' (a list of numbers)"});
  // Beyond the range of a double, with what it became.
  expectMentions(errorOf(replaced(kFullScene, "end_time: 0.5", "end_time: 1e-400")),
                 {"cfdmpm.time.end_time: got '1e-400' (read as 0: beyond the range of a double); must be > 0"});
}

TEST_F(SceneTest, RepeatedKeyIsNamedWithItsLine)
{
  // Teuchos's reader said 'Parameter "viscosity" already exists in list "ANONYMOUS"' at the next line.
  const std::string block =
      errorOf(replaced(kFullScene, "      viscosity: 1.0e-3\n", "      viscosity: 1.0e-3\n      viscosity: 2.0e-3\n"));
  expectMentions(block, {"scene.yaml:17:7: key 'viscosity' of cfdmpm.materials.water given twice (first on line 16)"});
  EXPECT_EQ(block.find("ANONYMOUS"), std::string::npos) << block;
  expectMentions(errorOf(replaced(kFullScene, "cfl: 0.4,", "cfl: 0.4, cfl: 0.3,")),
                 {"scene.yaml:40:", "key 'cfl' of cfdmpm.time given twice (first on line 40)"});
  expectMentions(errorOf(replaced(kFullScene, "  mpm: {}\n", "  mpm: {}\n  time: {end_time: 1.0}\n")),
                 {"scene.yaml:44:3: key 'time' of cfdmpm given twice (first on line 40)"});
  expectMentions(errorOf(replaced(kFullScene, "    air:\n", "    water:\n")),
                 {"scene.yaml:19:5: key 'water' of cfdmpm.materials given twice (first on line 13)"});
}

TEST_F(SceneTest, NestingBeyondTheBoundIsRefusedBeforeParsing)
{
  std::string deep = "  mpm: ";
  for (int i = 0; i < 40; ++i) deep += "{a: ";
  deep += "1" + std::string(40, '}') + "\n";
  const std::string message = errorOf(replaced(kFullScene, "  mpm: {}\n", deep));
  expectMentions(message, {"scene.yaml:43:", "levels deep", "at most 32"});
}

}  // namespace
}  // namespace cfdmpm::test
