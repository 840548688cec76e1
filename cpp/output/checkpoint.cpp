#include "output/checkpoint.h"

#include "output/write_failure.h"
#include "domain/domain.h"
#include "scene/scene.h"

#include <algorithm>
#include <array>
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

/// @brief The input names of the entities a space's DOFs sit on, per local
/// DOF block (owned and ghost), and the orientation of each.
struct EntityNames
{
  int width = 1;
  std::vector<std::int64_t> names; // width per block, ascending
  std::vector<double> sign;        // +-1: the DOF's orientation against the names' order
};

/// The sorted input indices of a facet's vertices and the parity of the
/// permutation from the order of the partition's global vertex numbering
/// (dolfinx's orientation of the facet) to that sorted order.
double facet_name(std::span<const std::int32_t> vertices, const std::vector<std::int64_t>& input,
                  const dolfinx::common::IndexMap& vertex_map, std::int64_t* name)
{
  std::array<std::int32_t, 3> local{};
  std::array<std::int64_t, 3> global{};
  const std::size_t n = std::min<std::size_t>(vertices.size(), 3); // simplex facets
  std::copy(vertices.begin(), vertices.end(), local.begin());
  vertex_map.local_to_global(std::span(local.data(), n), std::span(global.data(), n));
  std::array<std::size_t, 3> order{0, 1, 2};
  for (std::size_t a = 1; a < n; ++a) // insertion sort of at most 3
    for (std::size_t b = a; b > 0 and global[order[b]] < global[order[b - 1]]; --b)
      std::swap(order[b], order[b - 1]);
  int inversions = 0;
  for (std::size_t a = 0; a < n; ++a)
  {
    name[a] = input[local[order[a]]];
    for (std::size_t b = a + 1; b < n; ++b)
      inversions += input[local[order[a]]] > input[local[order[b]]];
  }
  std::sort(name, name + n);
  return inversions % 2 == 0 ? 1.0 : -1.0;
}

/// The names of the DOF blocks of V: one DOF per vertex, facet or cell.
EntityNames entity_names(const dolfinx::mesh::Mesh& mesh, const dolfinx::fem::FunctionSpace& V)
{
  const int tdim = mesh.topology().dim();
  const auto& dofmap = *V.dofmap();
  const auto& layout = dofmap.element_dof_layout();
  int dim = 0;
  while (dim <= tdim and layout.num_entity_dofs(dim) == 0)
    ++dim;
  const int per_cell = dim > tdim ? 0 : mesh::cell_num_entities(mesh.topology().cell_type(), dim);
  if (dim > tdim or layout.num_entity_dofs(dim) != 1 or layout.num_dofs() != per_cell)
    throw std::runtime_error("checkpoint: a space that is not one DOF per vertex, facet or cell");
  const auto blocks = dofmap.index_map->size_local() + dofmap.index_map->num_ghosts();
  EntityNames e;
  e.width = dim == tdim - 1 ? tdim : 1;
  e.names.assign(blocks * e.width, -1);
  e.sign.assign(blocks, 1.0);
  const std::vector<std::int64_t> input = vertex_input_indices(mesh);
  const auto cells = mesh.topology().index_map(tdim);
  const auto c_to_f = dim == tdim - 1 ? mesh.topology().connectivity(tdim, dim) : nullptr;
  const auto f_to_v = dim == tdim - 1 ? mesh.topology().connectivity(dim, 0) : nullptr;
  for (std::int32_t c = 0; c < cells->size_local() + cells->num_ghosts(); ++c)
  {
    auto cell_dofs = dofmap.cell_dofs(c);
    for (int k = 0; k < per_cell; ++k)
    {
      const std::int32_t block = cell_dofs[layout.entity_dofs(dim, k)[0]];
      std::int64_t* name = e.names.data() + block * e.width;
      if (dim == 0)
        name[0] = input[mesh.topology().connectivity(tdim, 0)->links(c)[k]];
      else if (dim == tdim)
        name[0] = mesh.topology().original_cell_index[c];
      else
        e.sign[block] = facet_name(f_to_v->links(c_to_f->links(c)[k]), input, *mesh.topology().index_map(0), name);
    }
  }
  return e;
}

using Key = std::array<std::int64_t, 3>;
struct KeyHash
{
  std::size_t operator()(const Key& k) const
  {
    std::size_t h = 0;
    for (std::int64_t v : k)
      h = h * 1000003u ^ std::hash<std::int64_t>()(v);
    return h;
  }
};

Key key(const std::int64_t* name, int width)
{
  Key k{-1, -1, -1};
  std::copy(name, name + width, k.begin());
  return k;
}
} // namespace

KeyedValues keyed_values(const dolfinx::mesh::Mesh& mesh, const UnknownsPart& part, std::span<const double> unknowns)
{
  const auto& dofmap = *part.space->dofmap();
  const int bs = dofmap.index_map_bs();
  const EntityNames e = entity_names(mesh, *part.space);
  KeyedValues kv;
  kv.width = e.width;
  for (std::int32_t block = 0; block < dofmap.index_map->size_local(); ++block)
    for (int j = 0; j < bs; ++j)
    {
      const std::int32_t entry = block * bs + j;
      for (int w = 0; w < e.width; ++w)
        kv.keys.push_back(bs == 1 ? e.names[block * e.width + w] : e.names[block] * bs + j);
      kv.values.push_back(e.sign[block] * unknowns[part.position.empty() ? entry : part.position[entry]]);
    }
  return kv;
}

std::int64_t restore_values(const dolfinx::mesh::Mesh& mesh, const UnknownsPart& part, const KeyedValues& values,
                            std::span<double> unknowns)
{
  const auto& dofmap = *part.space->dofmap();
  const int bs = dofmap.index_map_bs();
  const EntityNames e = entity_names(mesh, *part.space);
  const std::int32_t blocks = dofmap.index_map->size_local() + dofmap.index_map->num_ghosts();
  std::unordered_map<Key, std::int32_t, KeyHash> entry_of;
  for (std::int32_t block = 0; block < blocks; ++block)
    for (int j = 0; j < bs; ++j)
    {
      const std::int64_t vertex = e.names[block] * bs + j;
      entry_of[bs == 1 ? key(&e.names[block * e.width], e.width) : key(&vertex, 1)] = block * bs + j;
    }
  std::int64_t found = 0;
  const std::int32_t owned = dofmap.index_map->size_local() * bs;
  if (values.width == e.width)
    for (std::size_t i = 0; i < values.values.size(); ++i)
      if (auto it = entry_of.find(key(&values.keys[i * values.width], values.width)); it != entry_of.end())
      {
        const std::int32_t entry = it->second;
        unknowns[part.position.empty() ? entry : part.position[entry]] = e.sign[entry / bs] * values.values[i];
        found += entry < owned;
      }
  return owned - found;
}

std::vector<double> mesh_signature(const dolfinx::mesh::Mesh& mesh)
{
  const auto& geometry = mesh.geometry();
  const std::vector<std::int64_t>& input = geometry.input_global_indices();
  const auto x = geometry.x();
  double sum = 0.0;
  for (std::int32_t node = 0; node < geometry.index_map()->size_local(); ++node)
    for (int j = 0; j < geometry.dim(); ++j)
      sum += x[3 * node + j] * static_cast<double>(1 + (input[node] * 3 + j) % 1009);
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, mesh.comm());
  const int tdim = mesh.topology().dim();
  return {static_cast<double>(geometry.index_map()->size_global()),
          static_cast<double>(mesh.topology().index_map(tdim)->size_global()), sum};
}

std::string mesh_difference(const std::vector<double>& stored, const std::vector<double>& current)
{
  auto size = [](const std::vector<double>& s)
  { return std::to_string(std::int64_t(s[0])) + " nodes and " + std::to_string(std::int64_t(s[1])) + " cells"; };
  if (stored.size() != 3)
    return "written for an unknown mesh";
  if (stored[0] != current[0] or stored[1] != current[1])
    return "written for " + size(stored) + ", this mesh has " + size(current);
  if (std::abs(stored[2] - current[2]) > 1e-12 * std::max(std::abs(stored[2]), std::abs(current[2])))
    return "the same numbers of nodes and cells, but the nodes moved";
  return "";
}

namespace
{
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
    throw SceneError("--restart " + directory + ": the checkpoint was written for another scene or other --set values");
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
  for (const auto& [name, f] : run.scheme.history())
    restore({{name, f->function_space(), {}}}, f->x()->mutable_array());
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

void restore_checkpoint(const Checkpoint& c, const RunState& run, MPI_Comm comm, const std::string& directory)
{
  run.grid.t = c.arrays.at("times");
  run.grid.dt = c.arrays.at("time_steps");
  restore_unknowns(c, run, comm, directory);
  for_each_checkpointed(run.report, run.state, [&](const char* name, auto& value)
                        { value = static_cast<std::remove_reference_t<decltype(value)>>(c.numbers.at(name)); });
  for (Step* step : run.scheme.steps())
  {
    SolverStatistics earlier;
    for (const auto& [name, count] : solver_counts)
      earlier.*count = static_cast<long>(stored_count(c, step->name(), name));
    step->system().add_earlier(earlier);
  }
}

} // namespace biotcontact
