#include "output/checkpoint.h"

#include "output/write_failure.h"
#include "domain/domain.h"
#include "scene/scene.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <dolfinx/fem/FunctionSpace.h>
#include <filesystem>
#include <fstream>
#include <unordered_map>

namespace biotcontact
{

namespace
{
const char magic[] = "biotcontact checkpoint 2";

/// The --set keys a restart may change (docs/user-guide.md, "Restart"):
/// the split's iteration, its acceleration, the retries of a failed step,
/// the single-rate scheme and its fallback, and the linear solvers, so that
/// a run the split could not carry through a step goes on monolithic from
/// its checkpoint, by the solver that carries it.
constexpr std::array<const char*, 9> restart_keys{
    "coupling.scheme",  "coupling.acceleration", "coupling.depth",    "coupling.max_iterations", "coupling.fallback",
    "time.retry",       "solver.flow",           "solver.mechanics", "solver.monolithic"};

bool may_change(const std::string& assignment)
{
  std::string key = assignment.substr(0, assignment.find('='));
  key.erase(std::remove_if(key.begin(), key.end(), [](unsigned char c) { return std::isspace(c); }), key.end());
  return std::find(restart_keys.begin(), restart_keys.end(), key) != restart_keys.end();
}

/// The keys a restart may change, for its refusal.
std::string changeable()
{
  std::string keys = " (a restart may change with --set ";
  for (const char* key : restart_keys)
    keys += key + std::string(key == restart_keys[0] ? " between \"fixed-stress\" and \"monolithic\"" : "")
            + (key == restart_keys.back() ? ")" : ", ");
  return keys;
}

std::string state_file(const std::string& directory) { return directory + "/checkpoint/state.bin"; }

std::string values_file(const std::string& directory, int steps, int rank)
{
  return directory + "/checkpoint/values." + std::to_string(steps) + "." + std::to_string(rank) + ".bin";
}

void put(std::ofstream& f, const std::string& s)
{
  const std::uint64_t n = s.size();
  f.write(reinterpret_cast<const char*>(&n), sizeof n);
  f.write(s.data(), static_cast<std::streamsize>(n));
}

template <typename T>
void put(std::ofstream& f, T value)
{
  f.write(reinterpret_cast<const char*>(&value), sizeof value);
}

template <typename T>
void put_vector(std::ofstream& f, const std::vector<T>& v)
{
  put(f, static_cast<std::uint64_t>(v.size()));
  f.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
}

std::string get_string(std::ifstream& f)
{
  std::uint64_t n = 0;
  f.read(reinterpret_cast<char*>(&n), sizeof n);
  if (!f or n > (1u << 30))
    throw std::runtime_error("truncated");
  std::string s(n, '\0');
  f.read(s.data(), static_cast<std::streamsize>(n));
  return s;
}

template <typename T>
T get(std::ifstream& f)
{
  T value{};
  f.read(reinterpret_cast<char*>(&value), sizeof value);
  if (!f)
    throw std::runtime_error("truncated");
  return value;
}

template <typename T>
std::vector<T> get_vector(std::ifstream& f)
{
  const auto n = get<std::uint64_t>(f);
  if (n > (std::uint64_t(1) << 40) / sizeof(T))
    throw std::runtime_error("truncated");
  std::vector<T> v(n);
  f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
  if (!f)
    throw std::runtime_error("truncated");
  return v;
}

/// Writes a file through `path`.new and renames it into place; returns
/// why it could not (the new file removed), or an empty string.
template <typename Write>
std::string write_file(const std::string& path, const Write& write)
{
  errno = 0;
  std::error_code ec;
  {
    std::ofstream f(path + ".new", std::ios::binary | std::ios::trunc);
    write(f);
    f.flush();
    if (f)
      std::filesystem::rename(path + ".new", path, ec);
    if (f and !ec)
      return "";
  }
  const std::string directory = std::filesystem::path(path).parent_path().string();
  const std::string failure = "cannot write " + path + ": " + write_failure_reason(directory);
  std::filesystem::remove(path + ".new", ec);
  return failure;
}

/// This rank's owned values, with their names.
std::string write_values(const std::string& directory, int rank, const Checkpoint& c)
{
  return write_file(values_file(directory, c.steps, rank),
                    [&](std::ofstream& f)
                    {
                      put(f, std::string(magic));
                      put(f, c.steps);
                      put(f, static_cast<std::uint64_t>(c.fields.size()));
                      for (const auto& [name, kv] : c.fields)
                      {
                        put(f, name);
                        put(f, kv.width);
                        put_vector(f, kv.keys);
                        put_vector(f, kv.values);
                      }
                    });
}

/// Everything but the values (rank 0); once it is in place, the values of
/// earlier checkpoints (of any number of ranks) go.
std::string write_state(const std::string& directory, const std::string& fingerprint, int ranks,
                        const Checkpoint& c)
{
  const std::string failure = write_file(state_file(directory),
                                         [&](std::ofstream& f)
                                         {
                                           put(f, std::string(magic));
                                           put(f, fingerprint);
                                           put(f, ranks);
                                           put(f, c.steps);
                                           put(f, c.time);
                                           put(f, static_cast<std::uint64_t>(c.numbers.size()));
                                           for (const auto& [name, value] : c.numbers)
                                             put(f, name), put(f, value);
                                           put(f, static_cast<std::uint64_t>(c.arrays.size()));
                                           for (const auto& [name, values] : c.arrays)
                                             put(f, name), put_vector(f, values);
                                           put(f, c.output);
                                         });
  if (!failure.empty())
    return failure;
  const std::string current = "values." + std::to_string(c.steps) + ".";
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(directory + "/checkpoint", ec))
    if (const std::string name = entry.path().filename().string();
        name.rfind("values.", 0) == 0 and name.rfind(current, 0) != 0)
      std::filesystem::remove(entry.path(), ec);
  return "";
}
} // namespace

void write_checkpoint(MPI_Comm comm, const std::string& directory, const std::string& fingerprint,
                      const Checkpoint& c)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::error_code ec;
  if (rank == 0)
    std::filesystem::create_directories(directory + "/checkpoint", ec);
  MPI_Barrier(comm);
  // Every rank's values are complete before the state points at them: a
  // failure anywhere leaves the previous checkpoint as it was.
  agree_on_output_error(write_values(directory, rank, c), comm);
  agree_on_output_error(rank == 0 ? write_state(directory, fingerprint, size, c) : "", comm);
}

namespace
{
/// The state file: everything but the values.
Checkpoint read_state(const std::string& directory, const std::string& fingerprint, int& ranks)
{
  const std::string path = state_file(directory);
  std::ifstream f(path, std::ios::binary);
  if (!f)
    throw SceneError("--restart " + directory + ": no checkpoint there (" + path
                     + "; runs write one with output.checkpoint_every)");
  if (get_string(f) != magic)
    throw SceneError("--restart " + directory + ": " + path + " is no checkpoint of this version of biotcontact");
  if (get_string(f) != fingerprint)
    throw SceneError("--restart " + directory + ": the checkpoint was written for another scene or other --set values"
                     + changeable());
  Checkpoint c;
  ranks = get<int>(f);
  c.steps = get<int>(f);
  c.time = get<double>(f);
  for (auto n = get<std::uint64_t>(f); n > 0; --n)
  {
    const std::string name = get_string(f);
    c.numbers[name] = get<double>(f);
  }
  for (auto n = get<std::uint64_t>(f); n > 0; --n)
  {
    const std::string name = get_string(f);
    c.arrays[name] = get_vector<double>(f);
  }
  c.output = get_string(f);
  return c;
}

/// Appends the values of one rank's file to c.fields.
void read_values(const std::string& path, Checkpoint& c)
{
  std::ifstream f(path, std::ios::binary);
  if (!f or get_string(f) != magic or get<int>(f) != c.steps)
    throw std::runtime_error("missing");
  for (auto n = get<std::uint64_t>(f); n > 0; --n)
  {
    KeyedValues& kv = c.fields[get_string(f)];
    kv.width = get<int>(f);
    const std::vector<std::int64_t> keys = get_vector<std::int64_t>(f);
    const std::vector<double> values = get_vector<double>(f);
    if (keys.size() != values.size() * kv.width)
      throw std::runtime_error("truncated");
    kv.keys.insert(kv.keys.end(), keys.begin(), keys.end());
    kv.values.insert(kv.values.end(), values.begin(), values.end());
  }
}
} // namespace

std::string restart_fingerprint(const std::string& text, const std::vector<std::string>& overrides, const Scene& scene)
{
  std::string fingerprint = text;
  for (const std::string& o : overrides)
    if (!may_change(o))
      fingerprint += "\n--set " + o;
  if (scene.coupling and scene.coupling->scheme != CouplingScheme::monolithic
      and scene.coupling->scheme != CouplingScheme::fixed_stress)
    fingerprint += std::string("\ncoupling.scheme = ") + name_of(scene.coupling->scheme);
  return fingerprint;
}

std::string restart_proposal(const std::string& failure, const Scene& scene)
{
  if (failure.find("coupling.scheme = \"monolithic\"") == std::string::npos)
    return "";
  if (!scene.coupling or !scene.coupling->multirate())
    return " --set coupling.scheme=monolithic";
  return scene.coupling->fallback == Fallback::monolithic ? "" : " --set coupling.fallback=monolithic";
}

Checkpoint read_checkpoint(MPI_Comm comm, const std::string& directory, const std::string& fingerprint)
{
  Checkpoint c;
  std::string error;
  std::string path = state_file(directory);
  try
  {
    int ranks = 0;
    c = read_state(directory, fingerprint, ranks);
    for (int r = 0; r < ranks; ++r)
      read_values(path = values_file(directory, c.steps, r), c);
  }
  catch (const SceneError& e)
  {
    error = e.what();
  }
  catch (const std::exception&)
  {
    error = "--restart " + directory + ": the checkpoint " + path + " is damaged or missing";
  }
  agree_on_error(error, comm);
  return c;
}

Checkpoint capture_checkpoint(const RunState& run, int steps, double time, const std::string& output)
{
  Checkpoint c;
  c.steps = steps;
  c.time = time;
  c.arrays["times"] = run.grid.t; // the grid as retries left it (the same on every rank)
  c.arrays["time_steps"] = run.grid.dt;
  c.arrays["mesh"] = mesh_signature(run.mesh);
  auto keep = [&](const std::vector<UnknownsPart>& parts, std::span<const double> unknowns)
  {
    for (const UnknownsPart& part : parts)
      c.fields[part.name] = keyed_values(run.mesh, part, unknowns);
  };
  for (const Step* step : run.scheme.steps())
    keep(step->parts(), step->unknowns());
  for (const auto& [name, f] : run.scheme.history())
    keep({{name, f->function_space(), {}}}, f->x()->array());
  for (const Step* step : run.scheme.steps())
    for (auto& [name, values] : step->arrays())
      c.arrays[name] = std::move(values);
  for_each_checkpointed(run.report, run.state, [&](const char* name, auto& value) { c.numbers[name] = value; });
  for (const Step* step : run.scheme.steps())
  {
    const SolverStatistics st = step->system().statistics();
    for (const auto& [name, count] : solver_counts)
      c.numbers[step->name() + "." + name] = st.*count;
  }
  c.output = output;
  return c;
}

namespace
{

/// The checkpoint's field for history field `name` of a scheme whose
/// history has `path` (displacement_path_before: the split with BDF2). The
/// displacement one fine step before t_K is the split's
/// displacement_path_before and the monolithic scheme's
/// displacement_before (each of its steps a window of one fine step), so
/// each reads the other's where it goes on from the other's state (a
/// restart with another coupling.scheme, coupling.fallback); the split's
/// displacement_before is one window before t_K.
std::string stored_history_name(const Checkpoint& c, const std::string& name, bool path)
{
  const char* by_path = "displacement_path_before";
  if (name == by_path and !c.fields.count(by_path))
    return "displacement_before";
  if (name == "displacement_before" and !path and c.fields.count(by_path))
    return by_path;
  return name;
}

/// Loads the stored unknowns into the steps; refuses a checkpoint of
/// another mesh, or one that lacks any of them (collective).
void restore_unknowns(const Checkpoint& c, const RunState& run, MPI_Comm comm, const std::string& directory)
{
  const auto stored_mesh = c.arrays.find("mesh");
  const std::string difference = mesh_difference(
      stored_mesh == c.arrays.end() ? std::vector<double>{} : stored_mesh->second, mesh_signature(run.mesh));
  if (not difference.empty())
    throw SceneError("--restart " + directory + ": the checkpoint does not match this mesh (" + difference + ")");
  auto restore = [&](const std::vector<UnknownsPart>& parts, std::span<double> unknowns)
  {
    for (const UnknownsPart& part : parts)
    {
      const auto stored = c.fields.find(part.name);
      std::int64_t missing
          = stored == c.fields.end() ? 1 : restore_values(run.mesh, part, stored->second, unknowns);
      MPI_Allreduce(MPI_IN_PLACE, &missing, 1, MPI_INT64_T, MPI_SUM, comm);
      if (missing > 0)
        throw SceneError("--restart " + directory + ": the checkpoint does not match this mesh ("
                         + std::to_string(missing) + " values of the " + part.name + " not in it)");
    }
  };
  for (Step* step : run.scheme.steps())
  {
    const std::vector<UnknownsPart> parts = step->parts();
    if (parts.empty())
      continue;
    std::vector<double> x = values(step->unknowns());
    restore(parts, x);
    step->set_unknowns(x);
  }
  const History history = run.scheme.history();
  const bool path = std::any_of(history.begin(), history.end(),
                                [](const auto& h) { return h.first == "displacement_path_before"; });
  for (const auto& [name, f] : history)
    restore({{stored_history_name(c, name, path), f->function_space(), {}}}, f->x()->mutable_array());
  for (Step* step : run.scheme.steps())
  {
    for (const auto& [name, values] : step->arrays())
      if (!c.arrays.count(name))
        throw SceneError("--restart " + directory + ": the checkpoint has no " + name);
    step->restore_arrays(c.arrays);
  }
}

/// The stored count `count` of system `system`: by name, or by the
/// system's position in the layout before names.
double stored_count(const Checkpoint& c, const std::string& system, const std::string& count)
{
  if (const auto by_name = c.numbers.find(system + "." + count); by_name != c.numbers.end())
    return by_name->second;
  const std::vector<std::string> positions{"flow", "mechanics", "monolithic", "flow_second_pass"};
  const auto i = std::find(positions.begin(), positions.end(), system) - positions.begin();
  // A count newer than the checkpoint (schur_factorizations) is 0.
  const auto by_position = c.numbers.find(std::to_string(i) + "." + count);
  return by_position != c.numbers.end() ? by_position->second : 0.0;
}

} // namespace

void restore_run_state(const Checkpoint& c, const RunState& run, MPI_Comm comm, const std::string& directory)
{
  run.grid.t = c.arrays.at("times");
  run.grid.dt = c.arrays.at("time_steps");
  restore_unknowns(c, run, comm, directory);
  // A number newer than the checkpoint (fallback_steps) keeps its value at
  // the run's start.
  for_each_checkpointed(run.report, run.state,
                        [&](const char* name, auto& value)
                        {
                          if (const auto stored = c.numbers.find(name); stored != c.numbers.end())
                            value = static_cast<std::remove_reference_t<decltype(value)>>(stored->second);
                        });
}

void restore_checkpoint(const Checkpoint& c, const RunState& run, MPI_Comm comm, const std::string& directory)
{
  restore_run_state(c, run, comm, directory);
  for (Step* step : run.scheme.steps())
  {
    SolverStatistics earlier;
    for (const auto& [name, count] : solver_counts)
      earlier.*count = static_cast<long>(stored_count(c, step->name(), name));
    step->system().add_earlier(earlier);
  }
}

} // namespace biotcontact
