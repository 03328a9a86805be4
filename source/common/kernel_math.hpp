#pragma once
// Device-safe math for Kokkos kernels, shared by the fluid (ice/) and particle (mpm/) solvers.
//
// min and max are a comparison the compiler inlines. Kokkos's fmin and fmax are calls into the C
// library on the Serial back end at -O3 (GCC does not inline them for their NaN rules); in the ICE
// solver's face kernels those calls cost 16 % of the fluids' face fractions (doc/mpmice.md, "Cost").
// Unlike fmin / fmax, a NaN in the first argument is dropped and one in the second passed on.
#include <Kokkos_Core.hpp>

namespace cfdmpm::math {

// Kokkos 3.4 keeps these in Kokkos::Experimental, Kokkos >= 3.7 in Kokkos.
#if KOKKOS_VERSION >= 30700
#define CFDMPM_KOKKOS_MATH Kokkos
#else
#define CFDMPM_KOKKOS_MATH Kokkos::Experimental
#endif
KOKKOS_INLINE_FUNCTION double sqrt(double x) { return CFDMPM_KOKKOS_MATH::sqrt(x); }
KOKKOS_INLINE_FUNCTION double cbrt(double x) { return CFDMPM_KOKKOS_MATH::cbrt(x); }
KOKKOS_INLINE_FUNCTION double floor(double x) { return CFDMPM_KOKKOS_MATH::floor(x); }
KOKKOS_INLINE_FUNCTION double exp(double x) { return CFDMPM_KOKKOS_MATH::exp(x); }
KOKKOS_INLINE_FUNCTION double abs(double x) { return CFDMPM_KOKKOS_MATH::fabs(x); }
#undef CFDMPM_KOKKOS_MATH
KOKKOS_INLINE_FUNCTION double max(double a, double b) { return a > b ? a : b; }
KOKKOS_INLINE_FUNCTION double min(double a, double b) { return a < b ? a : b; }

}  // namespace cfdmpm::math
