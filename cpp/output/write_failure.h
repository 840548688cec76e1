// A file of the run that cannot be written: a full disk, a quota, a lost
// mount. The run stops at the write that failed, with one line naming the
// file and the system's reason, and keeps everything written before
// (exit status run_output_failed).
#pragma once

#include <mpi.h>
#include <stdexcept>
#include <string>

namespace biotcontact
{

/// @brief A file of the run could not be written; the message names the
/// file and the reason.
struct OutputError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// Why the last write into `directory` failed, as the system says it:
/// HDF5's record of the system error, else errno; with the space left on
/// the device.
std::string write_failure_reason(const std::string& directory);

/// Throws OutputError with the lowest failing rank's message on every rank
/// when `failed` is not empty on any (collective), so that no rank is left
/// waiting in the next collective write.
void agree_on_output_error(const std::string& failed, MPI_Comm comm);

/// Silences HDF5's own printing of its error stack (a failed write is
/// reported once, by OutputError) and its closing of files at exit.
void silence_hdf5_errors();

} // namespace biotcontact
