// Long runs: `finecap refine` killed with SIGKILL in the middle of a frame leaves no partial file,
// and the same command run again finishes with the results of a run that never stopped; two
// shards run one after the other give the results of one whole run; `finecap status` lists what
// is missing. Warm start is on, so each frame's result depends on the frame before it (the
// temporal term's own test resumes its pull, src/energy/terms/temporal/).
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/io/mesh_io.h"
#include "finecap/refine/frame_stats.h"
#include "finecap/synth/synth.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;
using testing_util::FileBytes;
using testing_util::FilesIn;
using testing_util::MakeTempDir;

constexpr int kFrames = 4;

// The arguments of every run: one thread, so that runs are repeatable to the last bit.
std::vector<std::string> RefineArguments(const std::string& capture, const std::string& out) {
  return {FINECAP_BINARY, "refine",
          "--capture",    capture,
          "--out",        out,
          "--threads",    "1",
          "--set",        "refine.warm_start=true,solver.max_iterations=8"};
}

// Starts the binary with `arguments`, its output discarded; returns its pid.
pid_t Start(const std::vector<std::string>& arguments) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    std::vector<char*> argv;
    for (const std::string& argument : arguments)
      argv.push_back(const_cast<char*>(argument.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

// Waits for `pid`; its exit code, or -1 when a signal ended it.
int Wait(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int RunToEnd(const std::vector<std::string>& arguments) { return Wait(Start(arguments)); }

std::string FrameName(int frame) {
  std::ostringstream name;
  name.width(6);
  name.fill('0');
  name << frame;
  return name.str();
}

// The numbers of a k/<frame>.txt file.
std::vector<double> ReadNumbers(const std::string& path) {
  std::istringstream text(FileBytes(path));
  std::vector<double> values;
  std::string line;
  while (std::getline(text, line)) {
    if (!line.empty() && line[0] != '#') values.push_back(std::strtod(line.c_str(), nullptr));
  }
  return values;
}

// Every line of `path` is one whole JSON object of a frame record; a frame's own record file
// holds one, stats.jsonl may hold none yet (a run killed before its first frame was logged).
void ExpectWholeRecords(const std::string& path) {
  const std::string bytes = FileBytes(path);
  if (bytes.empty()) {
    EXPECT_EQ(fs::path(path).filename(), "stats.jsonl") << "an empty record file";
    return;
  }
  EXPECT_EQ(bytes.back(), '\n') << path;
  std::istringstream text(bytes);
  std::string line;
  while (std::getline(text, line)) {
    EXPECT_EQ(line.rfind("{\"frame\": ", 0), 0u) << path << ": " << line;
    EXPECT_NE(line.find("\"peak_rss_mb\": "), std::string::npos) << path << ": " << line;
    EXPECT_EQ(line.back(), '}') << path << ": " << line;
  }
}

// Nothing in `out` is partial: the names are final, every mesh parses, every displacement file
// and record is whole.
void ExpectNoPartialFile(const std::string& out) {
  for (const auto& entry : fs::recursive_directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(".tmp-", 0) == 0) continue;  // Never read: a temporary is not a result.
    const std::string folder = entry.path().parent_path().filename().string();
    if (folder == "meshes") {
      EXPECT_NO_THROW(ReadMesh(entry.path().string())) << entry.path();
    } else if (folder == "frames" || name == "stats.jsonl") {
      ExpectWholeRecords(entry.path().string());
    } else if (folder == "k") {
      // The mesh is written before its displacement: one number per vertex of it.
      const Mesh mesh = ReadMesh(out + "/meshes/" + entry.path().stem().string() + ".ply");
      EXPECT_EQ(ReadNumbers(entry.path().string()).size(), static_cast<size_t>(mesh.num_vertices()))
          << entry.path();
    }
  }
}

// The flicker figures of `frame`'s record in `out`, NaN where it has none.
std::vector<double> Flicker(const std::string& out, int frame) {
  const FrameStats record = ReadFrameStats(out + "/frames/" + FrameName(frame) + ".json");
  return {record.flicker_coarse_mm, record.flicker_subdivided_mm, record.flicker_refined_mm};
}

// `out` holds the very frames of `reference`, with displacements within 1e-9 m, the same flicker
// within 1e-6 mm (measured against the frame before, wherever that frame was refined) and the same
// records in stats.jsonl, in frame order.
void ExpectSameResults(const std::string& reference, const std::string& out) {
  for (const char* folder : {"meshes", "k", "frames"}) {
    EXPECT_EQ(FilesIn(out + "/" + folder), FilesIn(reference + "/" + folder)) << folder;
  }
  for (int frame = 0; frame < kFrames; ++frame) {
    const std::string file = "/k/" + FrameName(frame) + ".txt";
    const std::vector<double> expected = ReadNumbers(reference + file);
    const std::vector<double> actual = ReadNumbers(out + file);
    ASSERT_EQ(actual.size(), expected.size()) << file;
    ASSERT_FALSE(expected.empty()) << file;
    for (size_t v = 0; v < expected.size(); ++v) {
      if (std::isnan(expected[v])) {
        EXPECT_TRUE(std::isnan(actual[v])) << file << " vertex " << v;
      } else {
        EXPECT_NEAR(actual[v], expected[v], 1e-9) << file << " vertex " << v;
      }
    }
    const std::vector<double> expected_flicker = Flicker(reference, frame),
                              actual_flicker = Flicker(out, frame);
    for (size_t i = 0; i < expected_flicker.size(); ++i) {
      // No frame before the first; every other frame follows a done one.
      EXPECT_EQ(std::isnan(expected_flicker[i]), frame == 0) << FrameName(frame);
      if (frame > 0) {
        EXPECT_NEAR(actual_flicker[i], expected_flicker[i], 1e-6) << FrameName(frame);
      }
    }
  }
  std::istringstream lines(FileBytes(out + "/stats.jsonl"));
  std::string line;
  for (int frame = 0; frame < kFrames; ++frame) {
    ASSERT_TRUE(std::getline(lines, line)) << "stats.jsonl ends before frame " << frame;
    EXPECT_EQ(line.rfind("{\"frame\": \"" + FrameName(frame) + "\"", 0), 0u) << line;
  }
  EXPECT_FALSE(std::getline(lines, line)) << "more records than frames: " << line;
}

std::string HostName() {
  char name[256] = {};
  gethostname(name, sizeof(name) - 1);
  return name;
}

class ResumeTest : public ::testing::Test {
 protected:
  // One capture and one uninterrupted run for all tests.
  static void SetUpTestSuite() {
    root_ = new std::string(MakeTempDir("resume"));
    GenerateSyntheticCapture(testing_util::TinyRefinableSynthOptions(kFrames), capture());
    ASSERT_EQ(RunToEnd(RefineArguments(capture(), reference())), 0);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  static std::string capture() { return *root_ + "/capture"; }
  static std::string reference() { return *root_ + "/uninterrupted"; }
  static std::string* root_;
};

std::string* ResumeTest::root_ = nullptr;

TEST_F(ResumeTest, UninterruptedRunIsWhole) {
  ExpectNoPartialFile(reference());
  ExpectSameResults(reference(), reference());
}

TEST_F(ResumeTest, KilledInAFrameThenRerunEqualsUninterruptedRun) {
  const std::string out = *root_ + "/killed";
  const pid_t pid = Start(RefineArguments(capture(), out));
  // Kill as soon as the first frame is marked done: the process is then inside the second.
  const std::string first_record = out + "/frames/" + FrameName(0) + ".json";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!fs::exists(first_record) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(fs::exists(first_record));
  kill(pid, SIGKILL);
  EXPECT_EQ(Wait(pid), -1);
  EXPECT_LT(FilesIn(out + "/frames").size(), static_cast<size_t>(kFrames));
  ExpectNoPartialFile(out);

  // What a kill during a write leaves: a temporary of this host's dead process.
  const std::string stale = out + "/meshes/.tmp-" + HostName() + "+" + std::to_string(pid) + "-" +
                            FrameName(kFrames - 1) + ".ply";
  std::ofstream(stale) << "ply\nformat binary_little_endian 1.0\nelement vert";
  ASSERT_EQ(RunToEnd(RefineArguments(capture(), out)), 0);
  EXPECT_FALSE(fs::exists(stale));
  for (const auto& entry : fs::recursive_directory_iterator(out)) {
    EXPECT_NE(entry.path().filename().string().rfind(".tmp-", 0), 0u) << entry.path();
  }
  ExpectNoPartialFile(out);
  ExpectSameResults(reference(), out);
}

TEST_F(ResumeTest, TwoShardsOneAfterTheOtherEqualOneRun) {
  const std::string out = *root_ + "/shards";
  Config config;
  config.capture.dir = capture();
  config.output.dir = out;
  testing_util::ExpectErrorMentions([&] { RunStatus(config); }, {out, "no such folder"});
  EXPECT_FALSE(fs::exists(out));  // Status writes nothing.

  std::vector<std::string> first = RefineArguments(capture(), out);
  first.insert(first.end(), {"--shard", "0/2"});
  ASSERT_EQ(RunToEnd(first), 0);
  EXPECT_EQ(FilesIn(out + "/frames").size(), static_cast<size_t>((kFrames + 1) / 2));

  ::testing::internal::CaptureStdout();
  EXPECT_EQ(RunStatus(config), kStatusIncomplete);
  const std::string report = ::testing::internal::GetCapturedStdout();
  EXPECT_NE(report.find("2 of 4 frames done"), std::string::npos) << report;
  EXPECT_NE(report.find("missing 000002 to 000003 (indices 2:4)"), std::string::npos) << report;
  config.runtime.shard = {0, 2};
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(RunStatus(config), 0);
  ::testing::internal::GetCapturedStdout();

  std::vector<std::string> second = RefineArguments(capture(), out);
  second.insert(second.end(), {"--shard", "1/2"});
  ASSERT_EQ(RunToEnd(second), 0);
  ExpectSameResults(reference(), out);
  config.runtime.shard = {};
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(RunStatus(config), 0);
  EXPECT_NE(::testing::internal::GetCapturedStdout().find("4 of 4 frames done"), std::string::npos);
}

// The frame names of the records in `path`, in order.
std::vector<std::string> RecordFrames(const std::string& path) {
  std::istringstream lines(FileBytes(path));
  std::vector<std::string> frames;
  std::string line;
  while (std::getline(lines, line)) frames.push_back(line.substr(11, 6));  // {"frame": "......"
  return frames;
}

TEST_F(ResumeTest, ShardsInReverseOrderLeaveTheRecordsInFrameOrder) {
  Config config;
  config.capture.dir = capture();
  config.output.dir = *root_ + "/reverse";
  config.runtime.threads = 1;
  config.refine.solver.num_threads = 1;
  config.refine.solver.max_iterations = 2;
  config.runtime.shard = {1, 2};
  ASSERT_EQ(RunRefine(config), 0);
  EXPECT_EQ(RecordFrames(config.output.dir + "/stats.jsonl"),
            (std::vector<std::string>{"000002", "000003"}));
  config.runtime.shard = {0, 2};
  ASSERT_EQ(RunRefine(config), 0);
  EXPECT_EQ(RecordFrames(config.output.dir + "/stats.jsonl"),
            (std::vector<std::string>{"000000", "000001", "000002", "000003"}));
  ExpectNoPartialFile(config.output.dir);

  // More shards than frames: a shard without frames succeeds and writes none.
  config.output.dir = *root_ + "/empty_shard";
  config.runtime.shard = {5, 8};
  ASSERT_EQ(RunRefine(config), 0);
  EXPECT_TRUE(FilesIn(config.output.dir + "/frames").empty());
}

}  // namespace
}  // namespace finecap
