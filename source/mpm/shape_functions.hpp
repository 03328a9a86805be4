#pragma once
// MPM shape functions: the weights w_ip and gradients grad w_ip that tie a material point p to the
// grid nodes i around it, for particle-to-grid and grid-to-particle transfers.
//
// Two kernels, both tensor products of a 1-D function of r = (x_p - x_i) / h (h: cell size):
//
//  * LinearHat: S(r) = 1 - |r| for |r| < 1. Two nodes per direction (2^Dim in all). The gradient
//    jumps when a particle crosses a cell face, which is the source of MPM's cell-crossing noise.
//
//  * UniformGimp: uGIMP of Bardenhagen & Kober 2004, the hat convolved with the particle's
//    characteristic function of half-width lp (normalised l = lp / h, 0 < l <= 1/2; for ppc
//    particles per cell and direction, lp = h / (2 ppc)):
//        S(r) = 1 - (r^2 + l^2) / (2 l)        |r| < l
//             = 1 - |r|                        l <= |r| <= 1 - l
//             = (1 + l - |r|)^2 / (4 l)        1 - l < |r| < 1 + l
//             = 0                              otherwise
//    S is C^1 and piecewise quadratic, so its gradient is continuous across cell faces. A particle
//    touches at most three nodes per direction: the lowest is floor(xi - l), xi = (x_p - origin)/h,
//    and the stencil is that node and the next two (3^Dim in all; the third weight is zero when the
//    particle's domain lies inside one cell).
//
// Both reproduce constants and linear functions exactly: sum_i w_i = 1, sum_i w_i x_i = x_p,
// sum_i grad w_i = 0 (the unit tests check these to round-off).
//
// Usage inside a kernel (values live on the stack; no allocation):
//
//     ShapeStencil<2, UniformGimp> s;
//     evaluateShape(x_p, grid_origin, cell_size, half_width, s);
//     for (int k = 0; k < s.size; ++k) {
//       long long node[2];
//       s.node(k, node);              // global node index (may lie outside the grid near its edge)
//       ... s.weight[k], s.gradient[k][d] ...
//     }
//
// Stencil entries are ordered lexicographically with x fastest, like the grid's node numbering.
// Node indices are not clamped: near the domain edge the caller maps them to ghost nodes or drops
// them (a particle domain that pokes out of the grid loses those weights).
#include "mpm/tensor.hpp"

namespace cfdmpm::mpm {

/// Particle half-width for uGIMP: lp = h / (2 ppc) with ppc particles per cell in that direction.
KOKKOS_INLINE_FUNCTION double gimpHalfWidth(double cell_size, int particles_per_cell)
{
  return cell_size / (2.0 * particles_per_cell);
}

/// Linear hat S(r) = 1 - |r|; two nodes per direction.
struct LinearHat {
  static constexpr int nodes_per_direction = 2;

  /// Weight of a node at normalised distance r = (x_p - x_i) / h.
  KOKKOS_INLINE_FUNCTION static double weight(double r)
  {
    const double a = math::abs(r);
    return a < 1.0 ? 1.0 - a : 0.0;
  }

  /// 1-D stencil for a particle at xi = (x_p - origin) / h: lowest node and the weights and
  /// d(weight)/d(xi) of nodes base, base + 1. `l` is unused (kept for a common kernel interface).
  /// A particle exactly on a node belongs to the cell above it (gradient -1, +1).
  KOKKOS_INLINE_FUNCTION static void evaluate1D(double xi, double /*l*/, long long& base,
                                                double w[2], double dw[2])
  {
    const double cell = math::floor(xi);
    base = static_cast<long long>(cell);
    const double f = xi - cell;  // position inside the cell, in [0, 1)
    w[0] = 1.0 - f;
    w[1] = f;
    dw[0] = -1.0;
    dw[1] = 1.0;
  }
};

/// Uniform GIMP (Bardenhagen & Kober 2004); three nodes per direction.
struct UniformGimp {
  static constexpr int nodes_per_direction = 3;

  /// Weight of a node at normalised distance r = (x_p - x_i) / h for a particle of normalised
  /// half-width l = lp / h, 0 < l <= 1/2.
  KOKKOS_INLINE_FUNCTION static double weight(double r, double l)
  {
    const double a = math::abs(r);
    if (a < l) return 1.0 - (r * r + l * l) / (2.0 * l);
    if (a <= 1.0 - l) return 1.0 - a;
    if (a < 1.0 + l) {
      const double t = 1.0 + l - a;
      return t * t / (4.0 * l);
    }
    return 0.0;
  }

  /// dS/dr, the derivative of weight() with respect to the particle position (in units of 1/h).
  KOKKOS_INLINE_FUNCTION static double slope(double r, double l)
  {
    const double a = math::abs(r);
    const double sign = r < 0.0 ? -1.0 : 1.0;
    if (a < l) return -r / l;
    if (a <= 1.0 - l) return -sign;
    if (a < 1.0 + l) return -sign * (1.0 + l - a) / (2.0 * l);
    return 0.0;
  }

  /// 1-D stencil for a particle at xi = (x_p - origin) / h with half-width l: lowest node
  /// floor(xi - l) and the weights and d(weight)/d(xi) of nodes base, base + 1, base + 2.
  KOKKOS_INLINE_FUNCTION static void evaluate1D(double xi, double l, long long& base, double w[3],
                                                double dw[3])
  {
    const double lowest = math::floor(xi - l);
    base = static_cast<long long>(lowest);
    for (int k = 0; k < 3; ++k) {
      const double r = xi - (lowest + k);
      w[k] = weight(r, l);
      dw[k] = slope(r, l);
    }
  }
};

/// n^Dim at compile time.
KOKKOS_INLINE_FUNCTION constexpr int stencilSize(int nodes_per_direction, int dim)
{
  return dim == 0 ? 1 : nodes_per_direction * stencilSize(nodes_per_direction, dim - 1);
}

/// The nodes one particle touches, with weights and gradients (1/m). A plain value type.
template <int Dim, class Kernel>
struct ShapeStencil {
  static_assert(Dim == 2 || Dim == 3, "shape functions are for 2-D and 3-D grids");
  static constexpr int per_direction = Kernel::nodes_per_direction;
  static constexpr int size = stencilSize(per_direction, Dim);

  long long base_node[Dim];   ///< global index of the lowest node in each direction
  double weight[size];        ///< w_ip
  double gradient[size][Dim]; ///< d w_ip / d x_p

  /// Offset (0 .. per_direction-1 per direction) of stencil entry k from base_node; x fastest.
  KOKKOS_INLINE_FUNCTION static void offset(int k, int o[Dim])
  {
    for (int d = 0; d < Dim; ++d) {
      o[d] = k % per_direction;
      k /= per_direction;
    }
  }

  /// Global node index of stencil entry k.
  KOKKOS_INLINE_FUNCTION void node(int k, long long index[Dim]) const
  {
    int o[Dim];
    offset(k, o);
    for (int d = 0; d < Dim; ++d) index[d] = base_node[d] + o[d];
  }
};

/// Evaluates the shape functions of one particle.
///   position    particle position x_p (m)
///   origin      position of node 0 in each direction (m)
///   spacing     cell size h per direction (m)
///   half_width  particle half-width lp per direction (m); ignored by LinearHat
///   stencil     output: base node, weights and gradients of all per_direction^Dim nodes
template <int Dim, class Kernel>
KOKKOS_INLINE_FUNCTION void evaluateShape(const double position[Dim], const double origin[Dim],
                                          const double spacing[Dim], const double half_width[Dim],
                                          ShapeStencil<Dim, Kernel>& stencil)
{
  constexpr int n = Kernel::nodes_per_direction;
  double w1[Dim][n];
  double g1[Dim][n];
  for (int d = 0; d < Dim; ++d) {
    const double inv_h = 1.0 / spacing[d];
    const double xi = (position[d] - origin[d]) * inv_h;
    double dw[n];
    Kernel::evaluate1D(xi, half_width[d] * inv_h, stencil.base_node[d], w1[d], dw);
    for (int k = 0; k < n; ++k) g1[d][k] = dw[k] * inv_h;
  }
  for (int k = 0; k < ShapeStencil<Dim, Kernel>::size; ++k) {
    int o[Dim];
    ShapeStencil<Dim, Kernel>::offset(k, o);
    double w = 1.0;
    for (int d = 0; d < Dim; ++d) w *= w1[d][o[d]];
    stencil.weight[k] = w;
    for (int d = 0; d < Dim; ++d) {
      double g = g1[d][o[d]];
      for (int e = 0; e < Dim; ++e)
        if (e != d) g *= w1[e][o[e]];
      stencil.gradient[k][d] = g;
    }
  }
}

}  // namespace cfdmpm::mpm
