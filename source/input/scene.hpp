#pragma once
// A scene: everything one run needs, read from one YAML file and validated before the first step.
// The typed structs hold what the foundation (grid, output, time control) uses; each physics module
// reads its own, already validated, sublist from `parameters`.
#include "common/error.hpp"

#include <Teuchos_ParameterList.hpp>
#include <Teuchos_RCP.hpp>

#include <array>
#include <string>
#include <vector>

namespace cfdmpm {

struct DomainSpec {
  int dimension = 2;                          // 2 or 3
  std::array<double, 3> lower{0, 0, 0};       // m; unused dimensions 0
  std::array<double, 3> upper{1, 1, 1};       // m; unused dimensions 1
  std::array<long long, 3> cells{1, 1, 1};    // cells per direction; unused dimensions 1
  std::array<long long, 3> patch_cells{1, 1, 1};  // patch size in cells, at most `cells`; unused dimensions 1
  int ghost_width = 2;                        // ghost cell layers around each rank's cells
  std::array<double, 3> gravity{0, 0, 0};     // m/s^2
  int rebalance_interval = 0;                 // steps between decompositions with particle weights; 0 never
};

struct MaterialSpec {
  std::string name;
  std::string kind;                 // "fluid" (ICE) or "solid" (MPM)
  Teuchos::ParameterList parameters;  // the material's validated sublist
};

struct RegionSpec {
  std::string name;
  std::string material;
  std::string shape;                         // "box", "polygon", "half_plane"
  std::array<double, 3> lower{0, 0, 0};      // box
  std::array<double, 3> upper{0, 0, 0};      // box
  std::vector<std::array<double, 2>> vertices;  // polygon (2-D; extruded in z in 3-D)
  std::array<double, 3> point{0, 0, 0};      // half_plane: a point on the plane
  std::array<double, 3> normal{0, 0, 0};     // half_plane: outward unit normal (region is behind it)
  std::array<double, 3> velocity{0, 0, 0};   // m/s
  double temperature = 0;                    // K
};

struct BoundarySpec {
  std::string face;        // "x-", "x+", "y-", "y+", "z-", "z+"
  std::string velocity;    // "no_slip" or "free_slip"
  std::string temperature; // "zero_gradient" or "fixed"
  double temperature_value = 0;  // K, when temperature is "fixed"
};

struct TimeSpec {
  double end_time = 0;    // s
  double cfl = 0.25;
  double dt_initial = 1e-5;  // s
  double dt_min = 1e-10;     // s
  double dt_max = 1e-2;      // s
  long long max_steps = -1;  // -1: no limit
  int step_retries = 3;      // a failed step is undone and retried with half its Δt this many times
};

struct OutputSpec {
  std::string directory;          // created; never silently overwritten
  double interval = 0;            // s of simulated time between output steps; 0 = initial state only
  std::vector<std::string> fields;
  bool overwrite = false;
  double progress_interval = 1.0;  // s of wall time between progress lines
  double checkpoint_interval = 0;       // s of simulated time between checkpoints; 0 = none
  double checkpoint_wall_interval = 0;  // s of wall-clock time between checkpoints; 0 = none
  int checkpoints_kept = 2;             // the newest checkpoints kept; older ones are removed
};

struct InitialStateSpec {
  std::string background_material;  // fills every cell that no region claims
  double temperature = 293.15;      // K
  double pressure = 101325;         // Pa, at the top of the domain
  bool hydrostatic = true;          // integrate the pressure down from the top with the column's weight
};

/// The `mpm` section: settings of the particle solver (doc/mpm.md explains each).
struct MpmSpec {
  std::string shape_function = "gimp";  // gimp | linear
  double flip_fraction = 0.99;          // in [0, 1]
  std::string stress_update = "usl";    // usl | musl
  double wall_friction = 0.0;           // Coulomb coefficient at free_slip walls
  bool contact = true;                  // friction contact between solid materials
  double contact_friction = 0.0;        // Coulomb coefficient between solid materials
  double velocity_damping = 0.0;        // 1/s
  double face_layer = 0.125;            // cells: layer in which a solid's cover of a face is measured
  std::string coupling = "monolithic";  // monolithic | staggered (fluid-solid pressure coupling)
  std::string solid_volume = "faces";   // faces | particles (the solids' volume change in the pressure equation)
  int substeps = 1;                     // most particle steps in one step of the fluids
};

struct Scene {
  std::string path;
  std::string text;  // the file as read (a checkpoint keeps it, so that a restart needs no scene file)
  std::string title;
  DomainSpec domain;
  std::vector<MaterialSpec> materials;  // in file order; a material's index is its position here
  InitialStateSpec initial;
  std::vector<RegionSpec> regions;      // in file order; later regions overwrite earlier ones
  std::vector<BoundarySpec> boundaries; // one per face of the domain (4 in 2-D, 6 in 3-D)
  TimeSpec time;
  OutputSpec output;
  MpmSpec mpm;
  Teuchos::RCP<Teuchos::ParameterList> parameters;  // the whole validated list, defaults filled in

  int materialIndex(const std::string& name) const;  // throws InputError if unknown
};

/// The list of valid parameters with defaults and documentation; the single source of truth for
/// validation and for doc/input.md. Each entry carries a ParameterRule (input/parameter_rule.hpp).
/// The named-entry sections (materials, regions, boundary_conditions) are empty here: their entries
/// follow the templates below. `ice.linear_solver` is checked by the pressure solver.
Teuchos::RCP<const Teuchos::ParameterList> validSceneParameters();

/// Templates for named entries, one per value of their selector key (which each template holds):
/// a material of a `kind`, its `equation_of_state` or solid `model` of a `type`, a region of a
/// `shape`, one face of `boundary_conditions`. Throw std::invalid_argument for an unknown name.
Teuchos::RCP<const Teuchos::ParameterList> validMaterialParameters(const std::string& kind);
Teuchos::RCP<const Teuchos::ParameterList> validEquationOfStateParameters(const std::string& type);
Teuchos::RCP<const Teuchos::ParameterList> validSolidModelParameters(const std::string& type);
Teuchos::RCP<const Teuchos::ParameterList> validRegionParameters(const std::string& shape);
Teuchos::RCP<const Teuchos::ParameterList> validBoundaryParameters();

/// The names the selector keys allow, in documentation order.
const std::vector<std::string>& materialKinds();         // fluid, solid
const std::vector<std::string>& equationOfStateTypes();  // linear_water, ideal_gas, tait
const std::vector<std::string>& solidModelTypes();       // linear_elastic, neo_hookean, tresca, ...
const std::vector<std::string>& regionShapes();          // box, polygon, half_plane
const std::vector<std::string>& outputFieldNames();      // cell fields, then particle fields
std::vector<std::string> boundaryFaces(int dimension);   // x-, x+, y-, y+ (, z-, z+)

/// A solid's `interior_pressure` when the scene does not give it: "reference" for the plastic
/// models (tresca, drucker_prager), whose particles shear off their lattice, "cell" otherwise.
std::string defaultInteriorPressure(const std::string& model_type);

/// Reads and validates a scene file. Throws InputError (message: key, value, what is allowed) on
/// any problem; nothing is written before it returns.
Scene readScene(const std::string& path);

/// The same for a scene's text (`path` names it in messages and gives the run its name), e.g. the
/// scene a checkpoint keeps.
Scene readSceneText(const std::string& text, const std::string& path);

}  // namespace cfdmpm
