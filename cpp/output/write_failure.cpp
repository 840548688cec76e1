#include "output/write_failure.h"

#include "scene/scene.h"

#include <cerrno>
#include <cstring>
#include <hdf5.h>
#include <iomanip>
#include <sstream>
#include <sys/statvfs.h>

namespace biotcontact
{

namespace
{
/// The system's words in HDF5's error stack: its POSIX file driver records
/// "errno = 28, error message = 'No space left on device'", MPI-IO
/// "MPI error string is '...'".
herr_t find_system_error(unsigned, const H5E_error2_t* e, void* found)
{
  auto& reason = *static_cast<std::string*>(found);
  const std::string text = e->desc ? e->desc : "";
  for (const std::string mark : {"error message = '", "error string is '"})
    if (const auto at = text.find(mark); reason.empty() and at != std::string::npos)
    {
      const auto start = at + mark.size();
      reason = text.substr(start, text.find('\'', start) - start);
    }
  return 0;
}
} // namespace

std::string write_failure_reason(const std::string& directory)
{
  std::string reason;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, find_system_error, &reason);
  H5Eclear2(H5E_DEFAULT);
  if (reason.empty() and errno != 0)
    reason = std::strerror(errno);
  struct statvfs disk{};
  if (statvfs(directory.c_str(), &disk) == 0)
  {
    if (reason.empty() and disk.f_bavail == 0) // MPI-IO does not always say
      reason = std::strerror(ENOSPC);
    std::ostringstream left;
    left << std::setprecision(3) << static_cast<double>(disk.f_bavail) * static_cast<double>(disk.f_frsize) / 1e6
         << " MB left on the device";
    reason += (reason.empty() ? "" : "; ") + left.str();
  }
  return reason.empty() ? std::string("the system gave no reason") : reason;
}

void agree_on_output_error(const std::string& failed, MPI_Comm comm)
{
  if (const std::string text = agreed_error(failed, comm); !text.empty())
    throw OutputError(text);
}

void silence_hdf5_errors()
{
  // Before any other HDF5 call: at exit, HDF5 would close the file that a
  // failed write left behind, collectively, and could wait forever.
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

} // namespace biotcontact
