#pragma once
// The reference both benchmarks report against, timed in the same run: a memory-bound triad.
#include <Kokkos_Core.hpp>

#include <algorithm>
#include <chrono>

namespace cfdmpm::bench {

/// Seconds per pass of a = b + s c over n doubles (best of 5).
inline double triadSeconds(std::size_t n)
{
  Kokkos::View<double*> a("a", n), b("b", n), c("c", n);
  Kokkos::deep_copy(b, 1.0);
  Kokkos::deep_copy(c, 2.0);
  double best = 1e300;
  for (int r = 0; r < 5; ++r) {
    const auto start = std::chrono::steady_clock::now();
    Kokkos::parallel_for("triad", n, KOKKOS_LAMBDA(const std::size_t i) { a(i) = b(i) + 0.5 * c(i); });
    Kokkos::fence();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

}  // namespace cfdmpm::bench
