// The memory a process may use, read before a run that may need more than there is.
#ifndef FINECAP_UTIL_MEMORY_H_
#define FINECAP_UTIL_MEMORY_H_

#include <string>

namespace finecap {

struct AvailableMemory {
  // Megabytes (1e6 bytes) this process may still take; infinite when nothing could be read.
  double megabytes;
  // The file the figure comes from ("/proc/meminfo", "/sys/fs/cgroup/memory.max", ...), for
  // the messages that quote it; empty when none could be read.
  std::string source;
};

// The smaller of the memory limit of this process's cgroup (v2: memory.max of its cgroup, or of
// the root a container sees; v1: memory/memory.limit_in_bytes), when it has one, and
// MemAvailable of /proc/meminfo: a cgroup limit can lie above what the machine has free, and the
// machine can have more free than the cgroup lets a process take. The limit is taken whole, not
// less the cgroup's usage, since that usage counts page cache the kernel reclaims before it
// kills. `root` prefixes every path ("" reads the live system; a test passes a folder laid out
// like it).
AvailableMemory ReadAvailableMemory(const std::string& root = "");

// MemAvailable of a /proc/meminfo text, megabytes; negative when the line is missing or malformed.
double ParseMemAvailableMegabytes(const std::string& meminfo);

// A cgroup memory limit as the file holds it ("max", or bytes), megabytes; infinite for "max" and
// for v1's "no limit" (a figure near 2^63), negative when malformed.
double ParseCgroupLimitMegabytes(const std::string& text);

}  // namespace finecap

#endif  // FINECAP_UTIL_MEMORY_H_
