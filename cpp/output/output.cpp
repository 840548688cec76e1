#include "output/output.h"

#include "output/progress.h"
#include "scene/scene.h"

#include <cerrno>
#include <cmath>
#include <dolfinx/common/Timer.h>
#include <filesystem>
#include <iomanip>
#include <sstream>

namespace biotcontact
{

namespace
{
std::string number(double v)
{
  if (!std::isfinite(v))
    return "null"; // JSON has no NaN or infinity
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}

std::string quoted(const std::string& v)
{
  std::string q = "\"";
  for (char c : v)
  {
    if (c == '"' or c == '\\')
      q += '\\';
    q += c;
  }
  return q + "\"";
}
} // namespace

Json& Json::set(const std::string& key, double value)
{
  _items.emplace_back(key, number(value));
  _nested.push_back(false);
  return *this;
}
Json& Json::set(const std::string& key, int value) { return set(key, static_cast<long>(value)); }
Json& Json::set(const std::string& key, const std::vector<double>& values)
{
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i)
    text += (i ? ", " : "") + number(values[i]);
  _items.emplace_back(key, text + "]");
  _nested.push_back(false);
  return *this;
}
Json& Json::set(const std::string& key, long value)
{
  _items.emplace_back(key, std::to_string(value));
  _nested.push_back(false);
  return *this;
}
Json& Json::set(const std::string& key, bool value)
{
  _items.emplace_back(key, value ? "true" : "false");
  _nested.push_back(false);
  return *this;
}
Json& Json::set(const std::string& key, const std::string& value)
{
  _items.emplace_back(key, quoted(value));
  _nested.push_back(false);
  return *this;
}
Json& Json::set(const std::string& key, const Json& value)
{
  _items.emplace_back(key, std::to_string(_children.size()));
  _nested.push_back(true);
  _children.push_back(value);
  return *this;
}

std::string Json::str(int indent) const
{
  const std::string pad(indent + 2, ' ');
  std::string s = "{\n";
  for (std::size_t i = 0; i < _items.size(); ++i)
  {
    s += pad + quoted(_items[i].first) + ": ";
    s += _nested[i] ? _children[std::stoul(_items[i].second)].str(indent + 2) : _items[i].second;
    s += i + 1 < _items.size() ? ",\n" : "\n";
  }
  return s + std::string(indent, ' ') + "}";
}

Output::Output(MPI_Comm comm, const std::string& directory,
               std::shared_ptr<const dolfinx::mesh::Mesh> mesh, bool xdmf, const std::string* resume)
    : _comm(comm), _directory(directory)
{
  // A resumed run's state starts with the length of iterations.csv.
  std::istringstream state(resume ? *resume : "");
  std::uintmax_t csv_size = 0;
  std::string series;
  if (resume)
  {
    state >> csv_size;
    series.assign(std::istreambuf_iterator<char>(state >> std::ws), {});
  }
  // Rank 0 writes the log; every rank learns whether it could (a failure
  // on rank 0 alone would leave the others waiting). The directory exists:
  // the run's DirectoryLock made it.
  std::string error;
  if (is_rank0(comm))
  {
    std::error_code ec;
    {
      const std::string csv = directory + "/iterations.csv";
      if (resume)
      {
        std::filesystem::resize_file(csv, csv_size, ec);
        _csv.open(csv, std::ios::app);
      }
      else
        _csv.open(csv);
      if (!_csv or ec)
        error = "--out " + directory + ": cannot write iterations.csv there";
      else if (!resume)
        _csv << "step,time,iteration,dsigma_norm,ratio,gamma,dp_norm,du_norm,active_nodes,fault_dp_norm,"
                "fault_ratio,newton_steps\n"
             << std::flush;
    }
  }
  agree_on_error(error, comm);
  if (!xdmf)
    return;
  std::string failed;
  try
  {
    _series = std::make_unique<TimeSeries>(comm, xdmf_path(), *mesh, resume ? &series : nullptr);
  }
  catch (const OutputError& e) // rank 0's XML file
  {
    failed = e.what();
  }
  agree_on_output_error(failed, comm);
}

std::string Output::position()
{
  const std::streamoff csv = _csv.is_open() ? static_cast<std::streamoff>(_csv.tellp()) : 0;
  return std::to_string(csv) + "\n" + (_series ? _series->position() : std::string());
}

void Output::write(const dolfinx::fem::Function<double>& f, double t)
{
  if (!_series)
    return;
  dolfinx::common::Timer timer("output");
  std::string failed;
  try
  {
    _series->write(f, t);
  }
  catch (const OutputError& e)
  {
    failed = e.what();
  }
  agree_on_output_error(failed, _comm);
  time += timer.stop();
}

void Output::iteration(const IterationRecord& r)
{
  std::string failed;
  if (_csv.is_open())
  {
    auto v = [](double x) { return std::isfinite(x) ? number(x) : std::string(""); };
    errno = 0;
    _csv << r.step << ',' << number(r.time) << ',' << r.iteration << ',' << v(r.dsigma_norm) << ','
         << v(r.ratio) << ',' << v(r.gamma) << ',' << v(r.dp_norm) << ',' << v(r.du_norm) << ','
         << r.active_nodes << ',' << v(r.fault_dp_norm) << ',' << v(r.fault_ratio) << ',' << r.newton_steps << '\n'
         << std::flush;
    if (!_csv)
      failed = "cannot write " + _directory + "/iterations.csv: " + write_failure_reason(_directory);
  }
  agree_on_output_error(failed, _comm);
}

void Output::summary(const Json& json) const
{
  std::string failed;
  if (is_rank0(_comm))
  {
    // Written beside and renamed: a full disk leaves the old one or none,
    // never half of one.
    const std::string path = _directory + "/summary.json";
    errno = 0;
    std::ofstream f(path + ".new");
    f << json.str() << "\n" << std::flush;
    std::error_code ec;
    if (f)
      std::filesystem::rename(path + ".new", path, ec);
    if (!f or ec)
    {
      failed = "cannot write " + path + ": " + write_failure_reason(_directory);
      std::filesystem::remove(path + ".new", ec);
    }
  }
  agree_on_output_error(failed, _comm);
}

} // namespace biotcontact
