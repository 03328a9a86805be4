// Every scene shipped in input/ is valid, and the three reference scenes say what they claim.
#include "input/scene.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace cfdmpm::test {
namespace {

const std::filesystem::path kInputDirectory = std::filesystem::path(CFDMPM_SOURCE_DIR) / "input";

TEST(SceneFiles, EveryShippedSceneIsValid)
{
  int scenes = 0;
  for (const auto& file : std::filesystem::directory_iterator(kInputDirectory)) {
    if (file.path().extension() != ".yaml") continue;
    ++scenes;
    EXPECT_NO_THROW({
      try {
        readScene(file.path().string());
      } catch (const InputError& error) {
        ADD_FAILURE() << error.what();
        throw;
      }
    }) << file.path();
  }
  EXPECT_GE(scenes, 3);
}

TEST(SceneFiles, DamBreakIsMartinAndMoyceColumnInATank)
{
  const Scene scene = readScene((kInputDirectory / "dam-break.yaml").string());
  EXPECT_EQ(scene.domain.upper[0], 0.5);
  EXPECT_EQ(scene.domain.upper[1], 0.2);
  EXPECT_EQ(scene.domain.cells[0], 200);  // 2.5 mm cells
  EXPECT_EQ(scene.domain.cells[1], 80);
  EXPECT_EQ(scene.domain.gravity[1], -9.81);
  ASSERT_EQ(scene.regions.size(), 1u);
  EXPECT_EQ(scene.regions[0].material, "water");
  EXPECT_EQ(scene.regions[0].lower, (std::array<double, 3>{0.0, 0.0, 0.0}));
  EXPECT_EQ(scene.regions[0].upper, (std::array<double, 3>{0.05715, 0.1143, 0.0}));
  EXPECT_EQ(scene.initial.background_material, "air");
  for (const auto& face : scene.boundaries) EXPECT_EQ(face.velocity, "no_slip") << face.face;
  EXPECT_EQ(scene.time.end_time, 0.25);
  EXPECT_EQ(scene.output.interval, 0.01);
  EXPECT_EQ(scene.output.directory, "output/dam-break");
  const auto& air = scene.materials.at(scene.materialIndex("air")).parameters;
  // Air at 101325 Pa and 293.15 K: rho = p / (R T) = 1.204 kg/m^3.
  EXPECT_NEAR(101325.0 / (air.sublist("equation_of_state").get<double>("gas_constant") * scene.initial.temperature),
              1.204, 5e-4);
}

TEST(SceneFiles, RzadkiewiczSlideHasBedSandWaterAndAir)
{
  const Scene scene = readScene((kInputDirectory / "rzadkiewicz.yaml").string());
  EXPECT_EQ(scene.domain.lower, (std::array<double, 3>{-2.02, -0.04, 0.0}));
  EXPECT_EQ(scene.domain.upper, (std::array<double, 3>{1.5, 1.8, 1.0}));
  EXPECT_EQ(scene.domain.cells, (std::array<long long, 3>{352, 184, 1}));  // cell_size: 10 mm
  ASSERT_EQ(scene.materials.size(), 4u);
  EXPECT_EQ(scene.materials[scene.materialIndex("bed")].parameters.sublist("model").get<std::string>("type"), "rigid");
  const auto& sand = scene.materials[scene.materialIndex("sand")].parameters;
  EXPECT_EQ(sand.get<double>("density"), 1985.0);
  EXPECT_EQ(sand.sublist("model").get<double>("yield_stress"), 200.0);
  EXPECT_EQ(sand.get<int>("particles_per_cell"), 2);
  const auto& water = scene.materials[scene.materialIndex("water")].parameters;
  EXPECT_EQ(water.sublist("equation_of_state").get<double>("bulk_modulus"), 2.15e9);
  EXPECT_EQ(water.get<double>("viscosity"), 855e-6);
  ASSERT_EQ(scene.regions.size(), 3u);
  EXPECT_EQ(scene.regions[0].shape, "half_plane");
  EXPECT_EQ(scene.regions[0].point[1], 1.6);
  EXPECT_EQ(scene.regions[1].vertices.size(), 6u);
  EXPECT_EQ(scene.regions[2].vertices[2], (std::array<double, 2>{-1.486, 1.5}));
  EXPECT_EQ(scene.initial.temperature, 278.15);
  EXPECT_EQ(scene.time.end_time, 0.8);
  EXPECT_EQ(scene.output.interval, 0.05);
}

}  // namespace
}  // namespace cfdmpm::test
