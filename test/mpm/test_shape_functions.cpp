// Shape functions: uGIMP (Bardenhagen & Kober 2004) and the linear hat, in 2-D and 3-D.
#include "mpm/shape_functions.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace cfdmpm::mpm {
namespace {

template <int Dim>
struct TestGrid {
  double origin[Dim];
  double spacing[Dim];
  double half_width[Dim];
};

TestGrid<2> grid2()
{
  // Unequal spacings and an offset origin, so no formula can lean on h = 1 or origin = 0.
  return TestGrid<2>{{-2.0, 0.3}, {0.005, 0.0075}, {0.005 / 4, 0.0075 / 4}};
}

TestGrid<3> grid3()
{
  // Particles per cell 2, 3 and 1 per direction: l = 1/4, 1/6 and the extreme 1/2.
  return TestGrid<3>{{0.1, -0.4, 1.0},
                     {0.01, 0.02, 0.015},
                     {gimpHalfWidth(0.01, 2), gimpHalfWidth(0.02, 3), gimpHalfWidth(0.015, 1)}};
}

/// Random positions over ten cells per direction plus the awkward ones: on a node, on either side
/// of a node by 1e-12 h, and with the particle's domain edge exactly on a cell face.
template <int Dim>
std::vector<std::array<double, Dim>> samplePositions(const TestGrid<Dim>& g, int random_count)
{
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::array<double, Dim>> positions;
  for (int n = 0; n < random_count; ++n) {
    std::array<double, Dim> x;
    for (int d = 0; d < Dim; ++d) x[d] = g.origin[d] + (1.0 + 8.0 * unit(rng)) * g.spacing[d];
    positions.push_back(x);
  }
  const double fractions[] = {0.0, 1e-12, -1e-12, 0.5};
  for (double f : fractions) {
    for (int mode = 0; mode < 3; ++mode) {
      std::array<double, Dim> x;
      for (int d = 0; d < Dim; ++d) {
        const double face = g.origin[d] + 4.0 * g.spacing[d];
        const double shift = mode == 0 ? 0.0 : (mode == 1 ? g.half_width[d] : -g.half_width[d]);
        x[d] = face + shift + f * g.spacing[d];
      }
      positions.push_back(x);
    }
  }
  return positions;
}

/// Weight of global node `node` for a particle at x (0 when the node is outside the stencil).
template <int Dim, class Kernel>
double weightOfNode(const TestGrid<Dim>& g, const std::array<double, Dim>& x,
                    const long long node[Dim])
{
  ShapeStencil<Dim, Kernel> s;
  evaluateShape<Dim, Kernel>(x.data(), g.origin, g.spacing, g.half_width, s);
  for (int k = 0; k < s.size; ++k) {
    long long idx[Dim];
    s.node(k, idx);
    bool same = true;
    for (int d = 0; d < Dim; ++d) same = same && idx[d] == node[d];
    if (same) return s.weight[k];
  }
  return 0.0;
}

/// Partition of unity, sum of gradients, linear reproduction sum w x_i = x_p and its gradient
/// sum x_i (grad w_i)^T = I, for every sample position.
template <int Dim, class Kernel>
void checkReproduction(const TestGrid<Dim>& g)
{
  double worst_unity = 0, worst_gradient_sum = 0, worst_position = 0, worst_identity = 0;
  for (const auto& x : samplePositions(g, 2000)) {
    ShapeStencil<Dim, Kernel> s;
    evaluateShape<Dim, Kernel>(x.data(), g.origin, g.spacing, g.half_width, s);
    double sum_w = 0, sum_grad[Dim] = {}, sum_wx[Dim] = {}, sum_x_grad[Dim][Dim] = {};
    for (int k = 0; k < s.size; ++k) {
      long long idx[Dim];
      s.node(k, idx);
      sum_w += s.weight[k];
      for (int a = 0; a < Dim; ++a) {
        const double xa = g.origin[a] + double(idx[a]) * g.spacing[a];
        sum_grad[a] += s.gradient[k][a];
        sum_wx[a] += s.weight[k] * xa;
        for (int b = 0; b < Dim; ++b) sum_x_grad[a][b] += xa * s.gradient[k][b];
      }
    }
    worst_unity = std::max(worst_unity, std::abs(sum_w - 1.0));
    for (int a = 0; a < Dim; ++a) {
      worst_gradient_sum = std::max(worst_gradient_sum, std::abs(sum_grad[a]) * g.spacing[a]);
      worst_position = std::max(worst_position, std::abs(sum_wx[a] - x[a]) / g.spacing[a]);
      for (int b = 0; b < Dim; ++b)
        worst_identity =
            std::max(worst_identity, std::abs(sum_x_grad[a][b] - (a == b ? 1.0 : 0.0)));
    }
  }
  // The weights are sums of a few products of O(1) numbers: round-off is a few ulp, 1e-14 is the
  // required bound. Gradients are scaled by h, so they are O(1) too.
  EXPECT_LT(worst_unity, 1e-14);
  EXPECT_LT(worst_gradient_sum, 1e-13);
  // x_i are absolute coordinates of size up to ~2 m with h ~ 5e-3 m: ulp(2) / h ~ 1e-13, so
  // linear reproduction holds to ~1e-12 cell sizes; sum x_i grad w_i carries |x| / h ~ 400 times
  // the round-off of the gradient sum.
  EXPECT_LT(worst_position, 1e-11);
  EXPECT_LT(worst_identity, 1e-10);
  std::printf("  [Dim %d, %d nodes/dir] |sum w - 1| <= %.2e, |h sum grad| <= %.2e, "
              "|sum w x - x|/h <= %.2e, |sum x grad - I| <= %.2e\n",
              Dim, Kernel::nodes_per_direction, worst_unity, worst_gradient_sum, worst_position,
              worst_identity);
}

/// Gradients against central differences of the weight of a fixed node.
template <int Dim, class Kernel>
void checkGradientsByFiniteDifference(const TestGrid<Dim>& g, double tolerance_times_h,
                                      bool skip_near_nodes)
{
  double worst = 0;
  int checked = 0;
  for (const auto& x : samplePositions(g, 300)) {
    ShapeStencil<Dim, Kernel> s;
    evaluateShape<Dim, Kernel>(x.data(), g.origin, g.spacing, g.half_width, s);
    for (int d = 0; d < Dim; ++d) {
      const double delta = 1e-6 * g.spacing[d];
      if (skip_near_nodes) {
        // The hat's gradient jumps at nodes: a difference across one measures the average.
        const double xi = (x[d] - g.origin[d]) / g.spacing[d];
        if (std::abs(xi - std::round(xi)) < 2e-6) continue;
      }
      for (int k = 0; k < s.size; ++k) {
        long long idx[Dim];
        s.node(k, idx);
        auto plus = x, minus = x;
        plus[d] += delta;
        minus[d] -= delta;
        const double fd = (weightOfNode<Dim, Kernel>(g, plus, idx) -
                           weightOfNode<Dim, Kernel>(g, minus, idx)) / (2.0 * delta);
        worst = std::max(worst, std::abs(fd - s.gradient[k][d]) * g.spacing[d]);
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_LT(worst, tolerance_times_h);
  std::printf("  [Dim %d, %d nodes/dir] finite difference vs gradient: max |diff| h = %.2e over "
              "%d entries\n",
              Dim, Kernel::nodes_per_direction, worst, checked);
}

// Central differences are exact for the piecewise quadratic uGIMP except when a breakpoint lies
// within delta of x; S'' jumps there by at most 1/l (per h^2), giving an error of at most
// delta / (4 l) in units of 1/h: 1e-6 / (4 * 1/6) = 1.5e-6 for the smallest l here. Round-off:
// x +- delta is rounded at ulp(|x|) with |x| up to ~400 h, so the difference quotient carries
// ~eps * 400 / 1e-6 = 1e-7. Tolerance 2e-6 (in units of 1/h).
TEST(GimpShape, PartitionOfUnityAndLinearReproduction2D)
{
  checkReproduction<2, UniformGimp>(grid2());
}
TEST(GimpShape, PartitionOfUnityAndLinearReproduction3D)
{
  checkReproduction<3, UniformGimp>(grid3());
}
TEST(GimpShape, GradientsMatchFiniteDifferences2D)
{
  checkGradientsByFiniteDifference<2, UniformGimp>(grid2(), 2e-6, false);
}
TEST(GimpShape, GradientsMatchFiniteDifferences3D)
{
  checkGradientsByFiniteDifference<3, UniformGimp>(grid3(), 2e-6, false);
}

TEST(LinearHatShape, PartitionOfUnityAndLinearReproduction2D)
{
  checkReproduction<2, LinearHat>(grid2());
}
TEST(LinearHatShape, PartitionOfUnityAndLinearReproduction3D)
{
  checkReproduction<3, LinearHat>(grid3());
}
// Away from nodes the hat is linear, so central differences are exact up to round-off: x +- delta
// is rounded at ulp(|x|), |x| up to ~400 h, giving ~eps * 400 / 1e-6 = 1e-7 in units of 1/h.
TEST(LinearHatShape, GradientsMatchFiniteDifferencesAwayFromNodes2D)
{
  checkGradientsByFiniteDifference<2, LinearHat>(grid2(), 1e-7, true);
}
TEST(LinearHatShape, GradientsMatchFiniteDifferencesAwayFromNodes3D)
{
  checkGradientsByFiniteDifference<3, LinearHat>(grid3(), 1e-7, true);
}

// The 1-D uGIMP function at its defining points (exact in binary for l = 1/4).
TEST(GimpShape, OneDimensionalValuesAndContinuity)
{
  const double l = 0.25;
  EXPECT_DOUBLE_EQ(UniformGimp::weight(0.0, l), 1.0 - l / 2);  // centre: 1 - l/2
  EXPECT_DOUBLE_EQ(UniformGimp::weight(1.0, l), l / 4);        // on the neighbour node
  EXPECT_DOUBLE_EQ(UniformGimp::weight(-1.0, l), l / 4);
  EXPECT_DOUBLE_EQ(UniformGimp::weight(0.5, l), 0.5);          // linear middle piece
  EXPECT_EQ(UniformGimp::weight(1.0 + l, l), 0.0);             // edge of the support
  EXPECT_EQ(UniformGimp::weight(-1.3, l), 0.0);
  // S and dS/dr are continuous at every breakpoint (C^1): compare one-sided limits 1e-12 apart;
  // the slopes S' are Lipschitz with constant 1/l, so they differ by < 1e-11.
  for (double r : {l, 1.0 - l, 1.0 + l, -l, -(1.0 - l), -(1.0 + l)}) {
    EXPECT_NEAR(UniformGimp::weight(r - 1e-12, l), UniformGimp::weight(r + 1e-12, l), 1e-11);
    EXPECT_NEAR(UniformGimp::slope(r - 1e-12, l), UniformGimp::slope(r + 1e-12, l), 1e-10);
  }
}

// The stencil starts at floor(xi - l), and nodes just outside it (base - 1, base + 3) have zero
// weight, so the 3-node stencil never misses a node; a particle inside one cell has a zero third
// weight, one straddling a face three non-zero ones.
TEST(GimpShape, StencilCoversTheWholeSupport)
{
  const double l = 0.25;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 20.0);
  for (int n = 0; n < 10000; ++n) {
    const double xi = unit(rng);
    long long base;
    double w[3], dw[3];
    UniformGimp::evaluate1D(xi, l, base, w, dw);
    ASSERT_EQ(base, static_cast<long long>(std::floor(xi - l)));
    EXPECT_EQ(UniformGimp::weight(xi - double(base - 1), l), 0.0);
    EXPECT_EQ(UniformGimp::weight(xi - double(base + 3), l), 0.0);
    const bool inside_one_cell = std::floor(xi - l) == std::floor(xi + l);
    if (inside_one_cell) EXPECT_EQ(w[2], 0.0);
    else EXPECT_GT(w[2], 0.0);
  }
}

// With the particle domain inside one cell, uGIMP equals the linear hat (the hat is linear over
// the domain, so averaging it changes nothing): the two kernels agree to round-off there.
TEST(GimpShape, EqualsLinearHatInsideOneCell)
{
  const double l = 0.25;
  for (double xi : {3.3, 3.5, 3.74, 3.26}) {
    long long base_g, base_h;
    double wg[3], dg[3], wh[2], dh[2];
    UniformGimp::evaluate1D(xi, l, base_g, wg, dg);
    LinearHat::evaluate1D(xi, l, base_h, wh, dh);
    ASSERT_EQ(base_g, base_h);
    EXPECT_NEAR(wg[0], wh[0], 1e-15);
    EXPECT_NEAR(wg[1], wh[1], 1e-15);
    EXPECT_NEAR(dg[0], dh[0], 1e-15);
    EXPECT_NEAR(dg[1], dh[1], 1e-15);
  }
}

}  // namespace
}  // namespace cfdmpm::mpm
