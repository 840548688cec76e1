#include "output/directory_lock.h"

#include "output/progress.h"
#include "scene/scene.h"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <fcntl.h>
#include <filesystem>
#include <sys/file.h>
#include <unistd.h>

namespace biotcontact
{

namespace
{
/// What the lock file says of its holder: "pid 1234 on host, started ...".
std::string holder(int fd)
{
  char text[256] = {};
  const ssize_t n = pread(fd, text, sizeof text - 1, 0);
  std::string s = n > 0 ? std::string(text, static_cast<std::size_t>(n)) : "an unknown process";
  while (!s.empty() and (s.back() == '\n' or s.back() == ' '))
    s.pop_back();
  return s;
}

/// This process, as the lock file records it.
std::string this_process()
{
  char host[128] = {};
  gethostname(host, sizeof host - 1);
  const std::time_t now = std::time(nullptr);
  char started[64];
  std::strftime(started, sizeof started, "%Y-%m-%d %H:%M:%S", std::localtime(&now));
  return "process " + std::to_string(getpid()) + " on " + host + ", started " + started + "\n";
}
} // namespace

DirectoryLock::DirectoryLock(MPI_Comm comm, const std::string& directory)
{
  std::string error;
  if (is_rank0(comm))
  {
    std::error_code ec;
    std::filesystem::create_directories(directory, ec);
    const std::string path = directory + "/" + file_name;
    if (ec)
      error = "--out " + directory + ": cannot create the output directory: " + ec.message();
    else if ((_fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644)) < 0)
      error = "--out " + directory + ": cannot create the lock file " + file_name + ": " + std::strerror(errno);
    else if (flock(_fd, LOCK_EX | LOCK_NB) != 0)
    {
      error = "--out " + directory + ": the directory is in use by another run (" + holder(_fd)
              + "); one run per output directory: choose another --out or wait for it to end";
      close(_fd);
      _fd = -1;
    }
    else
    {
      const std::string me = this_process();
      if (ftruncate(_fd, 0) != 0 or pwrite(_fd, me.data(), me.size(), 0) != static_cast<ssize_t>(me.size()))
        error = "--out " + directory + ": cannot write the lock file " + file_name + ": " + std::strerror(errno);
    }
  }
  agree_on_error(error, comm);
}

DirectoryLock::~DirectoryLock()
{
  if (_fd >= 0)
    close(_fd); // releases the lock; the file stays, unlocked
}

} // namespace biotcontact
