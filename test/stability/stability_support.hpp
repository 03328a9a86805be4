#pragma once
// Helpers of the stability cases (doc/stability.md): each case writes its sweep as a small CSV
// (parameter, value, method, status) that utilities/stability_map.py draws.
#include "../mpmice/coupled_support.hpp"
#include "common/error.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <string>

namespace cfdmpm::test {

/// One row of a sweep: the swept parameter, the measured value (an error, a growth factor), the
/// method that gave it, and "ok" or "failed" (the run stopped, or left the bound of its case).
struct SweepRow {
  double parameter;
  double value;
  std::string method;
  std::string status;
};

/// Writes rows as <directory>/<name>_np<ranks>.csv on rank 0: the directory is $CFDMPM_STABILITY_DIR when set,
/// else the working directory (ctest's: build/test/stability). The header names the columns, and a
/// comment line before it names the quantities. The method is quoted (it may hold commas).
inline void writeSweep(const Teuchos::Comm<int>& comm, const std::string& name, const std::string& parameter,
                       const std::string& value, const std::vector<SweepRow>& rows,
                       const std::vector<std::pair<std::string, double>>& thresholds = {})
{
  if (comm.getRank() != 0) return;
  const char* dir = std::getenv("CFDMPM_STABILITY_DIR");
  const std::string path = (dir && *dir ? std::string(dir) + "/" : std::string()) + name + "_np" +
                           std::to_string(comm.getSize()) + ".csv";
  std::ofstream out(path);
  out << "# " << name << ": " << parameter << " against " << value << "; ranks " << comm.getSize() << "\n";
  for (const auto& [label, at] : thresholds) out << "# threshold " << label << " = " << std::setprecision(6) << at << "\n";
  out << "parameter,value,method,status\n";
  out << std::setprecision(10);
  for (const SweepRow& r : rows) out << r.parameter << "," << r.value << ",\"" << r.method << "\"," << r.status << "\n";
  std::cout << "stability: wrote " << path << " (" << rows.size() << " rows)\n";
}

/// Free-slip walls on every face of a 2-D box (YAML of `boundary_conditions`).
inline const char* freeSlipBox()
{
  return R"(  boundary_conditions:
    x-: {velocity: free_slip}
    x+: {velocity: free_slip}
    y-: {velocity: free_slip}
    y+: {velocity: free_slip}
)";
}

}  // namespace cfdmpm::test
