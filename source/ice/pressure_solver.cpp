// The implicit pressure solve: graph and matrix (Tpetra), CG (Belos), smoothed aggregation (MueLu).
// This is the only translation unit that includes Belos and MueLu.
#include "ice/pressure_solver.hpp"

#include "common/error.hpp"
#include "common/mpi_comm.hpp"
#include "input/parameter_rule.hpp"

#include <BelosCGIter.hpp>
#include <BelosLinearProblem.hpp>
#include <BelosStatusTestCombo.hpp>
#include <BelosStatusTestMaxIters.hpp>
#include <BelosTpetraAdapter.hpp>
#include <MueLu_CreateTpetraPreconditioner.hpp>
#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_TimeMonitor.hpp>
#include <Tpetra_CrsGraph.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Vector.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace cfdmpm {

namespace {

using MultiVector = Tpetra::MultiVector<Scalar, LocalOrdinal, GlobalOrdinal, Node>;
using Vector = Tpetra::Vector<Scalar, LocalOrdinal, GlobalOrdinal, Node>;
using Operator = Tpetra::Operator<Scalar, LocalOrdinal, GlobalOrdinal, Node>;
using Graph = Tpetra::CrsGraph<LocalOrdinal, GlobalOrdinal, Node>;
using CrsMatrix = Tpetra::CrsMatrix<Scalar, LocalOrdinal, GlobalOrdinal, Node>;
using MueLuPreconditioner = MueLu::TpetraOperator<Scalar, LocalOrdinal, GlobalOrdinal, Node>;
using Clock = std::chrono::steady_clock;

enum class PreconditionerType { MueLu, Jacobi, None };
enum class ReuseMode { KeepRAP, KeepRP, KeepTentativeP, Frozen };

double secondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The settings after validation, as typed values.
struct Settings {
  double tolerance = 1e-10;
  int maximum_iterations = 500;
  PreconditionerType preconditioner = PreconditionerType::MueLu;
  int verbosity = 0;
  int reuse_interval = 1;
  ReuseMode reuse_mode = ReuseMode::KeepRP;
  double reuse_slowdown_limit = 0;  // 0: off
  bool refresh_corrections = true;
};

std::string keysOf(const Teuchos::ParameterList& list)
{
  std::string keys;
  for (auto it = list.begin(); it != list.end(); ++it) keys += (keys.empty() ? "" : ", ") + list.name(it);
  return keys;
}

/// `prefix` starts each message's key ("pressure solver: " or "cfdmpm.ice.linear_solver.").
Settings readSettings(Teuchos::ParameterList& list, const Teuchos::ParameterList& valid,
                      const std::string& prefix = "pressure solver: ")
{
  // Unknown keys and wrong types first, each named with what is allowed (Teuchos's own message
  // dumps the whole valid list).
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string& key = list.name(it);
    const Teuchos::ParameterEntry* valid_entry = valid.getEntryPtr(key);
    if (!valid_entry) throw InputError(prefix + key + ": unknown key; allowed keys: " + keysOf(valid));
    const Teuchos::ParameterEntry& entry = list.entry(it);
    if (entry.isList() != valid_entry->isList() ||
        (!entry.isList() && entry.getAny(false).type() != valid_entry->getAny(false).type() &&
         !(valid_entry->isType<double>() && entry.isType<int>())))
      throw InputError(prefix + key + ": got a value of the wrong type; expected " + expectedType(*valid_entry, 0));
    if (valid_entry->isType<double>() && entry.isType<int>()) list.set(key, double(entry.getValue<int>(nullptr)));
  }
  try {
    // Depth 0: the "muelu" sublist is MueLu's to validate.
    list.validateParametersAndSetDefaults(valid, 0);
  } catch (const std::exception& e) {
    throw InputError(prefix + "settings: " + e.what());
  }
  Settings s;
  s.tolerance = list.get<double>("tolerance");
  if (!(s.tolerance > 0 && s.tolerance < 1))
    throw inputError(prefix + "tolerance", showNumber(s.tolerance), "must lie in (0, 1)");
  s.maximum_iterations = list.get<int>("maximum iterations");
  if (s.maximum_iterations < 1)
    throw inputError(prefix + "maximum iterations", std::to_string(s.maximum_iterations), "must be >= 1");
  const std::string preconditioner = list.get<std::string>("preconditioner");
  if (preconditioner == "muelu") s.preconditioner = PreconditionerType::MueLu;
  else if (preconditioner == "jacobi") s.preconditioner = PreconditionerType::Jacobi;
  else if (preconditioner == "none") s.preconditioner = PreconditionerType::None;
  else throw inputError(prefix + "preconditioner", preconditioner, "allowed: muelu, jacobi, none");
  s.verbosity = list.get<int>("verbosity");
  if (s.verbosity < 0 || s.verbosity > 2)
    throw inputError(prefix + "verbosity", std::to_string(s.verbosity), "allowed: 0, 1, 2");
  s.reuse_interval = list.get<int>("reuse interval");
  if (s.reuse_interval < 1)
    throw inputError(prefix + "reuse interval", std::to_string(s.reuse_interval), "must be >= 1");
  const std::string mode = list.get<std::string>("reuse mode");
  if (mode == "RAP") s.reuse_mode = ReuseMode::KeepRAP;
  else if (mode == "RP") s.reuse_mode = ReuseMode::KeepRP;
  else if (mode == "tP") s.reuse_mode = ReuseMode::KeepTentativeP;
  else if (mode == "frozen") s.reuse_mode = ReuseMode::Frozen;
  else throw inputError(prefix + "reuse mode", mode, "allowed: RAP, RP, tP, frozen");
  s.reuse_slowdown_limit = list.get<double>("reuse slowdown limit");
  if (!(s.reuse_slowdown_limit == 0 || s.reuse_slowdown_limit >= 1))
    throw inputError(prefix + "reuse slowdown limit", showNumber(s.reuse_slowdown_limit),
                     "must be 0 (off) or >= 1");
  s.refresh_corrections = list.get<bool>("refresh corrections");
  return s;
}

/// Jacobi preconditioner, y = beta y + alpha D^-1 x with D the matrix diagonal; kept only to show
/// what MueLu buys (see doc/ice-pressure.md).
class InverseDiagonal final : public Operator {
 public:
  explicit InverseDiagonal(const CrsMatrix& matrix) : inverse_(Teuchos::rcp(new Vector(matrix.getRowMap())))
  {
    update(matrix);
  }
  void update(const CrsMatrix& matrix)
  {
    matrix.getLocalDiagCopy(*inverse_);
    inverse_->reciprocal(*inverse_);
  }
  Teuchos::RCP<const Map> getDomainMap() const override { return inverse_->getMap(); }
  Teuchos::RCP<const Map> getRangeMap() const override { return inverse_->getMap(); }
  void apply(const MultiVector& x, MultiVector& y, Teuchos::ETransp, Scalar alpha, Scalar beta) const override
  {
    y.elementWiseMultiply(alpha, *inverse_, x, beta);
  }

 private:
  Teuchos::RCP<Vector> inverse_;
};

/// The face coefficient of every direction, readable inside a kernel: (d, c) is the value on the
/// lower face of cell c in direction d.
template <int Dim>
struct LowerFaceValues {
  typename Field<Dim>::ConstView direction[Dim];
  KOKKOS_INLINE_FUNCTION Scalar operator()(int d, LocalOrdinal c) const { return direction[d](c, 0); }
};

/// max_i |v_i| of a one-column vector over every rank, +∞ if an entry is not finite. Tpetra's
/// normInf passes over a NaN and returns −DBL_MAX for entries that are all NaN: in a slide in air
/// at 10 mm (0.788 s) a face velocity of 2.5e85 m/s (mended in IceSolver::faceVelocities) drove
/// the pressure to 1e88 Pa and the volume law's slope to 1e-130, CG's next iterate was NaN in every
/// cell, its relative residual −1.5e106 passed "at most the tolerance", and the step failed only
/// later, on a right-hand side that was not finite, naming neither the solve nor its cause.
double largestMagnitude(const MultiVector& v)
{
  const auto view = v.getLocalViewDevice(Tpetra::Access::ReadOnly);
  double local = 0;
  Kokkos::parallel_reduce(
      "PressureSolver::largestMagnitude", Kokkos::RangePolicy<ExecutionSpace>(0, view.extent(0)),
      KOKKOS_LAMBDA(const int i, double& largest) {
        const double a = view(i, 0);
        const double magnitude = Kokkos::Experimental::isfinite(a) ? (a < 0 ? -a : a) : INFINITY;
        if (magnitude > largest) largest = magnitude;
      },
      Kokkos::Max<double>(local));
  double global = 0;
  Teuchos::reduceAll(*v.getMap()->getComm(), Teuchos::REDUCE_MAX, std::max(local, 0.0), Teuchos::outArg(global));
  return global;
}

/// How a solve measures a residual: ||v||₂, max_i |v_i|, or max_i w_i |v_i| with the caller's
/// weights w (a row whose residual matters less to the caller counts for less). A vector with an
/// entry that is not finite measures NaN (2-norm) or +∞ (the others): it never passes a bound.
struct ResidualMeasure {
  Belos::NormType norm = Belos::TwoNorm;
  Teuchos::RCP<const Vector> weight;  // with norm = InfNorm only
  Teuchos::RCP<MultiVector> scratch;  // w ⊙ v

  double operator()(const MultiVector& v) const
  {
    double value = 0;
    if (!weight.is_null()) {
      scratch->elementWiseMultiply(1.0, *weight, v, 0.0);
      value = largestMagnitude(*scratch);
    } else if (norm == Belos::InfNorm) {
      value = largestMagnitude(v);
    } else {
      v.norm2(Teuchos::ArrayView<double>(&value, 1));
    }
    return value;
  }
};

/// Belos stopping test on CG's recurrence residual in a ResidualMeasure: passed once it is at most
/// `bound` (Belos's own residual test knows no weights). With `trace` it prints every check.
class ResidualBoundTest : public Belos::StatusTest<Scalar, MultiVector, Operator> {
 public:
  ResidualBoundTest(const ResidualMeasure& measure, double bound, bool trace)
      : measure_(measure), bound_(bound), trace_(trace)
  {
  }
  Belos::StatusType checkStatus(Belos::Iteration<Scalar, MultiVector, Operator>* iteration) override
  {
    value_ = measure_(*iteration->getNativeResiduals(nullptr));
    // No iteration recovers from a residual that is not finite: stop (runCG reports the failure).
    if (!std::isfinite(value_))
      throw std::runtime_error("CG's residual is not finite at iteration " + std::to_string(iteration->getNumIters()));
    status_ = value_ <= bound_ ? Belos::Passed : Belos::Failed;
    if (trace_) {
      std::cout << "  CG iteration " << iteration->getNumIters() << ": ";
      print(std::cout, 0);
    }
    return status_;
  }
  Belos::StatusType getStatus() const override { return status_; }
  void reset() override { status_ = Belos::Undefined; }
  void print(std::ostream& os, int indent) const override
  {
    os << std::string(indent, ' ') << "residual " << value_ << " (bound " << bound_ << "): " << Belos::convertStatusTypeToString(status_) << "\n";
  }

 private:
  const ResidualMeasure& measure_;
  double bound_;
  bool trace_;
  double value_ = 0;
  Belos::StatusType status_ = Belos::Undefined;
};

void requireOneColumn(int columns, const std::string& name, const char* role)
{
  if (columns != 1)
    throw std::invalid_argument("PressureSolver: " + std::string(role) + " '" + name + "' must have 1 column, has " +
                                std::to_string(columns));
}

}  // namespace

template <int Dim>
struct PressureSolver<Dim>::Impl {
  static constexpr int kStencil = 1 + 2 * Dim;  // slot 0: the cell; slot 1 + f: across face f

  std::shared_ptr<const Layout<Dim>> layout;
  Teuchos::ParameterList settings_list;
  Settings settings;

  Teuchos::RCP<CrsMatrix> matrix;
  // (row, slot) -> position of that entry in the local CRS values array; kNoEntry across a wall or
  // towards an excluded cell. assemble() writes the values there directly: the graph and its maps
  // change only with the excluded cells.
  Kokkos::View<std::size_t**, MemorySpace> stencil_offsets;
  static constexpr std::size_t kNoEntry = ~std::size_t(0);

  // The excluded cells the graph was built for (a copy of excludeCells()'s mask; empty: none).
  CellMask excluded;
  // With excluded cells: row k of the matrix is owned cell row_cell(k), and the caller's fields are
  // gathered into (and scattered from) vectors over the rows. Without, the rows are the owned cells
  // in the layout's map and the fields' owned parts are used as they are.
  bool every_cell_a_row = true;
  Kokkos::View<LocalOrdinal*, MemorySpace> row_cell;
  long long global_rows = 0;
  Teuchos::RCP<MultiVector> rows_b, rows_x, rows_weight, rows_y;
  // The rows' cell centres (Dim columns), for MueLu's repartitioning of coarse levels.
  Teuchos::RCP<MultiVector> coordinates;

  // Work vectors of solve(), allocated once per graph (a residual, the caller's guess, a weighted
  // residual).
  Teuchos::RCP<MultiVector> residual, guess, weighted;

  // Cumulative wall time of the parts of the solve, for profiling (bench/bench_ice).
  Teuchos::RCP<Teuchos::Time> assemble_timer = Teuchos::TimeMonitor::getNewCounter("pressure solver: assemble");
  Teuchos::RCP<Teuchos::Time> setup_timer = Teuchos::TimeMonitor::getNewCounter("pressure solver: preconditioner");
  Teuchos::RCP<Teuchos::Time> cg_timer = Teuchos::TimeMonitor::getNewCounter("pressure solver: CG");

  Teuchos::RCP<MueLuPreconditioner> muelu;
  Teuchos::RCP<InverseDiagonal> jacobi;
  bool assembled = false;
  bool values_changed = false;  // since the preconditioner last saw the matrix
  bool rebuild_requested = false;
  int solves_since_setup = 0;
  // Per kind of solve (solve()'s kind): CG iterations per decade of residual reduction of the first
  // solve of that kind with the current hierarchy (0: none yet); a later solve of the same kind that
  // needs `reuse slowdown limit` times more is followed by a full setup. After a setup every kind's
  // reference is due again, whichever kind's solve the setup happened in: a setup requested by one
  // kind happens in the next solve, of another kind, and a reference renewed only for that kind left
  // the first kind comparing the new hierarchy with the old one's measure (the seed slide at 5 mm
  // then set up its hierarchy at nearly every step).
  std::array<double, PressureSolver<Dim>::kSolveKinds> fresh_iterations_per_decade{};
  std::array<bool, PressureSolver<Dim>::kSolveKinds> reference_due{};

  void buildGraph();
  LocalOrdinal localRows() const { return LocalOrdinal(row_cell.extent(0)); }
  /// rows(k) = field(row_cell(k)) over the rows; field: an owned part of a 1-column field.
  void gather(const MultiVector& field, MultiVector& rows) const;
  /// field(row_cell(k)) = rows(k), and 0 in the excluded owned cells.
  void scatter(const MultiVector& rows, MultiVector& field) const;
  Teuchos::ParameterList mueluParameters() const;
  Teuchos::RCP<Operator> preparePreconditioner(PressureSolveReport& report, int kind);
  double residualNorm(const MultiVector& b, const MultiVector& x, const ResidualMeasure& measure) const;
  void runCG(const Teuchos::RCP<Operator>& preconditioner, const MultiVector& b, MultiVector& x,
             const ResidualMeasure& measure, double b_norm, double tolerance, PressureSolveReport& report) const;
};

template <int Dim>
void PressureSolver<Dim>::Impl::buildGraph()
{
  const Layout<Dim>& lay = *layout;
  if (lay.ghostWidth() < 1) throw std::invalid_argument("PressureSolver: the layout needs ghost width >= 1");
  const LocalOrdinal owned = lay.ownedCells();
  const Map& overlap = *lay.overlapCellMap();
  const auto neighbours = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), lay.cellNeighbours());
  const auto excluded_host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), excluded);
  const bool any_excluded_here = excluded.extent(0) > 0;

  // The rows: the owned cells that are not excluded, in the layout's order.
  std::vector<LocalOrdinal> cells;
  cells.reserve(owned);
  for (LocalOrdinal c = 0; c < owned; ++c)
    if (!any_excluded_here || !excluded_host(c)) cells.push_back(c);
  const long long local_rows = static_cast<long long>(cells.size());
  Teuchos::reduceAll(*lay.comm(), Teuchos::REDUCE_SUM, local_rows, Teuchos::outArg(global_rows));
  every_cell_a_row = global_rows == lay.grid().cellCount();  // every cell is owned by one rank

  // Each overlap cell's global row id (-1: no row). Without excluded cells the rows are the layout's
  // owned cells with their global ids; with them, rank r numbers its rows after those of ranks < r,
  // and the ghosts learn their owners' numbers by a halo exchange (so that both sides of a face
  // between ranks agree on whether it couples two rows).
  std::vector<GlobalOrdinal> row_id(lay.overlapCells(), -1);
  Teuchos::RCP<const Map> rows;
  if (every_cell_a_row) {
    rows = lay.ownedCellMap();
    for (LocalOrdinal c = 0; c < lay.overlapCells(); ++c) row_id[c] = overlap.getGlobalElement(c);
  } else {
    long long first = 0;
    Teuchos::scan(*lay.comm(), Teuchos::REDUCE_SUM, local_rows, Teuchos::outArg(first));
    first -= local_rows;
    rows = Teuchos::rcp(new Map(Tpetra::global_size_t(global_rows), std::size_t(local_rows), GlobalOrdinal(0), lay.comm()));
    Field<Dim> ids(layout, Location::Cell, 1, "pressure row ids");
    ids.fill(-1.0);
    {
      auto id = ids.view();
      const auto id_host = Kokkos::create_mirror_view(id);
      Kokkos::deep_copy(id_host, id);
      for (std::size_t k = 0; k < cells.size(); ++k) id_host(cells[k], 0) = double(first + static_cast<long long>(k));
      Kokkos::deep_copy(id, id_host);
    }
    ids.exchangeHalo();
    const auto id_host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), ids.view());
    for (LocalOrdinal c = 0; c < lay.overlapCells(); ++c) row_id[c] = GlobalOrdinal(id_host(c, 0));
  }
  row_cell = Kokkos::View<LocalOrdinal*, MemorySpace>("pressure row cells", cells.size());
  {
    const auto host = Kokkos::create_mirror_view(row_cell);
    for (std::size_t k = 0; k < cells.size(); ++k) host(k) = cells[k];
    Kokkos::deep_copy(row_cell, host);
  }

  // Global ids of each row's stencil (the cell first, then its face neighbours that have rows).
  const LocalOrdinal n_rows = LocalOrdinal(cells.size());
  std::vector<GlobalOrdinal> stencil_gids(std::size_t(n_rows) * kStencil, -1);
  std::vector<std::size_t> entries(n_rows, 0);
  for (LocalOrdinal k = 0; k < n_rows; ++k) {
    const LocalOrdinal c = cells[k];
    stencil_gids[k * kStencil] = row_id[c];
    entries[k] = 1;
    for (int f = 0; f < 2 * Dim; ++f) {
      const LocalOrdinal n = neighbours(c, f);
      if (n == Layout<Dim>::kOutsideDomain) continue;  // wall: no coupling
      if (n < 0) throw std::logic_error("PressureSolver: face neighbour of an owned cell is not local");
      if (row_id[n] < 0) continue;  // an excluded cell: a wall
      stencil_gids[k * kStencil + 1 + f] = row_id[n];
      ++entries[k];
    }
  }

  // Tpetra builds the column map from the global ids: the rows plus the face-neighbour ghosts only,
  // so the matrix-vector product imports no more than the stencil needs.
  auto graph = Teuchos::rcp(new Graph(rows, Teuchos::ArrayView<const std::size_t>(entries.data(), entries.size())));
  for (LocalOrdinal k = 0; k < n_rows; ++k) {
    GlobalOrdinal columns[kStencil];
    int n = 0;
    for (int s = 0; s < kStencil; ++s)
      if (stencil_gids[k * kStencil + s] >= 0) columns[n++] = stencil_gids[k * kStencil + s];
    graph->insertGlobalIndices(stencil_gids[k * kStencil], Teuchos::ArrayView<const GlobalOrdinal>(columns, n));
  }
  graph->fillComplete(rows, rows);

  // Where each stencil entry sits in the local CRS arrays (the graph sorts a row's columns).
  const Map& column_map = *graph->getColMap();
  const auto local_graph = graph->getLocalGraphHost();
  stencil_offsets = Kokkos::View<std::size_t**, MemorySpace>("pressure stencil offsets", n_rows, kStencil);
  const auto offsets_host = Kokkos::create_mirror_view(stencil_offsets);
  for (LocalOrdinal k = 0; k < n_rows; ++k)
    for (int s = 0; s < kStencil; ++s) {
      const GlobalOrdinal gid = stencil_gids[k * kStencil + s];
      offsets_host(k, s) = kNoEntry;
      if (gid < 0) continue;
      const LocalOrdinal column = column_map.getLocalElement(gid);
      for (auto e = local_graph.row_map(k); e < local_graph.row_map(k + 1); ++e)
        if (local_graph.entries(e) == column) offsets_host(k, s) = e;
      if (offsets_host(k, s) == kNoEntry) throw std::logic_error("PressureSolver: stencil entry missing from the graph");
    }
  Kokkos::deep_copy(stencil_offsets, offsets_host);

  matrix = Teuchos::rcp(new CrsMatrix(graph));
  matrix->fillComplete(rows, rows);  // all zeros until the first assemble()

  // A new graph: the old preconditioner, work vectors and values do not fit it.
  muelu = Teuchos::null;
  jacobi = Teuchos::null;
  residual = guess = weighted = Teuchos::null;
  rows_b = rows_x = rows_weight = rows_y = Teuchos::null;
  if (!every_cell_a_row) {
    rows_b = Teuchos::rcp(new MultiVector(rows, 1));
    rows_x = Teuchos::rcp(new MultiVector(rows, 1));
    rows_weight = Teuchos::rcp(new MultiVector(rows, 1));
    rows_y = Teuchos::rcp(new MultiVector(rows, 1));
  }
  coordinates = Teuchos::rcp(new MultiVector(rows, Dim));
  {
    const auto ijk = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), lay.cellIndex());
    const auto x = coordinates->getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (LocalOrdinal k = 0; k < n_rows; ++k)
      for (int d = 0; d < Dim; ++d) x(k, d) = lay.grid().cellCentre(d, ijk(cells[k], d));
  }
  assembled = false;
  values_changed = true;
  solves_since_setup = 0;
  reference_due.fill(true);
}

template <int Dim>
void PressureSolver<Dim>::Impl::gather(const MultiVector& field, MultiVector& rows) const
{
  const auto from = field.getLocalViewDevice(Tpetra::Access::ReadOnly);
  const auto to = rows.getLocalViewDevice(Tpetra::Access::OverwriteAll);
  const auto cell = row_cell;
  Kokkos::parallel_for(
      "pressure solver: gather", Kokkos::RangePolicy<ExecutionSpace>(0, localRows()),
      KOKKOS_LAMBDA(const LocalOrdinal k) { to(k, 0) = from(cell(k), 0); });
}

template <int Dim>
void PressureSolver<Dim>::Impl::scatter(const MultiVector& rows, MultiVector& field) const
{
  field.putScalar(0.0);  // the excluded cells
  const auto from = rows.getLocalViewDevice(Tpetra::Access::ReadOnly);
  const auto to = field.getLocalViewDevice(Tpetra::Access::ReadWrite);
  const auto cell = row_cell;
  Kokkos::parallel_for(
      "pressure solver: scatter", Kokkos::RangePolicy<ExecutionSpace>(0, localRows()),
      KOKKOS_LAMBDA(const LocalOrdinal k) { to(cell(k), 0) = from(k, 0); });
}

template <int Dim>
Teuchos::ParameterList PressureSolver<Dim>::Impl::mueluParameters() const
{
  Teuchos::ParameterList p;
  p.set("verbosity", std::string(settings.verbosity >= 2 ? "low" : "none"));
  p.set("problem: symmetric", true);
  p.set("multigrid algorithm", std::string("sa"));
  p.set("smoother: type", std::string("CHEBYSHEV"));
  // MueLu's default coarse solver (Amesos2 KLU2) diverges on more than one rank with Debian's
  // Trilinos 13.2 while the coarse matrix stays distributed, and ILUT there (each rank's part alone)
  // doubles the CG iterations against one rank (seed scene, 10 mm, 0.15 s: 29 against 15 per step).
  // So from the first coarse level on, a level with fewer than 4000 rows per rank is moved onto
  // fewer ranks (Zoltan2's partition of the rows' centres, given in "user data"); the coarsest
  // level (at most MueLu's "coarse: max size", 2000 rows) lands on one rank, where KLU2 solves it
  // exactly: 14.6 CG iterations per step on 2 ranks, as on one. A Trilinos without Zoltan2 (the
  // threaded build's, utilities/build-trilinos-openmp.sh) keeps ILUT on the coarse level.
  // A matrix of at most "coarse: max size" rows is its own coarsest level, which stays distributed
  // (MueLu repartitions from level 1): ILUT there too.
  const Teuchos::ParameterList& user = settings_list.sublist("muelu");
  const int coarse_max = user.isType<int>("coarse: max size") ? user.get<int>("coarse: max size") : 2000;
  if (layout->comm()->getSize() > 1 && global_rows <= coarse_max) {
    p.set("coarse: type", std::string("ILUT"));
  } else if (layout->comm()->getSize() > 1) {
#ifdef HAVE_MUELU_ZOLTAN2
    p.set("repartition: enable", true);
    p.set("repartition: partitioner", std::string("zoltan2"));
    p.set("repartition: start level", 1);
    p.set("repartition: min rows per proc", 4000);
#else
    p.set("coarse: type", std::string("ILUT"));
#endif
  }
  if (settings.reuse_interval > 1 && settings.reuse_mode != ReuseMode::Frozen) {
    const char* type = settings.reuse_mode == ReuseMode::KeepRAP  ? "RAP"
                       : settings.reuse_mode == ReuseMode::KeepRP ? "RP"
                                                                  : "tP";
    p.set("reuse: type", std::string(type));
  }
  p.setParameters(settings_list.sublist("muelu"));  // the user's MueLu keys win
  // The finest level's Chebyshev smoother needs the largest eigenvalue of D^-1 A. Every row of the
  // pressure matrix has a positive diagonal V kappa + sum a_f and off-diagonals -a_f <= 0, so
  // D^-1 A = I - D^-1 N with N >= 0 and row sums of D^-1 N below 1: its eigenvalues lie in (0, 2)
  // (Gershgorin), and 2 is a bound that holds for every matrix this solver assembles. Ifpack2's
  // default estimate (10 power iterations, x1.1) costs 10 matrix-vector products at every reuse of
  // the hierarchy and comes out lower than the true largest eigenvalue of the 5-point Laplacian (~2):
  // on the 280k-cell dam break the bound cuts the CG iterations per solve from 8.4 to 7.2 and the
  // smoother's refresh to a fifth. One power iteration still runs (Ifpack2 estimates whenever the
  // matrix may have changed), its result unused. Coarse levels keep the estimate: their Galerkin
  // matrices need not be diagonally dominant.
  // In 2-D the smoother also aims at the modes the first coarse level cannot represent: its interval
  // [λmax / ratio, λmax] with ratio = the coarsening ratio of that level (~6 rows per aggregate for
  // the 5-point matrix, MueLu's default 20 suits 3-D). 280k-cell dam break: 6.5 -> 6.0 CG iterations
  // per step; 2.5-mm dam break over 577 steps: 10.8 -> 10.1 on 1 rank, 22.4 -> 21.1 on 2.
  if (p.get<std::string>("smoother: type") == "CHEBYSHEV" && !p.isSublist("level 0") && !p.isSublist("smoother: params")) {
    Teuchos::ParameterList& fine = p.sublist("level 0").sublist("smoother: params");
    fine.set("chebyshev: max eigenvalue", 2.0);
    fine.set("chebyshev: eigenvalue max iterations", 1);
    if (Dim == 2) fine.set("chebyshev: ratio eigenvalue", 6.0);
  }
  return p;
}

template <int Dim>
Teuchos::RCP<Operator> PressureSolver<Dim>::Impl::preparePreconditioner(PressureSolveReport& report, int kind)
{
  switch (settings.preconditioner) {
    case PreconditionerType::None:
      return Teuchos::null;
    case PreconditionerType::Jacobi:
      if (jacobi.is_null()) jacobi = Teuchos::rcp(new InverseDiagonal(*matrix));
      else if (values_changed) jacobi->update(*matrix);
      values_changed = false;
      return jacobi;
    case PreconditionerType::MueLu:
      break;
  }
  const bool rebuild = muelu.is_null() || rebuild_requested || solves_since_setup >= settings.reuse_interval;
  if (rebuild) {
    muelu = Teuchos::null;  // free the old hierarchy before building the new one
    Teuchos::ParameterList parameters = mueluParameters();
    parameters.sublist("user data").set("Coordinates", coordinates);
    muelu = MueLu::CreateTpetraPreconditioner(Teuchos::RCP<Operator>(matrix), parameters);
    solves_since_setup = 0;
    rebuild_requested = false;
    reference_due.fill(true);
    report.preconditioner_rebuilt = true;
  } else if (kind > 0 && !settings.refresh_corrections) {
    // A correction solve applies the hierarchy as the step's first solve left it; its finest level
    // sees the current matrix, which differs from the one refreshed for by the upwind sides of a
    // few faces (the ICE outer iteration). The next solve that may refresh does.
    return muelu;
  } else if (values_changed && settings.reuse_mode != ReuseMode::Frozen) {
    // Keep the coarse levels and recompute the finest level's smoother only (RAP), keep the
    // aggregates and the transfer operators (RP) or the tentative prolongator only (tP); recompute
    // the rest (smoothed prolongators for tP, coarse matrices, smoothers).
    MueLu::ReuseTpetraPreconditioner(matrix, *muelu);
  }
  // Frozen: the hierarchy built for older values is applied as it is (its finest level sees the
  // current matrix, which MueLu holds by reference).
  values_changed = false;
  return muelu;
}

template <int Dim>
double PressureSolver<Dim>::Impl::residualNorm(const MultiVector& b, const MultiVector& x,
                                               const ResidualMeasure& measure) const
{
  MultiVector& r = *residual;
  r.assign(b);
  matrix->apply(x, r, Teuchos::NO_TRANS, -1.0, 1.0);  // r = b - A x
  return measure(r);
}

/// CG (Belos's CG iteration) on A x = b from the current x, adding to the report: it stops when the
/// residual's measure is at most tolerance b_norm (b_norm: the measure of b). The stopping test
/// reads CG's recurrence residual, which can drift from the true one; if they disagree we restart
/// from the current iterate (a restart recomputes the residual), at most twice, within the iteration
/// budget. The preconditioner is applied on the right: Belos's CG applies a left or a right one the
/// same way (z = M^-1 r), but LinearProblem::setProblem() also computes the left-preconditioned
/// initial residual, which CG never reads, so on the right MueLu runs one V-cycle fewer per solve.
template <int Dim>
void PressureSolver<Dim>::Impl::runCG(const Teuchos::RCP<Operator>& preconditioner, const MultiVector& b,
                                      MultiVector& x, const ResidualMeasure& measure, double b_norm,
                                      double tolerance, PressureSolveReport& report) const
{
  using Problem = Belos::LinearProblem<Scalar, MultiVector, Operator>;
  using Combo = Belos::StatusTestCombo<Scalar, MultiVector, Operator>;
  auto problem = Teuchos::rcp(new Problem(matrix, Teuchos::rcpFromRef(x), Teuchos::rcpFromRef(b)));
  if (!preconditioner.is_null()) problem->setRightPrec(preconditioner);
  auto printer = Teuchos::rcp(new Belos::OutputManager<Scalar>(Belos::Errors + Belos::Warnings));
  const bool trace = settings.verbosity >= 2 && layout->comm()->getRank() == 0;
  int iterations = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    problem->setProblem();  // residual of the current iterate
    problem->setLSIndex(std::vector<int>{0});
    auto bound = Teuchos::rcp(new ResidualBoundTest(measure, tolerance * b_norm, trace));
    auto budget = Teuchos::rcp(
        new Belos::StatusTestMaxIters<Scalar, MultiVector, Operator>(settings.maximum_iterations - iterations));
    auto test = Teuchos::rcp(new Combo(Combo::OR, budget, bound));
    Teuchos::ParameterList options;  // asserts positive definiteness (Belos's default)
    Belos::CGIter<Scalar, MultiVector, Operator> cg(problem, printer, test, Teuchos::null, options);
    Belos::CGIterationState<Scalar, MultiVector> state;
    state.R = problem->getInitResVec();
    bool reached = false;
    try {
      cg.initializeCG(state);
      cg.iterate();
      reached = bound->getStatus() == Belos::Passed;
    } catch (const std::exception& e) {  // loss of positive definiteness, for one
      report.failure = e.what();
    }
    problem->setCurrLS();
    iterations += cg.getNumIters();
    report.relative_residual = residualNorm(b, x, measure) / b_norm;
    report.converged = report.relative_residual <= tolerance;
    if (report.converged || !reached || iterations >= settings.maximum_iterations) break;
  }
  report.iterations += iterations;
}

template <int Dim>
PressureSolver<Dim>::PressureSolver(std::shared_ptr<const Layout<Dim>> layout, const Teuchos::ParameterList& settings)
    : impl_(std::make_unique<Impl>())
{
  impl_->layout = std::move(layout);
  impl_->settings_list = settings;
  impl_->settings = readSettings(impl_->settings_list, *validParameters());
  impl_->buildGraph();
}

template <int Dim>
PressureSolver<Dim>::~PressureSolver() = default;

template <int Dim>
void PressureSolver<Dim>::checkSettings(const Teuchos::ParameterList& settings, const std::string& key_prefix)
{
  Teuchos::ParameterList copy = settings;
  readSettings(copy, *validParameters(), key_prefix);
}

template <int Dim>
Teuchos::RCP<const Teuchos::ParameterList> PressureSolver<Dim>::validParameters()
{
  auto p = Teuchos::rcp(new Teuchos::ParameterList("pressure solver"));
  p->set("tolerance", 1e-10, "CG stops when ||rhs - A dp|| / ||rhs|| is below this (checked with the true residual)");
  p->set("maximum iterations", 500,
         "CG iterations at most per preconditioner (a fresh one replacing a failed reused one gets its own)");
  p->set("preconditioner", std::string("muelu"),
         "muelu (smoothed aggregation, Chebyshev smoother), jacobi or none (the last two for comparison)");
  p->set("verbosity", 0, "0 quiet; 1 one line per solve on rank 0; 2 also every CG iteration's residual and MueLu's setup");
  p->set("reuse interval", 1, "a full MueLu setup every N solves (1: every solve)");
  p->set("reuse mode", std::string("RP"),
         "between full setups: RP keeps aggregates, prolongators and restrictions and recomputes the coarse "
         "matrices and smoothers; tP keeps the tentative prolongator only; RAP keeps the coarse levels and "
         "recomputes the finest level's smoother; frozen reuses the old hierarchy");
  p->set("reuse slowdown limit", 0.0,
         "0: off; else a full MueLu setup follows a solve whose reused hierarchy needed more than this factor "
         "times the CG iterations per decade of residual reduction of the last fresh hierarchy");
  p->set("refresh corrections", true,
         "true: every solve between full setups refreshes the hierarchy as `reuse mode` says; false: a solve "
         "of kind > 0 (the ICE step's correction solves) applies it as the last refresh left it");
  p->sublist("muelu", false, "MueLu parameters applied on top of cfdmpm's defaults");
  return p;
}

template <int Dim>
const Teuchos::ParameterList& PressureSolver<Dim>::settings() const
{
  return impl_->settings_list;
}

template <int Dim>
const Layout<Dim>& PressureSolver<Dim>::layout() const
{
  return *impl_->layout;
}

template <int Dim>
Teuchos::RCP<const typename PressureSolver<Dim>::Matrix> PressureSolver<Dim>::matrix() const
{
  return impl_->matrix;
}

template <int Dim>
void PressureSolver<Dim>::requestPreconditionerRebuild()
{
  impl_->rebuild_requested = true;
}

template <int Dim>
void PressureSolver<Dim>::assemble(const Field<Dim>& mixture_compressibility, FaceField<Dim>& face_coefficient,
                                   double dt)
{
  Impl& m = *impl_;
  const Layout<Dim>& lay = *m.layout;
  requireOneColumn(mixture_compressibility.columns(), mixture_compressibility.name(), "compressibility");
  for (int d = 0; d < Dim; ++d)
    requireOneColumn(face_coefficient.direction(d).columns(), face_coefficient.direction(d).name(), "face coefficient");
  if (!(dt > 0 && std::isfinite(dt))) throw std::invalid_argument("PressureSolver: dt must be > 0, got " + std::to_string(dt));

  Teuchos::TimeMonitor timer(*m.assemble_timer);
  // The upper face of an owned cell is the lower face of its neighbour, possibly a ghost.
  face_coefficient.exchangeHalo();

  // Kashiwa / Uintah impICE: a_nbr = -dt^2 (A_f / h_f) beta_f, a_cc = V kappa_c + sum_f dt^2 (A_f / h_f) beta_f.
  const double volume = lay.grid().cellVolume();
  double face_weight[3] = {0, 0, 0};  // dt^2 A_f / h_f = dt^2 V / h_d^2 per direction
  for (int d = 0; d < Dim; ++d) face_weight[d] = dt * dt * volume / (lay.grid().spacing()[d] * lay.grid().spacing()[d]);
  const double wx = face_weight[0], wy = face_weight[1], wz = face_weight[2];

  const auto kappa = mixture_compressibility.view();
  LowerFaceValues<Dim> beta;
  for (int d = 0; d < Dim; ++d) beta.direction[d] = face_coefficient.direction(d).view();
  const auto neighbours = lay.cellNeighbours();
  // The matrix's own values array (Serial: host memory; the graph is fixed, so no fill is resumed).
  const auto values = m.matrix->getLocalMatrixDevice().values;
  const auto offsets = m.stencil_offsets;
  const auto row_cell = m.row_cell;
  const LocalOrdinal rows = m.localRows();

  // The first row with a bad coefficient (rows when there is none).
  LocalOrdinal first_bad_row = rows;
  Kokkos::parallel_reduce(
      "pressure matrix values", Kokkos::RangePolicy<ExecutionSpace>(0, rows),
      KOKKOS_LAMBDA(const LocalOrdinal k, LocalOrdinal& bad) {
        const LocalOrdinal c = row_cell(k);
        const double weight[3] = {wx, wy, wz};
        double diagonal = volume * kappa(c, 0);
        bool ok = kappa(c, 0) > 0 && kappa(c, 0) < INFINITY;
        for (int f = 0; f < 2 * Dim; ++f) {
          if (offsets(k, 1 + f) == Impl::kNoEntry) continue;  // wall: zero normal gradient, no flux, no entry
          const LocalOrdinal n = neighbours(c, f);
          const int d = f / 2;
          const double b = beta(d, f % 2 == 0 ? c : n);  // lower face of c, or of the upper neighbour
          ok = ok && b >= 0 && b < INFINITY;
          const double a = weight[d] * b;
          values(offsets(k, 1 + f)) = -a;
          diagonal += a;
        }
        values(offsets(k, 0)) = diagonal;
        if (!ok && k < bad) bad = k;
      },
      Kokkos::Min<LocalOrdinal>(first_bad_row));
  const LocalOrdinal owned = lay.ownedCells();
  LocalOrdinal first_bad = owned;
  if (first_bad_row < rows) Kokkos::deep_copy(first_bad, Kokkos::subview(row_cell, first_bad_row));

  // A bad coefficient on any rank stops every rank (so none waits in a collective), with the
  // message of the lowest rank that found one.
  const int ranks = lay.comm()->getSize();
  int reporter = first_bad < owned ? lay.comm()->getRank() : ranks, first_reporter = ranks;
  Teuchos::reduceAll(*lay.comm(), Teuchos::REDUCE_MIN, reporter, Teuchos::outArg(first_reporter));
  if (first_reporter < ranks) {
    m.assembled = false;  // the values are partly overwritten: no solve with this matrix
    std::ostringstream message;
    message << "pressure equation: ";
    if (reporter == first_reporter) {
      message << lay.grid().cellName(lay.ownedCellMap()->getGlobalElement(first_bad)) << " has compressibility "
              << kappa(first_bad, 0) << " 1/Pa (must be > 0) or a face coefficient that is negative or not finite"
              << " (faces x-, x+, y-, y+" << (Dim == 3 ? ", z-, z+" : "") << ":";
      for (int f = 0; f < 2 * Dim; ++f) {
        const LocalOrdinal n = neighbours(first_bad, f);
        if (n < 0) message << " wall";
        else message << " " << beta.direction[f / 2](f % 2 == 0 ? first_bad : n, 0);
      }
      message << " m^3/kg)";
    }
    throw StepFailure(broadcastText(rawMpiComm(lay.comm()), first_reporter, message.str()));
  }

  m.assembled = true;
  m.values_changed = true;
}

template <int Dim>
void PressureSolver<Dim>::apply(const Field<Dim>& x, Field<Dim>& y) const
{
  if (!impl_->assembled) throw std::logic_error("PressureSolver::apply before assemble");
  requireOneColumn(x.columns(), x.name(), "x");
  requireOneColumn(y.columns(), y.name(), "y");
  const Impl& m = *impl_;
  if (m.every_cell_a_row) {
    m.matrix->apply(x.owned(), y.owned());
    return;
  }
  m.gather(x.owned(), *m.rows_x);
  m.matrix->apply(*m.rows_x, *m.rows_y);
  m.scatter(*m.rows_y, y.owned());
}

template <int Dim>
bool PressureSolver<Dim>::excludeCells(const CellMask& excluded)
{
  Impl& m = *impl_;
  const Layout<Dim>& lay = *m.layout;
  const bool given = excluded.extent(0) > 0, held = m.excluded.extent(0) > 0;
  if (given && excluded.extent(0) < std::size_t(lay.ownedCells()))
    throw std::invalid_argument("PressureSolver::excludeCells: the mask has fewer entries than owned cells");
  // Owned cells whose state differs from the graph's, on this rank, then on any.
  long long changed = 0, changed_anywhere = 0;
  const auto now = excluded;
  const auto before = m.excluded;
  Kokkos::parallel_reduce(
      "pressure solver: excluded cells changed", Kokkos::RangePolicy<ExecutionSpace>(0, lay.ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c, long long& count) {
        const bool out_now = given && now(c) != 0, out_before = held && before(c) != 0;
        if (out_now != out_before) ++count;
      },
      changed);
  Teuchos::reduceAll(*lay.comm(), Teuchos::REDUCE_SUM, changed, Teuchos::outArg(changed_anywhere));
  if (changed_anywhere == 0) return false;
  if (given) {
    m.excluded = CellMask("pressure solver excluded cells", excluded.extent(0));
    Kokkos::deep_copy(m.excluded, excluded);
  } else {
    m.excluded = CellMask();
  }
  m.buildGraph();
  return true;
}

template <int Dim>
long long PressureSolver<Dim>::rows() const
{
  return impl_->global_rows;
}

template <int Dim>
PressureSolveReport PressureSolver<Dim>::solve(const Field<Dim>& rhs, Field<Dim>& solution, double residual_target,
                                               int kind, const Field<Dim>* residual_weight)
{
  Impl& m = *impl_;
  if (!m.assembled) throw std::logic_error("PressureSolver::solve before assemble");
  requireOneColumn(rhs.columns(), rhs.name(), "rhs");
  requireOneColumn(solution.columns(), solution.name(), "solution");
  if (!(residual_target >= 0)) throw std::invalid_argument("PressureSolver::solve: residual target must be >= 0");
  const Settings& s = m.settings;
  PressureSolveReport report;

  // Over the rows: the fields' owned parts themselves, or gathered from the cells that have rows.
  const bool gathered = !m.every_cell_a_row;
  if (gathered) {
    m.gather(rhs.owned(), *m.rows_b);
    m.gather(solution.owned(), *m.rows_x);
  }
  const MultiVector& b = gathered ? *m.rows_b : rhs.owned();
  MultiVector& x = gathered ? *m.rows_x : solution.owned();
  if (m.residual.is_null()) {
    m.residual = Teuchos::rcp(new MultiVector(b.getMap(), 1, false));
    m.guess = Teuchos::rcp(new MultiVector(b.getMap(), 1, false));
    m.weighted = Teuchos::rcp(new MultiVector(b.getMap(), 1, false));
  }
  // The measure of the stopping test: the 2-norm, or with an absolute target the largest entry (the
  // caller bounds every cell's residual, and the 2-norm can exceed it by up to sqrt(cells)), each
  // entry times the caller's weight if there is one.
  ResidualMeasure measure;
  measure.norm = residual_target > 0 ? Belos::InfNorm : Belos::TwoNorm;
  if (residual_target > 0 && residual_weight) {
    requireOneColumn(residual_weight->columns(), residual_weight->name(), "residual weight");
    if (gathered) m.gather(residual_weight->owned(), *m.rows_weight);
    measure.weight = (gathered ? *m.rows_weight : residual_weight->owned()).getVector(0);
    measure.scratch = m.weighted;
  }
  const double b_norm = measure(b);
  if (b_norm == 0) {  // A is SPD, so the answer is exactly zero
    solution.owned().putScalar(0);
    solution.exchangeHalo();
    report.converged = true;
    return report;
  }
  // The relative tolerance of this solve: the settings' one, or looser when the caller's absolute
  // target allows it (never looser than 0.5: CG must reduce the residual at all).
  report.tolerance = std::min(std::max(s.tolerance, residual_target / b_norm), 0.5);

  // 1. Preconditioner: built, refreshed or reused.
  Clock::time_point start = Clock::now();
  Teuchos::RCP<Operator> preconditioner;
  {
    Teuchos::TimeMonitor timer(*m.setup_timer);
    preconditioner = m.preparePreconditioner(report, kind);
  }
  report.setup_seconds = secondsSince(start);
  const bool reused = s.preconditioner == PreconditionerType::MueLu && !report.preconditioner_rebuilt;
  if (reused) m.guess->assign(x);

  // 2. CG from the caller's guess.
  start = Clock::now();
  {
    Teuchos::TimeMonitor timer(*m.cg_timer);
    m.runCG(preconditioner, b, x, measure, b_norm, report.tolerance, report);
  }
  report.solve_seconds = secondsSince(start);

  // 3. A reused hierarchy may no longer suit the matrix (a frozen Chebyshev smoother that meets
  //    changed coefficients can make the preconditioner indefinite and CG break down): build a
  //    fresh one and start again from the caller's guess.
  if (!report.converged && reused) {
    m.rebuild_requested = true;
    start = Clock::now();
    {
      Teuchos::TimeMonitor timer(*m.setup_timer);
      preconditioner = m.preparePreconditioner(report, kind);  // rebuilt (requested above)
    }
    report.setup_seconds += secondsSince(start);
    start = Clock::now();
    x.assign(*m.guess);
    report.failure.clear();
    {
      Teuchos::TimeMonitor timer(*m.cg_timer);
      m.runCG(preconditioner, b, x, measure, b_norm, report.tolerance, report);
    }
    report.solve_seconds += secondsSince(start);
  }
  if (gathered) m.scatter(x, solution.owned());
  solution.exchangeHalo();
  ++m.solves_since_setup;

  // 4. Has the reused hierarchy grown stale? Compare the iterations per decade of reduction of
  //    ||rhs − A x|| / ||rhs|| with those of this kind's first solve with the hierarchy (the
  //    caller's guess counts as no better than zero, so a good guess can only make a reused
  //    hierarchy look better).
  if (s.preconditioner == PreconditionerType::MueLu && report.converged && report.iterations > 0 &&
      report.relative_residual > 0 && report.relative_residual < 0.1) {
    const double per_decade = report.iterations / -std::log10(report.relative_residual);
    const int k = std::clamp(kind, 0, kSolveKinds - 1);
    double& fresh = m.fresh_iterations_per_decade[k];
    // After a failed reuse the count includes the failed attempt: the next solve of this kind,
    // with the hierarchy built here, gives the reference.
    const bool counts_failed_attempt = report.preconditioner_rebuilt && reused;
    if (m.reference_due[k]) {
      if (!counts_failed_attempt) {
        fresh = per_decade;
        m.reference_due[k] = false;
      }
    } else if (s.reuse_slowdown_limit > 0 && fresh > 0 && per_decade > s.reuse_slowdown_limit * fresh) {
      m.rebuild_requested = true;
    }
  }

  if (s.verbosity >= 1 && m.layout->comm()->getRank() == 0) {
    std::cout << "pressure solve: " << report.iterations << " CG iterations, relative residual "
              << std::scientific << std::setprecision(2) << report.relative_residual << " (tolerance "
              << report.tolerance << ")" << std::defaultfloat << (report.converged ? "" : " (NOT CONVERGED)")
              << ", setup " << report.setup_seconds << " s"
              << (report.preconditioner_rebuilt ? " (new preconditioner)" : "") << ", solve "
              << report.solve_seconds << " s\n";
  }
  return report;
}

template class PressureSolver<2>;
template class PressureSolver<3>;

}  // namespace cfdmpm
