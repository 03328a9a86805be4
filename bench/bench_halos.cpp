// Halo sizes and balance of a scene's decomposition on many ranks, computed on one (doc/scaling.md):
// for each rank count P the grid is cut into patches of the given size and divided by
// partitionPatches, as a run on P ranks would (by cells, and by cells plus the particles' work),
// and for every rank: its cells, particles and work, its ghost cells (within domain.ghost_width,
// diagonals included, as Layout builds them) and the ranks that own them (its neighbours: one
// message each per halo exchange). Particles are seeded as the run seeds them (2-D), or for a 3-D
// extrusion of a 2-D scene, the 2-D lattice repeated in z.
//
// usage: bench_halos <scene.yaml> <particle work> <P>:<patch cells> ... [--depth <m> <cells in z>]
//        [--json <file>]
//   e.g. bench_halos input/rzadkiewicz.yaml 0.1 64:16 512:8 4096:4
#include "grid/decomposition.hpp"
#include "grid/layout.hpp"
#include "mpm/mpm_solver.hpp"

#include <Tpetra_Core.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

using namespace cfdmpm;

namespace {

struct RankFigures {
  double cells = 0, particles = 0, work = 0, ghosts = 0, neighbours = 0;
};

struct Summary {
  RankFigures most, mean;
  std::vector<RankFigures> ranks;
};

/// Particles in every cell of the 2-D scene's grid, seeded as MpmSolver seeds them.
std::vector<double> particlesPerCell(const Scene& scene, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  const Grid<2> grid(scene.domain);
  const auto layout = std::make_shared<const Layout<2>>(grid, partitionPatches(grid, 1), 1, comm);
  const mpm::MpmSolver<2> solver(scene, layout);
  const auto position = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), solver.particles().position);
  std::vector<double> count(std::size_t(grid.cellCount()), 0.0);
  for (int p = 0; p < solver.particles().count; ++p) {
    std::array<long long, 3> c{0, 0, 0};
    for (int d = 0; d < 2; ++d)
      c[d] = std::clamp<long long>((long long)std::floor((position(p, d) - grid.lower()[d]) / grid.spacing()[d]), 0,
                                   grid.cells()[d] - 1);
    count[std::size_t(grid.cellId(c))] += 1;
  }
  return count;
}

template <int Dim>
Summary measure(const Grid<Dim>& grid, const Decomposition& decomposition, const std::vector<double>& particles,
                double particle_work, int ghost_width)
{
  const int ranks = decomposition.ranks;
  std::vector<RankFigures> figures(ranks);
  std::vector<std::vector<int>> patches_of(ranks);
  for (int p = 0; p < grid.patchCount(); ++p) {
    const int r = decomposition.patch_owner[p];
    patches_of[r].push_back(p);
    figures[r].cells += double(grid.patchCells(p).count());
    figures[r].particles += particles[p];
    figures[r].work += double(grid.patchCells(p).count()) + particle_work * particles[p];
  }
  const auto& patch_cells = grid.patchCells(0);
  auto ownerOf = [&](const std::array<long long, 3>& c) {
    std::array<long long, 3> q{0, 0, 0};
    for (int d = 0; d < Dim; ++d) q[d] = c[d] / patch_cells.extent(d);
    return decomposition.patch_owner[grid.patchId(q)];
  };
  std::vector<long long> ghosts;
  for (int r = 0; r < ranks; ++r) {
    ghosts.clear();
    std::set<int> neighbours;
    for (int p : patches_of[r]) {
      const Box own = grid.patchCells(p);
      Box shell = own;
      for (int d = 0; d < Dim; ++d) {
        shell.lower[d] = std::max(0LL, own.lower[d] - ghost_width);
        shell.upper[d] = std::min(grid.cells()[d], own.upper[d] + ghost_width);
      }
      for (long long k = shell.lower[2]; k < shell.upper[2]; ++k)
        for (long long j = shell.lower[1]; j < shell.upper[1]; ++j)
          for (long long i = shell.lower[0]; i < shell.upper[0]; ++i) {
            const std::array<long long, 3> c{i, j, k};
            if (own.contains(c)) continue;
            const int owner = ownerOf(c);
            if (owner == r) continue;
            ghosts.push_back(grid.cellId(c));
            neighbours.insert(owner);
          }
    }
    std::sort(ghosts.begin(), ghosts.end());
    figures[r].ghosts = double(std::unique(ghosts.begin(), ghosts.end()) - ghosts.begin());
    figures[r].neighbours = double(neighbours.size());
  }
  Summary s;
  s.ranks = figures;
  for (const RankFigures& f : figures) {
    s.most.cells = std::max(s.most.cells, f.cells), s.mean.cells += f.cells / ranks;
    s.most.particles = std::max(s.most.particles, f.particles), s.mean.particles += f.particles / ranks;
    s.most.work = std::max(s.most.work, f.work), s.mean.work += f.work / ranks;
    s.most.ghosts = std::max(s.most.ghosts, f.ghosts), s.mean.ghosts += f.ghosts / ranks;
    s.most.neighbours = std::max(s.most.neighbours, f.neighbours), s.mean.neighbours += f.neighbours / ranks;
  }
  return s;
}

template <int Dim>
void run(const Scene& scene, const std::vector<double>& particles_2d, double particle_work,
         const std::vector<std::pair<int, long long>>& cases, long long cells_z, double depth, int particles_per_cell_z,
         std::FILE* json)
{
  bool first = true;
  for (const auto& [ranks, patch] : cases) {
    std::array<double, 3> upper = scene.domain.upper;
    std::array<long long, 3> cells = scene.domain.cells;
    if (Dim == 3) upper[2] = depth, cells[2] = cells_z;
    const Grid<Dim> grid(scene.domain.lower, upper, cells, {patch, patch, patch});
    // Particles per patch: the 2-D counts of the patch's cells (x the lattice in z in 3-D).
    std::vector<double> particles(grid.patchCount(), 0.0);
    const long long nx = scene.domain.cells[0];
    for (int p = 0; p < grid.patchCount(); ++p) {
      const Box b = grid.patchCells(p);
      double column = 0;
      for (long long j = b.lower[1]; j < b.upper[1]; ++j)
        for (long long i = b.lower[0]; i < b.upper[0]; ++i) column += particles_2d[std::size_t(i + nx * j)];
      particles[p] = Dim == 3 ? column * double(b.extent(2)) * particles_per_cell_z : column;
    }
    const PatchWork work = patchWork(grid, std::vector<long long>(particles.begin(), particles.end()), particle_work);
    for (int weighted = 0; weighted < 2; ++weighted) {
      const Decomposition decomposition = weighted ? partitionPatches(grid, ranks, work) : partitionPatches(grid, ranks);
      const Summary s = measure(grid, decomposition, particles, particle_work, scene.domain.ghost_width);
      std::printf("%5d ranks, patches %3lld^%d (%6d): by %-15s cells %9.0f (%9.0f)  particles %9.0f (%9.0f)  "
                  "imbalance %5.3f  ghosts %7.0f (%7.0f)  neighbours %3.0f (%4.1f)\n",
                  ranks, patch, Dim, grid.patchCount(), weighted ? "cells+particles" : "cells", s.most.cells,
                  s.mean.cells, s.most.particles, s.mean.particles, loadImbalance(decomposition, work), s.most.ghosts,
                  s.mean.ghosts, s.most.neighbours, s.mean.neighbours);
      if (json) {
        std::fprintf(json,
                     "%s  {\"dimension\": %d, \"ranks\": %d, \"patch\": %lld, \"weights\": \"%s\", \"cells\": [%.0f, %.6g], "
                     "\"particles\": [%.0f, %.6g], \"work\": [%.6g, %.6g], \"ghosts\": [%.0f, %.6g], "
                     "\"neighbours\": [%.0f, %.6g], \"per_rank\": [",
                     first ? "" : ",\n", Dim, ranks, patch, weighted ? "cells+particles" : "cells", s.most.cells,
                     s.mean.cells, s.most.particles, s.mean.particles, s.most.work, s.mean.work, s.most.ghosts,
                     s.mean.ghosts, s.most.neighbours, s.mean.neighbours);
        // Every rank's cells, particles, ghosts and neighbours, for per-phase maxima.
        for (std::size_t r = 0; r < s.ranks.size(); ++r)
          std::fprintf(json, "%s[%.0f, %.0f, %.0f, %.0f]", r ? ", " : "", s.ranks[r].cells, s.ranks[r].particles,
                       s.ranks[r].ghosts, s.ranks[r].neighbours);
        std::fprintf(json, "]}");
      }
      first = false;
    }
  }
}

}  // namespace

int main(int argc, char** argv)
{
  Tpetra::ScopeGuard guard(&argc, &argv);
  if (argc < 4) {
    std::fprintf(stderr, "usage: bench_halos <scene.yaml> <particle work> <P>:<patch> ... [--depth <m> <cells in z>] "
                         "[--json <file>]\n");
    return 2;
  }
  const Scene scene = readScene(argv[1]);
  const double particle_work = std::atof(argv[2]);
  std::vector<std::pair<int, long long>> cases;
  double depth = 0;
  long long cells_z = 0;
  std::FILE* json = nullptr;
  for (int a = 3; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--depth" && a + 2 < argc) {
      depth = std::atof(argv[a + 1]), cells_z = std::atoll(argv[a + 2]);
      a += 2;
    } else if (arg == "--json" && a + 1 < argc) {
      json = std::fopen(argv[++a], "w");
    } else {
      const std::size_t colon = arg.find(':');
      cases.emplace_back(std::atoi(arg.substr(0, colon).c_str()), std::atoll(arg.substr(colon + 1).c_str()));
    }
  }
  int particles_per_cell_z = 2;
  for (const MaterialSpec& m : scene.materials)
    if (m.kind == "solid" && m.parameters.isParameter("particles_per_cell"))
      particles_per_cell_z = m.parameters.get<int>("particles_per_cell");
  const std::vector<double> particles_2d = particlesPerCell(scene, Tpetra::getDefaultComm());
  double total = 0;
  for (double n : particles_2d) total += n;
  std::printf("%s: %lld x %lld cells, %.0f particles in 2-D; particle work %g cells\n", argv[1], scene.domain.cells[0],
              scene.domain.cells[1], total, particle_work);
  if (json) std::fprintf(json, "[\n");
  if (cells_z > 0)
    run<3>(scene, particles_2d, particle_work, cases, cells_z, depth, particles_per_cell_z, json);
  else
    run<2>(scene, particles_2d, particle_work, cases, 0, 0.0, 0, json);
  if (json) {
    std::fprintf(json, "\n]\n");
    std::fclose(json);
  }
  return 0;
}
