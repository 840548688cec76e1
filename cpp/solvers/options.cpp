#include "solvers/options.h"

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

} // namespace biotcontact
