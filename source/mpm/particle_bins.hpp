#pragma once
// Particles grouped by tiles of grid cells, so that a particle-to-node scatter can run on several
// threads without atomics and without per-thread copies of the node arrays.
//
// Tiles are blocks of kTileCells^Dim cells, counted from the lowest node of the rank's node box
// (BoxLookup). A tile gets one of 2^Dim colours from the parity of its index in each direction.
// A particle's cell index is computed as in evaluateShape, and its stencil starts at most one node
// below that cell (uGIMP: floor(xi - l) with l <= 1/2) and reaches at most two nodes above it, so
// a tile of cells [a, a + kTileCells) per direction writes only nodes in [a - 1, a + kTileCells + 1].
// Tiles of one colour are at least one tile apart in some direction, so with kTileCells >= 3 their
// node sets are disjoint (4 or more leaves a margin): the tiles of one colour can run in parallel,
// each tile's particles one after the other on one thread, adding directly into the node view.
// Particles outside the box (an error raised elsewhere) go to the nearest edge tile; they write
// only nodes inside the box, which lie within that tile's reach too.
//
// Within a tile the particles are listed in ascending index order, so every node's sum is taken in
// the same order (colour by colour, ascending particle index) for any number of threads.
//
//   bins.build(particles, grid, lookup, chunks);  // host call; three passes over the particles
//   bins.forEachParticle(f);                      // f(p) for every particle, colour by colour
//
// A build may take a subset of the particles instead (their indices, ascending): forEachParticle
// then visits those alone.
#include "common/types.hpp"
#include "grid/geometry.hpp"
#include "grid/layout.hpp"
#include "mpm/particles.hpp"
#include "mpm/tensor.hpp"

#include <algorithm>

namespace cfdmpm::mpm {

template <int Dim>
class ParticleBins {
 public:
  /// Cells per tile and direction (at least 4, see above). Larger tiles re-read fewer nodes at
  /// their edges; smaller ones give more tiles per colour to share among threads. Measured on
  /// bench_mpm (2-D, 2 threads): 16 about 5 % faster than 8, 32 no faster than 16.
  static constexpr int kTileCells = Dim == 2 ? 16 : 8;
  static_assert(kTileCells >= 4, "tiles of one colour must not share nodes");

  /// Sorts the particles into tiles of the node box of `lookup`, with `chunks` parallel pieces of
  /// the particle range for the counting sort (the result does not depend on it). With
  /// `subset_count` >= 0 only the particles subset(0 .. subset_count - 1) (ascending) are sorted.
  void build(const Particles<Dim>& particles, const Grid<Dim>& grid, const BoxLookup& lookup, int chunks,
             const Kokkos::View<int*, MemorySpace>& subset = {}, int subset_count = -1)
  {
    chunks = std::max(1, chunks);
    tile_count_ = 1;
    for (int d = 0; d < Dim; ++d) {
      tiles_[d] = int((lookup.extent[d] + kTileCells - 1) / kTileCells);
      tile_count_ *= tiles_[d];
    }
    const bool every = subset_count < 0;
    const int n = every ? particles.count : subset_count;
    if (int(tile_.extent(0)) < n) {
      tile_ = Kokkos::View<int*, MemorySpace>(Kokkos::view_alloc(Kokkos::WithoutInitializing, "particle tile"),
                                              std::size_t(n) * 3 / 2 + 16);
      order_ = Kokkos::View<int*, MemorySpace>(Kokkos::view_alloc(Kokkos::WithoutInitializing, "particles by tile"),
                                               tile_.extent(0));
    }
    if (int(start_.extent(0)) < tile_count_ + 1)
      start_ = Kokkos::View<int*, MemorySpace>(Kokkos::view_alloc(Kokkos::WithoutInitializing, "tile start"),
                                               std::size_t(tile_count_) + 1);
    if (int(counts_.extent(0)) < chunks || int(counts_.extent(1)) < tile_count_)
      counts_ = Kokkos::View<int**, Kokkos::LayoutRight, MemorySpace>(
          Kokkos::view_alloc(Kokkos::WithoutInitializing, "tile counts per chunk"), std::size_t(chunks),
          std::size_t(tile_count_));

    const auto x = particles.position;
    const auto tile = tile_;
    const auto order = order_;
    const auto start = start_;
    const auto counts = counts_;
    const int tile_count = tile_count_;
    double origin[Dim], inv_h[Dim];
    long long lower[Dim];
    int tiles[Dim];
    for (int d = 0; d < Dim; ++d) {
      origin[d] = grid.lower()[d], inv_h[d] = 1.0 / grid.spacing()[d];
      lower[d] = lookup.lower[d], tiles[d] = tiles_[d];
    }
    const int per_chunk = (n + chunks - 1) / chunks;

    // 1. Each chunk of the particle range: the tile of every particle and the chunk's count per tile.
    Kokkos::parallel_for(
        "mpm::bins_count", Kokkos::RangePolicy<ExecutionSpace>(0, chunks), KOKKOS_LAMBDA(const int c) {
          for (int t = 0; t < tile_count; ++t) counts(c, t) = 0;
          const int end = math::min(n, (c + 1) * per_chunk);
          for (int i = c * per_chunk; i < end; ++i) {
            const int p = every ? i : subset(i);
            int t = 0;
            for (int d = Dim - 1; d >= 0; --d) {
              const double cell = math::floor((x(p, d) - origin[d]) * inv_h[d]);
              long long k = cell > -1.0e15 && cell < 1.0e15 ? static_cast<long long>(cell) - lower[d] : 0;
              k = k < 0 ? 0 : k / kTileCells;
              t = t * tiles[d] + int(k < tiles[d] ? k : tiles[d] - 1);
            }
            tile(i) = t;
            ++counts(c, t);
          }
        });

    // 2. Where each tile's list starts, and within it where each chunk's particles go.
    Kokkos::parallel_scan(
        "mpm::bins_offsets", Kokkos::RangePolicy<ExecutionSpace>(0, tile_count),
        KOKKOS_LAMBDA(const int t, int& offset, const bool final) {
          if (final) start(t) = offset;
          for (int c = 0; c < chunks; ++c) {
            const int count = counts(c, t);
            if (final) counts(c, t) = offset;
            offset += count;
          }
          if (final && t == tile_count - 1) start(tile_count) = offset;
        });

    // 3. Each chunk places its particles, in ascending order, after the earlier chunks' ones.
    Kokkos::parallel_for(
        "mpm::bins_place", Kokkos::RangePolicy<ExecutionSpace>(0, chunks), KOKKOS_LAMBDA(const int c) {
          const int end = math::min(n, (c + 1) * per_chunk);
          for (int i = c * per_chunk; i < end; ++i) order(counts(c, tile(i))++) = every ? i : subset(i);
        });
  }

  /// Calls f(p) once for every particle binned by the last build: the tiles of one colour in
  /// parallel (dynamic schedule: tiles hold different numbers of particles), each tile's particles
  /// in ascending order on one thread; colour after colour.
  template <class F>
  void forEachParticle(const F& f) const
  {
    const auto order = order_;
    const auto start = start_;
    for (int colour = 0; colour < (1 << Dim); ++colour) {
      int first[Dim], count[Dim], total = 1;
      for (int d = 0; d < Dim; ++d) {
        first[d] = (colour >> d) & 1;
        count[d] = tiles_[d] > first[d] ? (tiles_[d] - first[d] + 1) / 2 : 0;
        total *= count[d];
      }
      if (total == 0) continue;
      int tiles[Dim];
      for (int d = 0; d < Dim; ++d) tiles[d] = tiles_[d];
      Kokkos::parallel_for(
          "mpm::bins_colour", Kokkos::RangePolicy<ExecutionSpace, Kokkos::Schedule<Kokkos::Dynamic>>(0, total).set_chunk_size(1),
          KOKKOS_LAMBDA(const int k) {
            int t = 0, rest = k, stride = 1;
            for (int d = 0; d < Dim; ++d) {
              t += (first[d] + 2 * (rest % count[d])) * stride;
              rest /= count[d];
              stride *= tiles[d];
            }
            for (int i = start(t); i < start(t + 1); ++i) f(order(i));
          });
    }
  }

 private:
  int tiles_[Dim] = {};
  int tile_count_ = 0;
  Kokkos::View<int*, MemorySpace> tile_;    // tile of each particle (of the subset)
  Kokkos::View<int*, MemorySpace> order_;   // particle indices, tile by tile, ascending in a tile
  Kokkos::View<int*, MemorySpace> start_;   // where each tile's list starts in order_ (+ the end)
  Kokkos::View<int**, Kokkos::LayoutRight, MemorySpace> counts_;  // per chunk and tile
};

}  // namespace cfdmpm::mpm
