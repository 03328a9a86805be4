// Per-phase profile of a cfdmpm run, for the scaling estimates (doc/scaling.md): a library loaded
// with LD_PRELOAD into an unchanged program,
//
//     LD_PRELOAD=build/bench/libcfdmpm_phase_profile.so mpiexec -n 4 build/cfdmpm scene.yaml
//
// It takes the Teuchos timers "mpmice: <phase>" of the coupled step (MpmIceStep::kPhases) and
// "cfdmpm: <what>" of the driver as phase markers (it interposes Teuchos::Time::start and stop) and
// the MPI calls (through their PMPI names): per phase, on every rank, the wall time, the time spent
// inside MPI, the point-to-point messages sent with their bytes and distinct destinations, and the
// collectives (reductions, and the others). MPI calls outside a phase count for "driver" (Δt, CSV
// sums, output). The first CFDMPM_PROFILE_SKIP steps (default 2: the first MueLu set-up and the
// start of the run) are left out; CFDMPM_PROFILE_NESTED=1 adds the fluid step's own timers. At
// MPI_Finalize rank 0 prints, per step, the slowest rank's and the mean figures; with
// CFDMPM_PROFILE_JSON=<file> it also writes them as JSON.
#include <Teuchos_Time.hpp>

#include <dlfcn.h>
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

struct PhaseCounts {
  double seconds = 0;       // wall time inside the phase (its own, nested phases excluded)
  double mpi_seconds = 0;   // of which inside MPI calls
  double entries = 0;       // times the phase was entered
  double messages = 0;      // point-to-point messages sent
  double bytes = 0;         // their bytes
  double reductions = 0;    // MPI_Allreduce, MPI_Reduce, MPI_Scan (and non-blocking ones)
  double reduction_bytes = 0;
  double collectives = 0;   // every other collective (Alltoall, Bcast, Allgather, Barrier, ...)
  std::set<int> destinations;
};

constexpr int kFields = 9;  // numbers per phase in the reduction at the end

struct Profile {
  std::map<std::string, PhaseCounts> phases;
  std::vector<std::string> stack{"driver"};
  std::vector<double> entered{0.0};  // wall time when the phase on top was (re)entered
  long long steps = 0, skip = 2;
  bool counting = false;
  int depth_in_mpi = 0;

  static double now()
  {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  PhaseCounts& current() { return phases[stack.back()]; }
  // Time up to now goes to the phase on top.
  void charge()
  {
    const double t = now();
    if (counting) current().seconds += t - entered.back();
    entered.back() = t;
  }
};

Profile& profile()
{
  static Profile* p = [] {
    auto* q = new Profile;
    if (const char* skip = std::getenv("CFDMPM_PROFILE_SKIP")) q->skip = std::atoll(skip);
    q->counting = q->skip == 0;
    q->entered.back() = Profile::now();
    return q;
  }();
  return *p;
}

// With CFDMPM_PROFILE_NESTED=1 the fluid step's own timers ("ice: <phase>", "pressure solver:
// <what>") are phases too, nested in the coupled step's: where its pressure phase spends its time.
bool isPhase(const std::string& name)
{
  static const bool nested = std::getenv("CFDMPM_PROFILE_NESTED") && std::string(std::getenv("CFDMPM_PROFILE_NESTED")) == "1";
  if (name.rfind("mpmice: ", 0) == 0 || name.rfind("cfdmpm: ", 0) == 0) return true;
  return nested && (name.rfind("ice: ", 0) == 0 || name.rfind("pressure solver: ", 0) == 0);
}

void startCounting(Profile& p)
{
  for (auto& [name, counts] : p.phases) counts = PhaseCounts{};
  for (double& t : p.entered) t = Profile::now();
  p.counting = true;
}

// Times one MPI call and charges it to the current phase.
struct MpiCall {
  double start;
  MpiCall() : start(Profile::now()) { ++profile().depth_in_mpi; }
  ~MpiCall()
  {
    Profile& p = profile();
    if (--p.depth_in_mpi == 0 && p.counting) p.current().mpi_seconds += Profile::now() - start;
  }
};

int typeSize(MPI_Datatype type)
{
  int size = 0;
  PMPI_Type_size(type, &size);
  return size;
}

void sent(int count, MPI_Datatype type, int destination)
{
  Profile& p = profile();
  if (!p.counting || p.depth_in_mpi > 1) return;
  PhaseCounts& c = p.current();
  c.messages += 1;
  c.bytes += double(count) * typeSize(type);
  c.destinations.insert(destination);
}

void reduced(int count, MPI_Datatype type)
{
  Profile& p = profile();
  if (!p.counting || p.depth_in_mpi > 1) return;
  p.current().reductions += 1;
  p.current().reduction_bytes += double(count) * typeSize(type);
}

void collective()
{
  Profile& p = profile();
  if (p.counting && p.depth_in_mpi <= 1) p.current().collectives += 1;
}

void report()
{
  Profile& p = profile();
  p.charge();
  int rank = 0, ranks = 1;
  PMPI_Comm_rank(MPI_COMM_WORLD, &rank);
  PMPI_Comm_size(MPI_COMM_WORLD, &ranks);
  // The same list of phases on every rank: the union, in name order.
  std::string names;
  for (const auto& [name, counts] : p.phases) names += name + "\n";
  int length = int(names.size()), longest = 0;
  PMPI_Allreduce(&length, &longest, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  std::vector<char> mine(longest + 1, 0), all(std::size_t(longest + 1) * ranks);
  std::copy(names.begin(), names.end(), mine.begin());
  PMPI_Allgather(mine.data(), longest + 1, MPI_CHAR, all.data(), longest + 1, MPI_CHAR, MPI_COMM_WORLD);
  std::set<std::string> phase_names;
  for (int r = 0; r < ranks; ++r) {
    std::string text(&all[std::size_t(r) * (longest + 1)]);
    for (std::size_t start = 0, end; (end = text.find('\n', start)) != std::string::npos; start = end + 1)
      phase_names.insert(text.substr(start, end - start));
  }
  long long steps = p.steps - p.skip, most_steps = 0;
  PMPI_Allreduce(&steps, &most_steps, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
  const double per = most_steps > 0 ? 1.0 / double(most_steps) : 1.0;
  std::FILE* json = nullptr;
  if (rank == 0)
    if (const char* path = std::getenv("CFDMPM_PROFILE_JSON")) json = std::fopen(path, "w");
  if (rank == 0) {
    std::printf("phase profile: %d rank(s), %lld steps after %lld skipped; per step, slowest rank (mean):\n", ranks,
                most_steps, p.skip);
    std::printf("%-28s %12s %12s %10s %12s %6s %8s %8s\n", "phase", "time ms", "in MPI ms", "messages", "bytes",
                "dests", "reduce", "other");
    if (json) std::fprintf(json, "{\"ranks\": %d, \"steps\": %lld, \"phases\": {", ranks, most_steps);
  }
  bool first = true;
  for (const std::string& name : phase_names) {
    const PhaseCounts& c = p.phases[name];
    const double local[kFields] = {c.seconds,    c.mpi_seconds, c.entries,         c.messages,
                                   c.bytes,      c.reductions,  c.reduction_bytes, c.collectives,
                                   double(c.destinations.size())};
    double most[kFields], sum[kFields];
    PMPI_Reduce(local, most, kFields, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    PMPI_Reduce(local, sum, kFields, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
    if (rank != 0) continue;
    std::printf("%-28s %5.1f (%4.1f) %5.1f (%4.1f) %4.0f (%3.0f) %5.0f (%5.0f) %6.0f %3.0f (%3.0f) %8.1f\n",
                name.c_str(), 1e3 * most[0] * per, 1e3 * sum[0] * per / ranks, 1e3 * most[1] * per,
                1e3 * sum[1] * per / ranks, most[3] * per, sum[3] * per / ranks, most[4] * per,
                sum[4] * per / ranks, most[8], most[5] * per, sum[5] * per / ranks, most[7] * per);
    if (json) {
      std::fprintf(json, "%s\n  \"%s\": {", first ? "" : ",", name.c_str());
      const char* keys[kFields] = {"seconds", "mpi_seconds", "entries", "messages", "bytes",
                                   "reductions", "reduction_bytes", "collectives", "destinations"};
      for (int k = 0; k < kFields; ++k) {
        const double scale = k == 8 ? 1.0 : per;
        std::fprintf(json, "%s\"%s\": [%.6g, %.6g]", k ? ", " : "", keys[k], most[k] * scale, sum[k] * scale / ranks);
      }
      std::fprintf(json, "}");
    }
    first = false;
  }
  if (json) {
    std::fprintf(json, "\n}}\n");
    std::fclose(json);
  }
}

template <class F>
F next(const char* symbol)
{
  return reinterpret_cast<F>(dlsym(RTLD_NEXT, symbol));
}

}  // namespace

// --- Teuchos timers as phase markers ------------------------------------------------------------

void Teuchos::Time::start(bool reset_timer)
{
  static auto real = next<void (*)(Teuchos::Time*, bool)>("_ZN7Teuchos4Time5startEb");
  if (isPhase(name())) {
    Profile& p = profile();
    p.charge();
    p.stack.push_back(name());
    p.entered.push_back(Profile::now());
    if (p.counting) p.current().entries += 1;
  }
  real(this, reset_timer);
}

double Teuchos::Time::stop()
{
  static auto real = next<double (*)(Teuchos::Time*)>("_ZN7Teuchos4Time4stopEv");
  const double elapsed = real(this);
  Profile& p = profile();
  if (isPhase(name()) && p.stack.size() > 1 && p.stack.back() == name()) {
    p.charge();
    p.stack.pop_back();
    p.entered.pop_back();
    p.entered.back() = Profile::now();
    if (name() == "mpmice: step" && ++p.steps == p.skip) startCounting(p);
  }
  return elapsed;
}

// --- MPI ----------------------------------------------------------------------------------------

extern "C" {

int MPI_Send(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm)
{
  MpiCall call;
  sent(count, type, dest);
  return PMPI_Send(buf, count, type, dest, tag, comm);
}
int MPI_Ssend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm)
{
  MpiCall call;
  sent(count, type, dest);
  return PMPI_Ssend(buf, count, type, dest, tag, comm);
}
int MPI_Rsend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm)
{
  MpiCall call;
  sent(count, type, dest);
  return PMPI_Rsend(buf, count, type, dest, tag, comm);
}
int MPI_Isend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm, MPI_Request* request)
{
  MpiCall call;
  sent(count, type, dest);
  return PMPI_Isend(buf, count, type, dest, tag, comm, request);
}
int MPI_Irsend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm, MPI_Request* request)
{
  MpiCall call;
  sent(count, type, dest);
  return PMPI_Irsend(buf, count, type, dest, tag, comm, request);
}
int MPI_Issend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm, MPI_Request* request)
{
  MpiCall call;
  sent(count, type, dest);
  return PMPI_Issend(buf, count, type, dest, tag, comm, request);
}
int MPI_Sendrecv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, int dest, int sendtag, void* recvbuf,
                 int recvcount, MPI_Datatype recvtype, int source, int recvtag, MPI_Comm comm, MPI_Status* status)
{
  MpiCall call;
  sent(sendcount, sendtype, dest);
  return PMPI_Sendrecv(sendbuf, sendcount, sendtype, dest, sendtag, recvbuf, recvcount, recvtype, source, recvtag, comm,
                       status);
}
int MPI_Recv(void* buf, int count, MPI_Datatype type, int source, int tag, MPI_Comm comm, MPI_Status* status)
{
  MpiCall call;
  return PMPI_Recv(buf, count, type, source, tag, comm, status);
}
int MPI_Wait(MPI_Request* request, MPI_Status* status)
{
  MpiCall call;
  return PMPI_Wait(request, status);
}
int MPI_Waitall(int count, MPI_Request requests[], MPI_Status statuses[])
{
  MpiCall call;
  return PMPI_Waitall(count, requests, statuses);
}
int MPI_Waitany(int count, MPI_Request requests[], int* index, MPI_Status* status)
{
  MpiCall call;
  return PMPI_Waitany(count, requests, index, status);
}

int MPI_Allreduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm)
{
  MpiCall call;
  reduced(count, type);
  return PMPI_Allreduce(sendbuf, recvbuf, count, type, op, comm);
}
int MPI_Iallreduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm,
                   MPI_Request* request)
{
  MpiCall call;
  reduced(count, type);
  return PMPI_Iallreduce(sendbuf, recvbuf, count, type, op, comm, request);
}
int MPI_Reduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op, int root, MPI_Comm comm)
{
  MpiCall call;
  reduced(count, type);
  return PMPI_Reduce(sendbuf, recvbuf, count, type, op, root, comm);
}
int MPI_Scan(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm)
{
  MpiCall call;
  reduced(count, type);
  return PMPI_Scan(sendbuf, recvbuf, count, type, op, comm);
}
int MPI_Exscan(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm)
{
  MpiCall call;
  reduced(count, type);
  return PMPI_Exscan(sendbuf, recvbuf, count, type, op, comm);
}
int MPI_Bcast(void* buf, int count, MPI_Datatype type, int root, MPI_Comm comm)
{
  MpiCall call;
  collective();
  return PMPI_Bcast(buf, count, type, root, comm);
}
int MPI_Barrier(MPI_Comm comm)
{
  MpiCall call;
  collective();
  return PMPI_Barrier(comm);
}
int MPI_Alltoall(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf, int recvcount,
                 MPI_Datatype recvtype, MPI_Comm comm)
{
  MpiCall call;
  collective();
  return PMPI_Alltoall(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, comm);
}
int MPI_Alltoallv(const void* sendbuf, const int sendcounts[], const int sdispls[], MPI_Datatype sendtype,
                  void* recvbuf, const int recvcounts[], const int rdispls[], MPI_Datatype recvtype, MPI_Comm comm)
{
  MpiCall call;
  collective();
  return PMPI_Alltoallv(sendbuf, sendcounts, sdispls, sendtype, recvbuf, recvcounts, rdispls, recvtype, comm);
}
int MPI_Allgather(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf, int recvcount,
                  MPI_Datatype recvtype, MPI_Comm comm)
{
  MpiCall call;
  collective();
  return PMPI_Allgather(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, comm);
}
int MPI_Allgatherv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf, const int recvcounts[],
                   const int displs[], MPI_Datatype recvtype, MPI_Comm comm)
{
  MpiCall call;
  collective();
  return PMPI_Allgatherv(sendbuf, sendcount, sendtype, recvbuf, recvcounts, displs, recvtype, comm);
}
int MPI_Gather(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf, int recvcount,
               MPI_Datatype recvtype, int root, MPI_Comm comm)
{
  MpiCall call;
  collective();
  return PMPI_Gather(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, root, comm);
}
int MPI_Gatherv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf, const int recvcounts[],
                const int displs[], MPI_Datatype recvtype, int root, MPI_Comm comm)
{
  MpiCall call;
  collective();
  return PMPI_Gatherv(sendbuf, sendcount, sendtype, recvbuf, recvcounts, displs, recvtype, root, comm);
}
int MPI_Scatter(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf, int recvcount,
                MPI_Datatype recvtype, int root, MPI_Comm comm)
{
  MpiCall call;
  collective();
  return PMPI_Scatter(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, root, comm);
}
int MPI_Reduce_scatter_block(const void* sendbuf, void* recvbuf, int recvcount, MPI_Datatype type, MPI_Op op,
                             MPI_Comm comm)
{
  MpiCall call;
  reduced(recvcount, type);
  return PMPI_Reduce_scatter_block(sendbuf, recvbuf, recvcount, type, op, comm);
}
int MPI_Reduce_scatter(const void* sendbuf, void* recvbuf, const int recvcounts[], MPI_Datatype type, MPI_Op op,
                       MPI_Comm comm)
{
  MpiCall call;
  reduced(recvcounts[0], type);
  return PMPI_Reduce_scatter(sendbuf, recvbuf, recvcounts, type, op, comm);
}

int MPI_Finalize()
{
  report();
  return PMPI_Finalize();
}

}  // extern "C"
