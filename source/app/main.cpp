// cfdmpm: the program. Run as `cfdmpm [options] scene.yaml`, under `mpiexec -n N` for N ranks.
#include "input/parameter_rule.hpp"
#include "input/scene.hpp"
#include "input/scene_checks.hpp"
#include "common/error.hpp"
#include "common/mpi_comm.hpp"
#include "mpmice/checkpoint.hpp"
#include "mpmice/simulation.hpp"

#include <Tpetra_Core.hpp>

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>

namespace {

const char* kUsage =
    "usage: cfdmpm [options] scene.yaml\n"
    "       mpiexec -n N cfdmpm [options] scene.yaml\n"
    "       mpiexec -n N cfdmpm --restart <checkpoint file or output directory> [scene.yaml]\n"
    "\n"
    "Runs a debris-flow scene: fluids by a multi-material ICE method, solids by the Material Point\n"
    "Method, on one Cartesian grid. The scene file's keys are documented in doc/input.md.\n"
    "\n"
    "options:\n"
    "  --overwrite   replace the output of an earlier run in the scene's output directory\n"
    "  --check       validate the scene file and stop: every check a run makes before its first\n"
    "                step (run it under mpiexec -n N to check the patches for N ranks), and what\n"
    "                each region places\n"
    "  --restart P   continue a run from a checkpoint (output.checkpoint_interval or\n"
    "                output.checkpoint_wall_interval; doc/output.md): P is a checkpoint file or an\n"
    "                output directory (its newest checkpoint in P/checkpoints/). The run goes on in\n"
    "                the directory holding the checkpoint, with the scene stored in the checkpoint,\n"
    "                or with scene.yaml when given (same grid and materials; e.g. a later\n"
    "                time.end_time). Step files and CSV rows after the checkpoint are rewritten. On\n"
    "                as many ranks as the first run the result is bit for bit that of a run that\n"
    "                never stopped; on another number of ranks it agrees to round-off\n"
    "  --help        print this help\n"
    "  --version     print the version\n"
    "\n"
    "exit codes: 0 the run reached its end (or --check passed), 1 run-time failure (such as a step\n"
    "            that still failed after time.step_retries retries with half the time step: the last\n"
    "            good state is written as a step file and a checkpoint), 2 bad input or\n"
    "            bad command line (a missing or unreadable checkpoint too),\n"
    "            3 stopped by SIGINT or SIGTERM before its end (the files written are complete, and\n"
    "            with checkpoints on a last checkpoint is written; a second signal ends the program\n"
    "            at once)\n";

struct CommandLine {
  std::string scene;
  std::string restart;  // checkpoint file or output directory
  cfdmpm::RunOptions options;
  bool check_only = false;
};

// Whether two paths name the same directory (either may not exist yet).
bool sameDirectory(const std::string& a, const std::string& b)
{
  std::error_code error;
  const auto ca = std::filesystem::weakly_canonical(a, error);
  const auto cb = std::filesystem::weakly_canonical(b, error);
  return error ? a == b : ca == cb;
}

/// Writes a message with one write() call, so that the lines of ranks failing together do not
/// interleave within a line (writes of up to PIPE_BUF bytes to a pipe are atomic).
void writeError(const std::string& message)
{
  const std::string text = message.back() == '\n' ? message : message + "\n";
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(STDERR_FILENO, text.data() + done, text.size() - done);
    if (n <= 0) break;
    done += std::size_t(n);
  }
}

/// One line per region: what it places on its own (later regions may overwrite part of it).
void printPlacements(const cfdmpm::Scene& scene)
{
  for (const cfdmpm::RegionPlacement& p : cfdmpm::regionPlacements(scene)) {
    std::cout << "  region " << p.region << ": " << p.material << ", ";
    if (p.points < 0)
      std::cout << "(too large to count)";
    else if (p.solid)
      std::cout << cfdmpm::showNumber(p.points) << " particles (" << cfdmpm::showNumber(std::round(p.cells * 10) / 10)
                << " cells' worth)";
    else
      std::cout << cfdmpm::showNumber(std::round(p.cells * 10) / 10) << " cells' worth";
    std::cout << "\n";
  }
}

}  // namespace

int main(int argc, char** argv)
{
  // 1. Arguments first: --help and --version need neither MPI nor a scene.
  CommandLine command;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (arg == "--version") {
      std::cout << "cfdmpm " << CFDMPM_VERSION << "\n";
      return 0;
    }
    if (arg == "--overwrite") {
      command.options.overwrite = true;
    } else if (arg == "--check") {
      command.check_only = true;
    } else if (arg == "--restart") {
      if (i + 1 >= argc || argv[i + 1][0] == '\0') {
        std::cerr << "cfdmpm: error: --restart needs a checkpoint file or an output directory\n" << kUsage;
        return 2;
      }
      command.restart = argv[++i];
    } else if (!arg.empty() && arg[0] == '-') {
      std::cerr << "cfdmpm: error: unknown option '" << arg << "'\n" << kUsage;
      return 2;
    } else if (command.scene.empty()) {
      command.scene = arg;
    } else {
      std::cerr << "cfdmpm: error: more than one scene file given ('" << command.scene << "', '" << arg
                << "')\n";
      return 2;
    }
  }
  if (command.scene.empty() && command.restart.empty()) {
    std::cerr << "cfdmpm: error: no scene file given\n" << kUsage;
    return 2;
  }
  if (!command.restart.empty() && command.check_only) {
    std::cerr << "cfdmpm: error: --check and --restart do not go together\n" << kUsage;
    return 2;
  }

  // 2. MPI and Kokkos live as long as the guard; every Tpetra object dies inside the block.
  Tpetra::ScopeGuard tpetra(&argc, &argv);
  const auto comm = Tpetra::getDefaultComm();
  const bool root = comm->getRank() == 0;
  try {
    // 3. Read and validate the scene on every rank; a bad file stops here, before any output. A
    //    restart takes the scene the checkpoint keeps, or the one given if it fits the checkpoint,
    //    and goes on in the checkpoint's output directory.
    cfdmpm::Scene scene;
    if (command.restart.empty()) {
      scene = cfdmpm::readScene(command.scene);
    } else {
      const std::string checkpoint = cfdmpm::findCheckpoint(command.restart);
      const cfdmpm::CheckpointHeader header = cfdmpm::readCheckpointHeader(cfdmpm::rawMpiComm(comm), checkpoint);
      const cfdmpm::Scene stored = cfdmpm::readSceneText(header.scene_text, header.scene_path);
      scene = stored;
      if (!command.scene.empty()) {
        scene = cfdmpm::readScene(command.scene);
        cfdmpm::checkRestartScene(scene, stored);
      }
      // The given scene's output directory is not used: say so before the restart trims the
      // checkpoint's directory to the checkpoint's step (doc/output.md).
      if (!command.scene.empty() && root && !sameDirectory(scene.output.directory, header.output_directory))
        std::cout << "cfdmpm: the restart continues in " << header.output_directory
                  << ", the checkpoint's output directory, removing what that run wrote after the checkpoint; "
                  << command.scene << "'s output.directory '" << scene.output.directory << "' is not used\n";
      scene.output.directory = header.output_directory;
      command.options.restart_checkpoint = checkpoint;
      command.options.run_name = header.run_name;
      command.options.overwrite = true;  // the directory holds the run being continued
    }
    //    Then the set-up checks that depend on the ranks and the machine (memory, patches per
    //    rank, output directory), nothing created; the run makes them again as it sets up.
    cfdmpm::checkSetUp(scene, comm, command.options.overwrite);
    if (command.check_only) {
      if (root) {
        std::cout << "cfdmpm: " << command.scene << " is valid for " << comm->getSize() << " rank(s)\n";
        printPlacements(scene);
      }
      return 0;
    }
    // 4. Run it.
    const cfdmpm::RunSummary summary = cfdmpm::runScene(scene, command.options, comm);
    if (root) {
      std::cout << "cfdmpm: output in " << summary.output_directory << "\n"
                << "  fields (open in ParaView): " << summary.time_series << "\n"
                << "  diagnostics: " << summary.diagnostics << "\n";
      // Undone steps cost their attempts: many of them say the time step's limits miss something
      // in the scene (the log's "undone" lines name the cell, material and quantity of each).
      if (summary.retried_steps > 0)
        std::cout << "  retried steps: " << summary.retried_steps << " (" << summary.undone_attempts
                  << " attempts undone) in this run to step " << summary.steps
                  << "; the CSV's column retries and the log's 'undone' lines say which and why\n";
    }
    // A run stopped by SIGINT or SIGTERM before its end time did not finish: exit 3 on every rank
    // (stopped_by_signal is the same on all of them).
    const double end = scene.time.end_time;
    if (summary.stopped_by_signal && summary.time < end - 1e-12 * end) {
      if (root)
        std::cout << "cfdmpm: stopped by a signal at t = " << cfdmpm::showNumber(summary.time) << " s of "
                  << cfdmpm::showNumber(end) << " s; the files written are complete\n";
      return 3;
    }
    return 0;
  } catch (const cfdmpm::InputError& e) {
    if (root) writeError(std::string("cfdmpm: error: ") + e.what());
    return 2;
  } catch (const cfdmpm::StepFailure& e) {
    // Thrown on every rank with the same message.
    if (root) writeError(std::string("cfdmpm: error: ") + e.what());
    return 1;
  } catch (const std::exception& e) {
    writeError("cfdmpm: rank " + std::to_string(comm->getRank()) + ": failure: " + e.what());
    return 1;
  }
}
