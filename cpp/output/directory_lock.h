// One run per output directory: a run holds an operating-system lock on
// DIR/.lock while it writes there, so that a second run into the same
// directory (a batch script reusing --out, a run started twice) stops before
// it creates or truncates anything instead of corrupting the first run's
// files. The kernel drops the lock when the process ends, however it ends
// (a SIGKILLed run leaves no stale lock behind).
#pragma once

#include <mpi.h>
#include <string>

namespace biotcontact
{

/// @brief The lock of a run on its output directory (rank 0 holds it for all).
///
/// The constructor creates the directory if needed, then takes the lock
/// (flock, exclusive, not waiting) and writes who holds it into the lock
/// file: process id, host and start time. If another process holds it, every
/// rank throws the one-line error naming the directory and that process.
/// The lock is released when the object is destroyed or the process ends.
class DirectoryLock
{
public:
  DirectoryLock(MPI_Comm comm, const std::string& directory);
  ~DirectoryLock();
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;

  /// The lock file's name in an output directory.
  static constexpr const char* file_name = ".lock";

private:
  int _fd = -1; // the locked file (rank 0), or -1
};

} // namespace biotcontact
