#include "grid/decomposition.hpp"

#include <metis.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>

namespace cfdmpm {

namespace {

// METIS wants integer vertex weights, interleaved per vertex for several constraints. Each
// constraint is scaled so that its lightest nonzero patch weighs ~1000 units, which keeps the
// rounding error of a weight below 0.1 %; idx_t is 32-bit, so each total stays below 2^30 / ncon.
// The first constraint's weights are at least 1 (every patch has cells); the others may be 0.
std::vector<idx_t> integerWeights(const std::vector<std::vector<double>>& constraints)
{
  const std::size_t ncon = constraints.size(), n = constraints.front().size();
  std::vector<idx_t> w(n * ncon);
  for (std::size_t c = 0; c < ncon; ++c) {
    const std::vector<double>& weight = constraints[c];
    double smallest = INFINITY;
    for (double x : weight)
      if (x > 0) smallest = std::min(smallest, x);
    const double total = std::accumulate(weight.begin(), weight.end(), 0.0);
    const double scale = std::min(1000.0 / smallest, double(1 << 30) / double(ncon) / total);
    for (std::size_t i = 0; i < n; ++i)
      w[i * ncon + c] = std::max<idx_t>(c == 0 ? 1 : 0, idx_t(std::llround(weight[i] * scale)));
  }
  return w;
}

}  // namespace

namespace {

/// METIS on the patch graph with one weight per patch and constraint, each constraint balanced on
/// its own. The first constraint's weights are > 0, the others' >= 0 with a positive total.
template <int Dim>
Decomposition partition(const Grid<Dim>& grid, int ranks, const std::vector<std::vector<double>>& constraints)
{
  const int patches = grid.patchCount();
  if (ranks < 1) throw std::invalid_argument("partitionPatches: ranks must be >= 1");
  if (patches < ranks)
    throw InputError("domain.patch_cells: the grid has " + std::to_string(patches) +
                     " patches for " + std::to_string(ranks) +
                     " ranks; every rank needs at least one patch: choose smaller patches or fewer ranks");
  for (std::size_t c = 0; c < constraints.size(); ++c) {
    if (int(constraints[c].size()) != patches)
      throw std::invalid_argument("partitionPatches: one weight per patch is needed");
    for (double w : constraints[c])
      if (!(c == 0 ? w > 0 : w >= 0)) throw std::invalid_argument("partitionPatches: patch weights must be > 0");
    if (!(std::accumulate(constraints[c].begin(), constraints[c].end(), 0.0) > 0))
      throw std::invalid_argument("partitionPatches: a constraint without weight");
  }

  Decomposition result;
  result.ranks = ranks;
  result.patch_owner.assign(patches, 0);
  if (ranks == 1) return result;

  // Patch graph in CSR form: face neighbours, edge weight = cells on the shared face.
  std::vector<idx_t> xadj{0}, adjncy, adjwgt;
  const auto counts = grid.patchCounts();
  for (int p = 0; p < patches; ++p) {
    const auto pijk = grid.patchIndex(p);
    const Box cells = grid.patchCells(p);
    for (int d = 0; d < Dim; ++d) {
      for (int side : {-1, 1}) {
        auto q = pijk;
        q[d] += side;
        if (q[d] < 0 || q[d] >= counts[d]) continue;
        adjncy.push_back(grid.patchId(q));
        adjwgt.push_back(idx_t(cells.count() / cells.extent(d)));
      }
    }
    xadj.push_back(idx_t(adjncy.size()));
  }

  std::vector<idx_t> vwgt = integerWeights(constraints);
  idx_t nvtxs = patches, ncon = idx_t(constraints.size()), nparts = ranks, objval = 0;
  std::vector<idx_t> part(patches, 0);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;  // same answer on every rank and every run
  options[METIS_OPTION_NUMBERING] = 0;
  // Recursive bisection balances better for few parts; k-way is the choice for many.
  const int status = ranks <= 8
      ? METIS_PartGraphRecursive(&nvtxs, &ncon, xadj.data(), adjncy.data(), vwgt.data(), nullptr,
                                 adjwgt.data(), &nparts, nullptr, nullptr, options, &objval, part.data())
      : METIS_PartGraphKway(&nvtxs, &ncon, xadj.data(), adjncy.data(), vwgt.data(), nullptr,
                            adjwgt.data(), &nparts, nullptr, nullptr, options, &objval, part.data());
  if (status != METIS_OK)
    throw std::runtime_error("METIS failed to partition " + std::to_string(patches) +
                             " patches into " + std::to_string(ranks) + " parts (status " +
                             std::to_string(status) + ")");
  for (int p = 0; p < patches; ++p) result.patch_owner[p] = int(part[p]);

  // Every rank must own something; METIS can leave a part empty on tiny graphs.
  std::vector<int> owned(ranks, 0);
  for (int r : result.patch_owner) ++owned[r];
  for (int r = 0; r < ranks; ++r)
    if (owned[r] == 0)
      throw InputError("domain.patch_cells: METIS left rank " + std::to_string(r) +
                       " without patches; choose smaller patches");
  return result;
}

}  // namespace

template <int Dim>
Decomposition partitionPatches(const Grid<Dim>& grid, int ranks, const std::vector<double>& patch_weight)
{
  if (!patch_weight.empty()) return partition(grid, ranks, {patch_weight});
  std::vector<double> cells(grid.patchCount());
  for (int p = 0; p < grid.patchCount(); ++p) cells[p] = double(grid.patchCells(p).count());
  return partition(grid, ranks, {cells});
}

template <int Dim>
Decomposition partitionPatches(const Grid<Dim>& grid, int ranks, const PatchWork& work)
{
  if (!(std::accumulate(work.particles.begin(), work.particles.end(), 0.0) > 0)) return partition(grid, ranks, {work.cells});
  try {
    return partition(grid, ranks, {work.cells, work.particles});
  } catch (const InputError&) {
    // With few patches per rank METIS may find no division that balances both and leave a rank
    // without patches: then the total work is balanced.
    return partition(grid, ranks, {work.total()});
  }
}

std::vector<double> rankLoads(const Decomposition& decomposition, const std::vector<double>& patch_weight)
{
  std::vector<double> load(decomposition.ranks, 0.0);
  for (std::size_t p = 0; p < decomposition.patch_owner.size(); ++p)
    load[decomposition.patch_owner[p]] += patch_weight[p];
  return load;
}

Decomposition closestNumbering(const Decomposition& division, const Decomposition& current,
                               const std::vector<double>& patch_weight)
{
  if (division.ranks != current.ranks || division.patch_owner.size() != current.patch_owner.size())
    throw std::invalid_argument("closestNumbering: the divisions differ in ranks or patches");
  // The work each (new part, current rank) pair shares, for the pairs that share any.
  std::map<std::pair<int, int>, double> shared;
  for (std::size_t p = 0; p < division.patch_owner.size(); ++p)
    shared[{division.patch_owner[p], current.patch_owner[p]}] += patch_weight[p];
  std::vector<std::pair<std::pair<int, int>, double>> pairs(shared.begin(), shared.end());
  std::stable_sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  const int ranks = division.ranks;
  std::vector<int> rank_of_part(ranks, -1);
  std::vector<bool> taken(ranks, false);
  for (const auto& [pair, work] : pairs)
    if (rank_of_part[pair.first] < 0 && !taken[pair.second]) {
      rank_of_part[pair.first] = pair.second;
      taken[pair.second] = true;
    }
  // Parts that share nothing with a free rank take the free ranks in order.
  int next_free = 0;
  for (int part = 0; part < ranks; ++part)
    if (rank_of_part[part] < 0) {
      while (taken[next_free]) ++next_free;
      rank_of_part[part] = next_free;
      taken[next_free] = true;
    }
  Decomposition renumbered = division;
  for (int& owner : renumbered.patch_owner) owner = rank_of_part[owner];
  return renumbered;
}

double loadImbalance(const std::vector<double>& load)
{
  const double mean = std::accumulate(load.begin(), load.end(), 0.0) / double(load.size());
  return mean > 0 ? *std::max_element(load.begin(), load.end()) / mean - 1.0 : 0.0;
}

template <int Dim>
PatchWork patchWork(const Grid<Dim>& grid, const std::vector<long long>& particles, double particle_work,
                    const std::vector<long long>& closed)
{
  PatchWork work;
  work.cells.resize(grid.patchCount());
  work.particles.assign(grid.patchCount(), 0.0);
  for (int p = 0; p < grid.patchCount(); ++p) {
    const double shut = closed.empty() ? 0.0 : double(closed[p]);
    // At least one cell's work, so that METIS's first constraint stays positive.
    work.cells[p] = std::max(1.0, double(grid.patchCells(p).count()) - (1.0 - kClosedCellWork) * shut);
    if (!particles.empty()) work.particles[p] = particle_work * double(particles[p]);
  }
  return work;
}

double loadImbalance(const Decomposition& decomposition, const PatchWork& work)
{
  const std::vector<double> cells = rankLoads(decomposition, work.cells);
  const std::vector<double> particles = rankLoads(decomposition, work.particles);
  const double ranks = double(decomposition.ranks);
  const double balanced = (std::accumulate(cells.begin(), cells.end(), 0.0) +
                           std::accumulate(particles.begin(), particles.end(), 0.0)) / ranks;
  const double slowest = *std::max_element(cells.begin(), cells.end()) +
                         *std::max_element(particles.begin(), particles.end());
  return balanced > 0 ? slowest / balanced - 1.0 : 0.0;
}

template <int Dim>
Redivision divideAgain(const Grid<Dim>& grid, const Decomposition& current, const PatchWork& work, double gain)
{
  Redivision result;
  result.decomposition = current;
  result.imbalance_before = result.imbalance_after = loadImbalance(current, work);
  Decomposition balanced;
  try {
    balanced = closestNumbering(partitionPatches(grid, current.ranks, work), current, work.total());
  } catch (const InputError&) {
    return result;  // METIS left a rank without patches: stay
  }
  const double imbalance = loadImbalance(balanced, work);
  if (!(imbalance < result.imbalance_before - gain)) return result;
  result.decomposition = balanced;
  result.imbalance_after = imbalance;
  return result;
}

template Decomposition partitionPatches<2>(const Grid<2>&, int, const std::vector<double>&);
template Decomposition partitionPatches<3>(const Grid<3>&, int, const std::vector<double>&);
template Decomposition partitionPatches<2>(const Grid<2>&, int, const PatchWork&);
template Decomposition partitionPatches<3>(const Grid<3>&, int, const PatchWork&);
template Redivision divideAgain(const Grid<2>&, const Decomposition&, const PatchWork&, double);
template Redivision divideAgain(const Grid<3>&, const Decomposition&, const PatchWork&, double);
template PatchWork patchWork(const Grid<2>&, const std::vector<long long>&, double, const std::vector<long long>&);
template PatchWork patchWork(const Grid<3>&, const std::vector<long long>&, double, const std::vector<long long>&);

}  // namespace cfdmpm
