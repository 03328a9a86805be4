#pragma once
// Checks of a scene as a whole, after every key has passed its own rule: what the regions place,
// the settings the solvers check when they are built, derived quantities (sound speed,
// compressibility, the first time step) and the size of the run. readScene runs the scene-only
// ones, so `cfdmpm --check` and a run refuse the same scenes; checkSetUp adds the ones that depend
// on the ranks and the machine (patches per rank, memory, the output directory).
#include "input/scene.hpp"

#include <Teuchos_Comm.hpp>

#include <string>
#include <vector>

namespace cfdmpm {

/// What one region places on its own (later regions that overwrite it not counted): the points of
/// the run's sampling lattice inside it. A fluid region's cells are sampled on a 4 x 4 (x 4)
/// lattice per cell (the initial state's volume fractions); a solid region's points are its
/// particles, particles_per_cell per direction per cell.
struct RegionPlacement {
  std::string region;
  std::string material;
  bool solid = false;
  int per_direction = 4;  // lattice points per cell and direction
  double points = 0;      // lattice points inside the region; -1 when too many to count
  double cells = 0;       // points / per_direction^dimension: the cells' worth it fills
};

/// The placements of every region, in file order.
std::vector<RegionPlacement> regionPlacements(const Scene& scene);

/// The checks of the scene as a whole (see above); throws InputError naming the key. Called by
/// readScene.
void checkSceneAsAWhole(const Scene& scene);

/// Bytes a run of the scene needs, estimated from measured peak memory per cell and per particle
/// (see scene_checks.cpp), and what it is made of, for messages.
struct MemoryEstimate {
  double bytes = 0;
  double cells = 0;
  double particles = 0;
  std::string detail;
};
MemoryEstimate estimateMemory(const Scene& scene);

/// The set-up checks that depend on the ranks and the machine, in the order a run meets them:
/// memory (the estimate against the physical memory of the nodes the ranks run on), the patches
/// for the ranks, the output directory (refused as prepareOutputDirectory would, nothing created).
/// Collective; throws InputError on every rank.
void checkSetUp(const Scene& scene, const Teuchos::RCP<const Teuchos::Comm<int>>& comm, bool overwrite);

}  // namespace cfdmpm
