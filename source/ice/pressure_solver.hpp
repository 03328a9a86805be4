#pragma once
// The implicit pressure equation of the ICE step (Kashiwa's cell-centred ICE; Uintah impICE): per
// owned cell c of volume V, for the pressure correction δp,
//
//   V κ_c δp_c − Δt² Σ_faces (A_f / h_f) β_f (δp_neighbour − δp_c) = rhs_c,   β_f = Σ_m θ_f,m v_f,m
//
// with κ_c = Σ_m θ_m κ_m the mixture compressibility (1/Pa), A_f the face area, h_f the cell spacing
// normal to the face and β_f (m^3/kg) the face sum of volume fraction times specific volume. Domain
// faces are walls: no flux (zero normal gradient of δp). The matrix is symmetric positive definite
// when κ > 0 and β ≥ 0; it is solved with Belos CG preconditioned by MueLu smoothed aggregation.
//
// The sparsity graph is built once per layout and set of excluded cells; assemble() only replaces
// values, and solve() builds or reuses the preconditioner. Cells that the caller excludes (cells that
// rigid bodies fill, walls to the fluids) have no row: the matrix and the preconditioner are built
// over the other cells, numbered consecutively rank by rank. See doc/ice-pressure.md for the matrix
// entries and the settings.
//
// Belos and MueLu are confined to pressure_solver.cpp (they are costly to compile); this header
// only forward-declares the matrix type.
#include "fields/field.hpp"
#include "ice/face_field.hpp"

#include <Teuchos_ParameterList.hpp>
#include <Teuchos_RCP.hpp>
#include <Tpetra_CrsMatrix_fwd.hpp>

#include <memory>
#include <string>

namespace cfdmpm {

/// What one pressure solve did. `converged` is true only when the true relative residual
/// ||b − A x|| / ||b|| (in the norm of the solve, see solve()), computed after the solve, is at most
/// the tolerance; the caller decides what
/// to do with an unconverged answer (Uintah restarts the time step with a smaller Δt).
struct PressureSolveReport {
  int iterations = 0;                   // CG iterations, summed over restarts and a fallback setup
  double relative_residual = 0;         // true residual ||b − A x|| / ||b|| (0 when b = 0)
  double tolerance = 0;                 // the relative tolerance this solve used (see solve())
  bool converged = false;
  bool preconditioner_rebuilt = false;  // a full MueLu setup happened in this solve (scheduled,
                                        // requested, or after a solve with a reused one failed)
  double setup_seconds = 0;             // preconditioner setup (full or reuse), this rank's wall time
  double solve_seconds = 0;             // CG iterations and the true-residual check
  std::string failure;                  // why Belos stopped, when it threw; empty otherwise
};

template <int Dim>
class PressureSolver {
 public:
  using Matrix = Tpetra::CrsMatrix<Scalar, LocalOrdinal, GlobalOrdinal, Node>;

  /// Builds the 5-point (2-D) or 7-point (3-D) graph on the layout's owned cells. `settings` is
  /// checked against validParameters() (unknown keys and bad values throw InputError); missing
  /// keys take their defaults. The layout needs a ghost width of at least 1.
  PressureSolver(std::shared_ptr<const Layout<Dim>> layout,
                 const Teuchos::ParameterList& settings = Teuchos::ParameterList());
  ~PressureSolver();
  PressureSolver(const PressureSolver&) = delete;
  PressureSolver& operator=(const PressureSolver&) = delete;

  /// The accepted settings with their defaults and documentation:
  ///   "tolerance" (1e-10, relative to ||rhs||), "maximum iterations" (500, per preconditioner),
  ///   "preconditioner" ("muelu" | "jacobi" | "none"), "verbosity" (0 quiet, 1 one line per solve,
  ///   2 plus Belos and MueLu output), "reuse interval" (1: a full MueLu setup every solve; N: every
  ///   N solves), "reuse mode" ("RAP" | "RP" | "tP" | "frozen": what happens between full setups),
  ///   "reuse slowdown limit" (0 off; else a full setup follows a reused solve that needed this
  ///   factor more iterations per decade than the last fresh hierarchy), "refresh corrections"
  ///   (true; false: a solve of kind > 0 applies the hierarchy as the last refresh left it), and a
  ///   sublist "muelu" passed to MueLu on top of cfdmpm's defaults.
  static Teuchos::RCP<const Teuchos::ParameterList> validParameters();
  /// Checks settings as the constructor does, without building anything: throws InputError for an
  /// unknown key, a wrong type or a bad value, the key named after `key_prefix`. The "muelu"
  /// sublist is checked by MueLu when the preconditioner is first built.
  static void checkSettings(const Teuchos::ParameterList& settings, const std::string& key_prefix);
  /// The settings in use, defaults filled in.
  const Teuchos::ParameterList& settings() const;

  /// One entry per overlap cell (owned cells first, then ghosts, as the layout orders them); nonzero:
  /// the cell is left out of the equation.
  using CellMask = Kokkos::View<unsigned char*, MemorySpace>;
  /// Leaves out of the equation the owned cells whose entry of `excluded` is nonzero (an empty view:
  /// none): they get no row, and a face towards one is a wall (no entry; its coefficient is not
  /// read). solve() returns δp = 0 there and apply() y = 0. Only the owned entries are read; whether
  /// a neighbour on another rank is excluded is its owner's entry. When the set differs from the one
  /// the graph was built for, on any rank, the graph is built again (the matrix then needs an
  /// assemble() and the next solve a fresh preconditioner) and true is returned, on every rank.
  /// Collective.
  bool excludeCells(const CellMask& excluded);
  /// Rows of the matrix over all ranks (the cells not excluded).
  long long rows() const;

  /// Fills the matrix values for this step (the graph is not rebuilt).
  ///   mixture_compressibility: κ_c (1/Pa), 1 column, owned cells read; must be > 0 (excluded cells:
  ///     not read).
  ///   face_coefficient: β_f (m^3/kg), 1 column, on the lower face of each cell (face_field.hpp);
  ///     must be >= 0. Its halo is exchanged here, because the upper face of an owned cell is the
  ///     lower face of its neighbour, which may live on another rank.
  ///   dt: the time step (s).
  /// Throws std::runtime_error on every rank if any rank finds a bad coefficient.
  void assemble(const Field<Dim>& mixture_compressibility, FaceField<Dim>& face_coefficient, double dt);

  /// Solves A δp = rhs. `solution` holds the initial guess on entry (warm start) and the answer on
  /// return, with its ghost entries exchanged. Both fields have 1 column; owned rows of rhs are read.
  /// CG stops when the true residual ||rhs − A δp||₂ is at most tolerance ||rhs||₂. A caller whose
  /// own convergence test needs no more than an absolute bound on every cell's residual (the ICE
  /// outer iteration) passes it as residual_target > 0: then the residual's largest entry is tested,
  /// max_c |rhs − A δp|_c <= max(tolerance max_c |rhs_c|, residual_target) (and <= 0.5 max_c |rhs_c|).
  /// Never throws for an unconverged solve: see the report. When a solve with a reused MueLu
  /// hierarchy fails, a fresh hierarchy is built and the solve repeated from the initial guess.
  /// kind (0 .. kSolveKinds − 1, larger values count as the last): the `reuse slowdown limit` test
  /// compares a solve only with fresh-hierarchy solves of the same kind, so that a caller whose
  /// solves differ in character (the ICE outer iteration: a first solve of a step reduces its
  /// residual by ~6 decades, a correction solve by ~4, in fewer iterations per decade) passes which
  /// is which; otherwise every first solve looks slowed down against the last correction solve.
  /// residual_weight (1 column, > 0, owned rows read; used with residual_target > 0 only): each
  /// cell's entry of the residual and of rhs in that test is multiplied by its weight, for a caller
  /// whose own test weighs the cells (the ICE outer test: a cell softer than water needs its volume
  /// matched less closely); the report's relative residual is then the weighted one.
  PressureSolveReport solve(const Field<Dim>& rhs, Field<Dim>& solution, double residual_target = 0, int kind = 0,
                            const Field<Dim>* residual_weight = nullptr);
  static constexpr int kSolveKinds = 4;

  /// y = A x on the owned cells (x's ghosts are not read; y's ghosts are not written; y = 0 in the
  /// excluded cells).
  void apply(const Field<Dim>& x, Field<Dim>& y) const;

  /// The next solve does a full preconditioner setup, whatever the reuse interval.
  void requestPreconditionerRebuild();

  /// The assembled matrix (rows: the owned cells, or with excluded cells the others, numbered
  /// consecutively from rank 0 up; column map built by Tpetra from the stencil).
  Teuchos::RCP<const Matrix> matrix() const;
  const Layout<Dim>& layout() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

extern template class PressureSolver<2>;
extern template class PressureSolver<3>;

}  // namespace cfdmpm
