// Temporaries of the atomic writes: named after their writer, and removed only when that writer,
// a process of this host, no longer runs.
#include "finecap/util/atomic_file.h"

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_util.h"

namespace finecap {
namespace {

using testing_util::FilesIn;
using testing_util::MakeTempDir;
using testing_util::WriteText;

std::string HostName() {
  char name[256] = {};
  gethostname(name, sizeof(name) - 1);
  return name;
}

// The pid of a process that has ended.
pid_t EndedProcess() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  waitpid(pid, nullptr, 0);
  return pid;
}

TEST(AtomicFileTest, TemporaryNamesTheHostAndTheProcessAndKeepsTheExtension) {
  const std::string temporary = TemporaryPathFor("/some/folder/000001.ply");
  EXPECT_EQ(temporary,
            "/some/folder/.tmp-" + HostName() + "+" + std::to_string(getpid()) + "-000001.ply");
}

TEST(AtomicFileTest, RemovesOnlyTheTemporariesOfEndedProcessesOfThisHost) {
  const std::string dir = MakeTempDir("stale");
  const std::string ended = std::to_string(EndedProcess());
  const std::string host = HostName();
  WriteText(dir + "/.tmp-" + host + "+" + ended + "-000001.ply", "partial");
  WriteText(dir + "/.tmp-" + host + "+" + ended + "-stats.jsonl", "partial");
  WriteText(dir + "/.tmp-" + host + "+" + std::to_string(getpid()) + "-000002.ply", "mine");
  WriteText(dir + "/.tmp-" + host + "+1-000003.ply", "init runs");
  WriteText(dir + "/.tmp-other-node+" + ended + "-000004.ply", "another host's writer");
  WriteText(dir + "/000001.ply", "a result");
  WriteText(dir + "/.tmp-notes.txt", "not a temporary of ours");
  EXPECT_EQ(RemoveStaleTemporaries(dir), 2);
  const std::vector<std::string> expected = {
      ".tmp-" + host + "+" + std::to_string(getpid()) + "-000002.ply",
      ".tmp-" + host + "+1-000003.ply", ".tmp-notes.txt",
      ".tmp-other-node+" + ended + "-000004.ply", "000001.ply"};
  std::vector<std::string> sorted = expected;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(FilesIn(dir), sorted);
  EXPECT_EQ(RemoveStaleTemporaries(dir + "/missing"), 0);
}

}  // namespace
}  // namespace finecap
