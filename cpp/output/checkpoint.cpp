#include "output/checkpoint.h"

#include "scene/scene.h"

#include <cstdint>
#include <filesystem>
#include <fstream>

namespace biotcontact
{

namespace
{
const char magic[] = "biotcontact checkpoint 1";

std::string rank_file(const std::string& directory, int rank)
{
  return directory + "/checkpoint/rank" + std::to_string(rank) + ".bin";
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
} // namespace

void write_checkpoint(MPI_Comm comm, const std::string& directory, const std::string& fingerprint,
                      const Checkpoint& c)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (rank == 0)
    std::filesystem::create_directories(directory + "/checkpoint");
  MPI_Barrier(comm);
  const std::string path = rank_file(directory, rank);
  {
    std::ofstream f(path + ".new", std::ios::binary | std::ios::trunc);
    put(f, std::string(magic));
    put(f, fingerprint);
    put(f, size);
    put(f, c.steps);
    put(f, c.time);
    put(f, static_cast<std::uint64_t>(c.numbers.size()));
    for (const auto& [name, value] : c.numbers)
      put(f, name), put(f, value);
    put(f, static_cast<std::uint64_t>(c.arrays.size()));
    for (const auto& [name, values] : c.arrays)
    {
      put(f, name);
      put(f, static_cast<std::uint64_t>(values.size()));
      f.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(double)));
    }
    put(f, c.output);
    if (!f)
      throw std::runtime_error("cannot write the checkpoint " + path);
  }
  // Every rank's new file is complete before any replaces the old one.
  MPI_Barrier(comm);
  std::filesystem::rename(path + ".new", path);
  MPI_Barrier(comm);
}

Checkpoint read_checkpoint(MPI_Comm comm, const std::string& directory, const std::string& fingerprint)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  Checkpoint c;
  std::string error;
  const std::string path = rank_file(directory, rank);
  try
  {
    std::ifstream f(path, std::ios::binary);
    if (!f)
      throw SceneError("--restart " + directory + ": no checkpoint there (" + path
                       + "; runs write one with output.checkpoint_every)");
    if (get_string(f) != magic)
      throw SceneError("--restart " + directory + ": " + path + " is no biotcontact checkpoint");
    if (get_string(f) != fingerprint)
      throw SceneError("--restart " + directory
                       + ": the checkpoint was written for another scene or other --set values");
    if (const int ranks = get<int>(f); ranks != size)
      throw SceneError("--restart " + directory + ": the checkpoint was written by " + std::to_string(ranks)
                       + " ranks; restart with as many");
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
      std::vector<double>& values = c.arrays[name];
      values.resize(get<std::uint64_t>(f));
      f.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(double)));
    }
    c.output = get_string(f);
    if (!f)
      throw std::runtime_error("truncated");
  }
  catch (const SceneError& e)
  {
    error = e.what();
  }
  catch (const std::exception&)
  {
    error = "--restart " + directory + ": the checkpoint " + path + " is damaged";
  }
  agree_on_error(error, comm);
  // The ranks' files must be of one checkpoint.
  int steps[2] = {c.steps, -c.steps}, extremes[2];
  MPI_Allreduce(steps, extremes, 2, MPI_INT, MPI_MAX, comm);
  if (extremes[0] != -extremes[1])
    throw SceneError("--restart " + directory + ": the ranks' checkpoint files are of different steps");
  return c;
}

} // namespace biotcontact
