// cfdmpm: the program. Run as `cfdmpm scene.yaml` (under `mpiexec -n N` for N ranks).
#include <Tpetra_Core.hpp>
#include <iostream>

int main(int argc, char** argv)
{
  Tpetra::ScopeGuard tpetra(&argc, &argv);
  std::cout << "cfdmpm " << CFDMPM_VERSION << "\n";
  return 0;
}
