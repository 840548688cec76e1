// Output of a run: the XDMF time series for ParaView and meshio
// (time_series.h), the per-iteration log iterations.csv and summary.json. Every row and every time written is
// flushed at once, so a run that stops later loses nothing it finished.
#pragma once

#include "coupling/coupling.h"
#include "output/time_series.h"
#include "output/write_failure.h"

#include <dolfinx/fem/Function.h>
#include <fstream>
#include <map>
#include <memory>
#include <mpi.h>
#include <string>
#include <vector>

namespace biotcontact
{

/// A JSON object built key by key, in insertion order.
class Json
{
public:
  Json& set(const std::string& key, double value);
  Json& set(const std::string& key, int value);
  Json& set(const std::string& key, long value);
  Json& set(const std::string& key, bool value);
  Json& set(const std::string& key, const std::string& value);
  Json& set(const std::string& key, const char* value) { return set(key, std::string(value)); }
  Json& set(const std::string& key, const Json& value);
  /// An array of numbers.
  Json& set(const std::string& key, const std::vector<double>& values);
  std::string str(int indent = 0) const;

private:
  std::vector<std::pair<std::string, std::string>> _items;
  std::vector<bool> _nested;
  std::vector<Json> _children;
};

class Output
{
public:
  /// Creates the files; or, given the position() of an earlier run of the
  /// same scene, goes on in its files, dropping what came after the state.
  Output(MPI_Comm comm, const std::string& directory, std::shared_ptr<const dolfinx::mesh::Mesh> mesh,
         bool xdmf, const std::string* resume = nullptr);

  /// Where the files stand, for a checkpoint (this rank's view).
  std::string position();

  /// The writers throw OutputError on every rank when any rank failed.
  void write(const dolfinx::fem::Function<double>& f, double t);
  void iteration(const IterationRecord& r);
  void summary(const Json& json) const;
  std::string xdmf_path() const { return _directory + "/solution.xdmf"; }
  const std::string& directory() const { return _directory; }

  double time = 0; // seconds spent writing

private:
  MPI_Comm _comm;
  std::string _directory;
  std::unique_ptr<TimeSeries> _series;
  std::ofstream _csv;
};

} // namespace biotcontact
