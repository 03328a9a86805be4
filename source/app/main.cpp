// cfdmpm: the program. Run as `cfdmpm [options] scene.yaml`, under `mpiexec -n N` for N ranks.
#include "input/scene.hpp"
#include "mpmice/simulation.hpp"

#include <Tpetra_Core.hpp>

#include <cstring>
#include <iostream>
#include <string>

namespace {

const char* kUsage =
    "usage: cfdmpm [options] scene.yaml\n"
    "       mpiexec -n N cfdmpm [options] scene.yaml\n"
    "\n"
    "Runs a debris-flow scene: fluids by a multi-material ICE method, solids by the Material Point\n"
    "Method, on one Cartesian grid. The scene file's keys are documented in doc/input.md.\n"
    "\n"
    "options:\n"
    "  --overwrite   replace the output of an earlier run in the scene's output directory\n"
    "  --check       validate the scene file and stop\n"
    "  --help        print this help\n"
    "  --version     print the version\n"
    "\n"
    "exit codes: 0 success, 1 run-time failure, 2 bad input or bad command line\n";

struct CommandLine {
  std::string scene;
  cfdmpm::RunOptions options;
  bool check_only = false;
};

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
  if (command.scene.empty()) {
    std::cerr << "cfdmpm: error: no scene file given\n" << kUsage;
    return 2;
  }

  // 2. MPI and Kokkos live as long as the guard; every Tpetra object dies inside the block.
  Tpetra::ScopeGuard tpetra(&argc, &argv);
  const auto comm = Tpetra::getDefaultComm();
  const bool root = comm->getRank() == 0;
  try {
    // 3. Read and validate the scene on every rank; a bad file stops here, before any output.
    const cfdmpm::Scene scene = cfdmpm::readScene(command.scene);
    if (command.check_only) {
      if (root) std::cout << "cfdmpm: " << command.scene << " is valid\n";
      return 0;
    }
    // 4. Run it.
    const cfdmpm::RunSummary summary = cfdmpm::runScene(scene, command.options, comm);
    if (root) {
      std::cout << "cfdmpm: output in " << summary.output_directory << "\n"
                << "  fields (open in ParaView): " << summary.time_series << "\n"
                << "  diagnostics: " << summary.diagnostics << "\n";
      if (summary.stopped_by_signal) std::cout << "cfdmpm: stopped by a signal; the files written are complete\n";
    }
    return 0;
  } catch (const cfdmpm::InputError& e) {
    if (root) std::cerr << "cfdmpm: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "cfdmpm: rank " << comm->getRank() << ": failure: " << e.what() << "\n";
    return 1;
  }
}
