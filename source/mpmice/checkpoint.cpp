#include "mpmice/checkpoint.hpp"

#include "common/mpi_comm.hpp"
#include "io/hdf5_reader.hpp"
#include "io/output_directory.hpp"
#include "io/xdmf_writer.hpp"
#include "mpmice/run_state.hpp"
#include "mpmice/state_output.hpp"

#include <filesystem>

namespace cfdmpm {

namespace {

namespace fs = std::filesystem;

constexpr const char* kFormat = "cfdmpm checkpoint 1";

/// Names of the columns of Particles::pack, in its order.
template <int Dim>
std::string particleColumns()
{
  const char* xyz = "xyz";
  std::string names;
  auto add = [&](const std::string& name) { names += (names.empty() ? "" : ",") + name; };
  for (const char* vector : {"position", "velocity", "half_width"})
    for (int d = 0; d < Dim; ++d) add(std::string(vector) + "_" + xyz[d]);
  for (const char* scalar : {"mass", "volume", "initial_volume"}) add(scalar);
  for (const char* tensor : {"deformation_gradient", "stress"})
    for (int d = 0; d < Dim; ++d)
      for (int e = 0; e < Dim; ++e) add(std::string(tensor) + "_" + xyz[d] + xyz[e]);
  for (const char* scalar : {"out_of_plane_stress", "equivalent_plastic_strain", "volumetric_plastic_strain"})
    add(scalar);
  for (int d = 0; d < Dim; ++d) add(std::string("velocity_change_") + xyz[d]);
  for (int d = 0; d < Dim; ++d) add(std::string("own_acceleration_") + xyz[d]);
  for (const char* scalar : {"material", "id"}) add(scalar);
  return names;
}

}  // namespace

std::string findCheckpoint(const std::string& file_or_directory)
{
  std::error_code error;
  const fs::path given(file_or_directory);
  if (fs::is_regular_file(given, error)) return file_or_directory;
  if (!fs::is_directory(given, error))
    throw InputError("--restart: '" + file_or_directory + "' is neither a checkpoint file nor an output directory");
  // The newest checkpoint in <directory>/checkpoints/, whatever the run's name.
  const fs::path folder = checkpointDirectory(file_or_directory);
  fs::path newest;
  long long newest_step = -1;
  if (fs::is_directory(folder, error))
    for (const fs::directory_entry& entry : fs::directory_iterator(folder, error)) {
      const std::string name = entry.path().filename().string();
      const std::size_t underscore = name.rfind('_');
      if (underscore == std::string::npos || !entry.is_regular_file()) continue;
      const long long step = stepOfFile(name, name.substr(0, underscore), ".h5");
      if (step > newest_step) newest_step = step, newest = entry.path();
    }
  if (newest_step < 0)
    throw InputError("--restart: no checkpoint in '" + folder.string() +
                     "' (a run writes checkpoints when output.checkpoint_interval or "
                     "output.checkpoint_wall_interval is set)");
  return newest.string();
}

CheckpointHeader readCheckpointHeader(MPI_Comm comm, const std::string& path)
{
  Hdf5Reader in(comm, path);
  if (!in.hasAttribute("format") || in.attributeText("format") != kFormat)
    throw InputError("checkpoint '" + path + "': not a cfdmpm checkpoint (no attribute format = '" + kFormat + "')");
  CheckpointHeader header;
  header.path = path;
  // The run goes on in the output directory the checkpoint belongs to; a checkpoint moved out of
  // its checkpoints/ folder has none.
  const fs::path folder = fs::path(path).parent_path();
  if (folder.filename() != "checkpoints")
    throw InputError("checkpoint '" + path + "': not in the checkpoints/ folder of an output directory, so the "
                     "run has nowhere to go on; put it in <output directory>/checkpoints/ and restart from there");
  header.output_directory = folder.parent_path().string();
  if (header.output_directory.empty()) header.output_directory = ".";
  header.run_name = in.attributeText("run_name");
  header.scene_path = in.attributeText("scene_path");
  header.scene_text = in.attributeText("scene");
  header.step = in.attributeInteger("step");
  header.time = in.attributeDouble("time");
  header.ranks = int(in.attributeInteger("ranks"));
  for (long long owner : in.attributeIntegers("decomposition")) header.decomposition.push_back(int(owner));
  return header;
}

void checkRestartScene(const Scene& scene, const Scene& original)
{
  auto refuse = [&](const std::string& what) {
    throw InputError(scene.path + ": does not fit the checkpoint of '" + original.path + "': " + what +
                     " differ; a restart continues the same grid and materials");
  };
  const DomainSpec &a = scene.domain, &b = original.domain;
  if (a.dimension != b.dimension) refuse("domain.dimension");
  if (a.lower != b.lower || a.upper != b.upper) refuse("domain.lower or domain.upper");
  if (a.cells != b.cells) refuse("domain.cells");
  if (a.patch_cells != b.patch_cells) refuse("domain.patch_cells");
  if (a.ghost_width != b.ghost_width) refuse("domain.ghost_width");
  if (scene.materials.size() != original.materials.size()) refuse("the materials");
  for (std::size_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].name != original.materials[m].name || scene.materials[m].kind != original.materials[m].kind)
      refuse("the materials (names, kinds or order)");
}

template <int Dim>
CheckpointWriter<Dim>::CheckpointWriter(const Scene& scene, const Layout<Dim>& layout, const std::string& run_name,
                                        const std::string& output_directory)
    : scene_(scene), layout_(layout), run_name_(run_name), output_directory_(output_directory)
{
  const MPI_Comm comm = rawMpiComm(layout.comm());
  createDirectory(comm, checkpointDirectory(output_directory));
  hdf5_ = std::make_unique<Hdf5Writer>(comm, checkpointDirectory(output_directory), run_name,
                                       outputLayout(layout.grid(), Location::Cell, layout.ownedCellBoxes()),
                                       outputLayout(layout.grid(), Location::Node, layout.ownedNodeBoxes()));
}

template <int Dim>
void CheckpointWriter<Dim>::writeField(const Field<Dim>& field, const std::string& name)
{
  const auto v = field.view();
  const int columns = field.columns();
  const LocalOrdinal n = field.ownedCount();
  buffer_.resize(std::size_t(n) * columns);
  for (LocalOrdinal l = 0; l < n; ++l)
    for (int c = 0; c < columns; ++c) buffer_[std::size_t(l) * columns + c] = v(l, c);
  hdf5_->writeTable(OutputLocation::Cells, name, buffer_.data(), buffer_.size(), columns);
}

template <int Dim>
std::string CheckpointWriter<Dim>::write(const RunClock& clock, const CellState<Dim>& state, MpmIceStep<Dim>& stepper,
                                         const std::vector<WrittenStep>& output_steps)
{
  const MPI_Comm comm = rawMpiComm(layout_.comm());
  hdf5_->beginStep(clock.step, clock.time);
  hdf5_->writeAttribute("format", std::string(kFormat));
  hdf5_->writeAttribute("run_name", run_name_);
  hdf5_->writeAttribute("scene_path", scene_.path);
  hdf5_->writeAttribute("scene", scene_.text);
  hdf5_->writeAttribute("ranks", static_cast<long long>(layout_.comm()->getSize()));
  const std::vector<int>& owner = layout_.decomposition().patch_owner;
  hdf5_->writeAttribute("decomposition", std::vector<long long>(owner.begin(), owner.end()));
  hdf5_->writeAttribute("dt_previous", clock.dt_previous);
  hdf5_->writeAttribute("output_mark", clock.output_mark);
  hdf5_->writeAttribute("checkpoint_mark", clock.checkpoint_mark);
  hdf5_->writeAttribute("unconverged_warnings", static_cast<long long>(clock.unconverged_warnings));
  hdf5_->writeAttribute("output_steps", stepRecordsText(output_steps));

  for (const auto& [name, field] : namedFields(state)) writeField(*field, name);
  if (const IceSolver<Dim>* fluids = stepper.fluids()) writeField(fluids->solidReferencePressure(), kSolidReferencePressureName);

  if (const mpm::MpmSolver<Dim>* solids = stepper.particles()) {
    const mpm::Particles<Dim>& particles = solids->particles();
    const int n = particles.count;
    constexpr int K = mpm::Particles<Dim>::kPackedSize;
    Kokkos::View<double**, Kokkos::LayoutRight, MemorySpace> packed("packed particles", std::size_t(n), K);
    Kokkos::parallel_for(
        "checkpoint::pack", Kokkos::RangePolicy<ExecutionSpace>(0, n),
        KOKKOS_LAMBDA(const int p) { particles.pack(p, &packed(p, 0)); });
    const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), packed);
    long long local = n;
    std::vector<long long> counts(std::size_t(layout_.comm()->getSize()));
    MPI_Allgather(&local, 1, MPI_LONG_LONG, counts.data(), 1, MPI_LONG_LONG, comm);
    hdf5_->writeAttribute("particle_rank_counts", counts);
    hdf5_->writeAttribute("particle_columns", particleColumns<Dim>());
    hdf5_->writeParticleVector("packed", host.data(), std::size_t(n), K);
  }
  const WrittenStep written = hdf5_->endStep();
  // The restarted run starts with a fresh preconditioner; so does this one from here on.
  if (IceSolver<Dim>* fluids = stepper.fluids()) fluids->restartPreconditionerSchedule();
  pruneCheckpoints(comm, output_directory_, run_name_, scene_.output.checkpoints_kept);
  return checkpointDirectory(output_directory_) + "/" + written.file;
}

template <int Dim>
RunClock readCheckpoint(const std::string& path, RunState<Dim>& run, std::vector<WrittenStep>& output_steps)
{
  const Layout<Dim>& layout = *run.layout;
  const MPI_Comm comm = rawMpiComm(layout.comm());
  Hdf5Reader in(comm, path);
  if (!in.hasAttribute("format") || in.attributeText("format") != kFormat)
    throw InputError("checkpoint '" + path + "': not a cfdmpm checkpoint");

  // 1. Cell fields: owned entries from the file (adoptState fills the ghosts from their owners).
  const OutputLayout cells = outputLayout(layout.grid(), Location::Cell, layout.ownedCellBoxes());
  std::vector<double> buffer;
  auto load = [&](const std::string& name, Field<Dim>& field) {
    const int columns = field.columns();
    const LocalOrdinal n = field.ownedCount();
    buffer.resize(std::size_t(n) * columns);
    in.readTable(cells, "/cells/" + name, columns, buffer.data());
    auto v = field.view();
    for (LocalOrdinal l = 0; l < n; ++l)
      for (int c = 0; c < columns; ++c) v(l, c) = buffer[std::size_t(l) * columns + c];
  };

  // 2. Particles: on as many ranks as wrote them, each rank its own block in its order (what makes
  //    the restart bit for bit); otherwise equal shares. adoptState sends each particle to its
  //    cell's owner.
  typename mpm::MpmSolver<Dim>::ParticleSnapshot particles;
  long long rows = 0;
  if (run.step->particles()) {
    constexpr int K = mpm::Particles<Dim>::kPackedSize;
    if (in.attributeText("particle_columns") != particleColumns<Dim>())
      throw InputError("checkpoint '" + path + "': its particle columns are not those of this version");
    const std::vector<long long> counts = in.attributeIntegers("particle_rank_counts");
    const int rank = layout.comm()->getRank(), ranks = layout.comm()->getSize();
    long long total = 0, first = 0;
    for (long long c : counts) total += c;
    if (int(counts.size()) == ranks) {
      for (int r = 0; r < rank; ++r) first += counts[r];
      rows = counts[rank];
    } else {
      first = total * rank / ranks;
      rows = total * (rank + 1) / ranks - first;
    }
    std::vector<double> packed(std::size_t(rows) * K);
    in.readRows("/particles/packed", first, rows, K, packed.data());
    particles = typename mpm::MpmSolver<Dim>::ParticleSnapshot("checkpoint particles", std::size_t(rows), K);
    Kokkos::View<double**, Kokkos::LayoutRight, Kokkos::HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>> host(
        packed.data(), std::size_t(rows), K);
    Kokkos::deep_copy(particles, host);
  }
  adoptState<Dim>(load, particles, int(rows), run);

  // 3. The driver's clock and the records of the step files written so far.
  RunClock clock;
  clock.step = in.attributeInteger("step");
  clock.time = in.attributeDouble("time");
  clock.dt_previous = in.attributeDouble("dt_previous");
  clock.output_mark = in.attributeDouble("output_mark");
  clock.checkpoint_mark = in.attributeDouble("checkpoint_mark");
  clock.unconverged_warnings = int(in.attributeInteger("unconverged_warnings"));
  try {
    output_steps = stepRecordsFromText(in.attributeText("output_steps"));
  } catch (const std::invalid_argument& e) {
    throw InputError("checkpoint '" + path + "': attribute output_steps: " + e.what());
  }
  return clock;
}

template class CheckpointWriter<2>;
template class CheckpointWriter<3>;
template RunClock readCheckpoint(const std::string&, RunState<2>&, std::vector<WrittenStep>&);
template RunClock readCheckpoint(const std::string&, RunState<3>&, std::vector<WrittenStep>&);

}  // namespace cfdmpm
