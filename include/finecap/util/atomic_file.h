// Output files are written under a temporary name in the same folder and renamed into place, so
// an interrupted run never leaves a half-written file under the real name.
#ifndef FINECAP_UTIL_ATOMIC_FILE_H_
#define FINECAP_UTIL_ATOMIC_FILE_H_

#include <functional>
#include <string>

namespace finecap {

// Calls `write(temporary_path)`, then renames the temporary file to `path`. If `write` throws,
// the temporary file is removed and the exception propagates; `path` is untouched.
void WriteFileAtomically(const std::string& path,
                         const std::function<void(const std::string& temporary_path)>& write);

// Writes `contents` to `path` atomically. Throws Error naming the path on failure.
void WriteTextFileAtomically(const std::string& path, const std::string& contents);

// The two halves of WriteFileAtomically, for a writer that keeps its file open across calls
// (e.g. a streamed point cache). TemporaryPathFor names the temporary: in the folder of `path`,
// so the final rename stays on one file system, and ending in the same file name, so writers
// that choose the format by the extension still do. The name, ".tmp-<host>+<pid>-<file name>",
// says which process writes it, so that RemoveStaleTemporaries can tell a live writer's file
// from one that a killed process left behind.
std::string TemporaryPathFor(const std::string& path);

// Renames the finished `temporary_path` to `path`. On failure removes the temporary and throws
// Error naming `path`.
void MoveIntoPlace(const std::string& temporary_path, const std::string& path);

// Removes the temporaries in `folder` (not below it) whose writer was a process of this host
// that no longer runs: what a run killed while writing leaves behind. Temporaries of running
// processes and of other hosts (which share the folder on a cluster file system) stay. Returns
// how many were removed; a missing folder holds none.
int RemoveStaleTemporaries(const std::string& folder);

}  // namespace finecap

#endif  // FINECAP_UTIL_ATOMIC_FILE_H_
