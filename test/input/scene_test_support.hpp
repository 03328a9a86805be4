#pragma once
// Support for the scene tests: a scene written into a fresh temporary directory, text edits that
// fail loudly when their target is missing, and a check that readScene refuses a scene with a
// message holding given pieces (key path, bad value, allowed values).
#include "input/scene.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace cfdmpm::test {

/// Each test writes its scene files into its own directory, removed afterwards.
class SceneTest : public ::testing::Test {
 protected:
  void SetUp() override
  {
    directory_ = std::filesystem::temp_directory_path() /
                 ("cfdmpm-input-" + std::to_string(::getpid()) + "-" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  std::string write(const std::string& text, const std::string& name = "scene.yaml")
  {
    const auto path = directory_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  /// The message of the InputError readScene throws for `text`; a test failure if it throws none.
  std::string errorOf(const std::string& text)
  {
    try {
      readScene(write(text));
    } catch (const InputError& error) {
      return error.what();
    }
    ADD_FAILURE() << "readScene accepted a bad scene:\n" << text;
    return "";
  }

  std::filesystem::path directory_;
};

/// `text` with the single occurrence of `from` replaced by `to`.
inline std::string replaced(const std::string& text, const std::string& from, const std::string& to)
{
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' is not in the scene";
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "'" << from << "' is in the scene twice";
  if (at == std::string::npos) return text;
  return text.substr(0, at) + to + text.substr(at + from.size());
}

/// Every piece must appear in the message.
inline void expectMentions(const std::string& message, const std::vector<std::string>& pieces)
{
  for (const auto& piece : pieces) EXPECT_NE(message.find(piece), std::string::npos) << "'" << piece << "' is not in: " << message;
}

/// A scene that uses every section and every struct field; tests break one thing in it at a time.
inline const std::string kFullScene = R"(# A scene for the tests
cfdmpm:
  title: "Test tank"
  domain:
    dimension: 2
    lower: [0.0, -0.5]
    upper: [1.0, 0.5]
    cells: [20, 10]
    patch_cells: [10, 5]
    ghost_width: 3
    gravity: [0.0, -9.81]
  materials:
    water:
      kind: fluid
      equation_of_state: {type: linear_water, bulk_modulus: 2.15e9, reference_density: 999.8, reference_pressure: 101000.0, reference_temperature: 278.15, thermal_expansion: 0.18}
      viscosity: 1.0e-3
      specific_heat: 4200.0
      thermal_conductivity: 0.6
    air:
      kind: fluid
      equation_of_state: {type: ideal_gas, gas_constant: 287.0, gamma: 1.4}
      viscosity: 1.8e-5
    sand:
      kind: solid
      density: 1985.0
      model: {type: tresca, youngs_modulus: 5.0e7, poisson_ratio: 0.25, yield_stress: 200.0}
      particles_per_cell: 3
  initial_state:
    background_material: air
    temperature: 280.0
    pressure: 100000.0
    hydrostatic: false
  regions:
    pool: {material: water, shape: half_plane, point: [0.0, 0.1], normal: [0.0, 2.0]}
    block: {material: sand, shape: box, lower: [0.2, -0.5], upper: [0.4, -0.3], velocity: [0.5, -0.25], temperature: 285.0}
    wedge: {material: sand, shape: polygon, vertices: [[0.6, -0.5], [0.9, -0.5], [0.9, -0.2]]}
  boundary_conditions:
    x-: {velocity: free_slip, temperature: fixed, temperature_value: 290.0}
    y+: {velocity: free_slip}
  time: {end_time: 0.5, cfl: 0.4, dt_initial: 1.0e-4, dt_min: 1.0e-8, dt_max: 1.0e-3, max_steps: 1000}
  output: {directory: out/test, interval: 0.1, fields: [velocity, pressure, particle_stress], overwrite: true, progress_interval: 5.0}
  ice: {outer_tolerance: 1.0e-9, solver_tolerance: 1.0e-11, linear_solver: {verbosity: 1}}
  mpm: {}
)";

/// The least a scene must say; every other key takes its default. Numbers are written as integers.
inline const std::string kMinimalScene = R"(cfdmpm:
  domain:
    dimension: 2
    lower: [0, 0]
    upper: [1, 2]
    cells: [40, 10]
    gravity: [0, -10]
  materials:
    air:
      kind: fluid
      equation_of_state: {type: ideal_gas}
      viscosity: 0
  initial_state: {background_material: air}
  time: {end_time: 1}
  output: {directory: out, interval: 0}
)";

}  // namespace cfdmpm::test
