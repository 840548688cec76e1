#include "solvers/options.h"

#include <cstdlib>
#include <iterator>
#include <sstream>
#include <vector>

namespace biotcontact
{

std::string system_name(const std::string& prefix) { return "the " + prefix.substr(0, prefix.size() - 1); }

std::string threaded_superlu(const std::string& options, int threads)
{
  if (threads <= 1)
    return "";
  std::istringstream in(options);
  std::vector<std::string> words{std::istream_iterator<std::string>(in), {}};
  for (std::size_t i = 1; i < words.size(); ++i)
    if (words[i] == "superlu_dist")
      return words[i - 1] + " superlu_dist: SuperLU_DIST solves wrongly with " + std::to_string(threads)
             + " OpenMP threads (Debian's 8.1.2: the contact solver cycles, the split diverges); "
               "set OMP_NUM_THREADS=1";
  return "";
}

std::string relative_tolerance_out_of_range(const std::string& options)
{
  std::istringstream in(options);
  std::vector<std::string> words{std::istream_iterator<std::string>(in), {}};
  const std::string suffix = "_rtol";
  for (std::size_t i = 0; i + 1 < words.size(); ++i)
  {
    const std::string& name = words[i];
    if (name.size() <= suffix.size() or name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    char* end = nullptr;
    const double value = std::strtod(words[i + 1].c_str(), &end);
    if (end != words[i + 1].c_str() and *end == '\0' and !(value >= 0 and value < 1))
      return name + " " + words[i + 1] + ": a relative tolerance lies in [0, 1) (from 1 on any first iterate meets it)";
  }
  return "";
}

} // namespace biotcontact
