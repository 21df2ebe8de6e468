// The real capture: the Middlebury temple (../shared/captures/middlebury_temple, outside the
// repository), reduced so that it runs in a test: no subdivision and a mask of the middle band of
// the temple's height. Refine with the four views of configs/temple.yaml held out, then eval: every
// held-out view gets finite scores, from the photos alone (the capture has no ground truth).
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/io/capture.h"
#include "finecap/refine/frame_stats.h"
#include "test_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

// ../shared/captures next to the repository (as CI has it), or the folder FINECAP_CAPTURES names
// (a worktree elsewhere).
std::string TempleDir() {
  const char* captures = std::getenv("FINECAP_CAPTURES");
  return (captures != nullptr && *captures != '\0' ? std::string(captures)
                                                   : FINECAP_SOURCE_DIR "/../shared/captures") +
         "/middlebury_temple";
}

// The temple with a mask.txt of the coarse vertices whose height (world y) lies in the middle
// `share` of the mesh's: the capture's own files linked, not copied.
std::string ReducedTemple(const std::string& root, double share) {
  const std::string dir = root + "/temple";
  fs::create_directories(dir);
  for (const char* entry : {"cameras.yaml", "images", "meshes"}) {
    fs::create_symlink(fs::absolute(fs::path(TempleDir()) / entry), fs::path(dir) / entry);
  }
  const Mesh mesh = Capture::Open(dir).ReadCoarseMesh(0);
  const double low = mesh.vertices.row(1).minCoeff(), high = mesh.vertices.row(1).maxCoeff();
  const double middle = 0.5 * (low + high), half = 0.5 * share * (high - low);
  std::ostringstream mask;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (std::abs(mesh.vertices(1, v) - middle) <= half) mask << v << "\n";
  }
  testing_util::WriteText(dir + "/mask.txt", mask.str());
  return dir;
}

TEST(TempleTest, HeldOutViewsAreScoredOnRealPhotos) {
  if (!fs::exists(fs::path(TempleDir()) / "cameras.yaml")) {
    GTEST_SKIP() << "the Middlebury temple capture is not at " << TempleDir()
                 << " (../shared/captures/middlebury_temple next to the repository, or "
                    "$FINECAP_CAPTURES/middlebury_temple)";
  }
  const std::string root = testing_util::MakeTempDir("temple");
  Config config = LoadConfig(FINECAP_SOURCE_DIR "/configs/temple.yaml",
                             {{"model.subdivision_levels", "0", "test"}});
  config.capture.dir = ReducedTemple(root, 0.3);
  config.output.dir = root + "/run";
  config.eval.flow = "none";
  ASSERT_EQ(config.validation.cameras.size(), 4u);
  ASSERT_EQ(RunRefine(config), 0);
  const FrameStats stats = ParseFrameStats(
      testing_util::FileBytes(config.output.dir + "/frames/000000.json"), "temple record");
  EXPECT_TRUE(std::isfinite(stats.heldout_ncc_input));
  EXPECT_TRUE(std::isfinite(stats.heldout_ncc_refined));
  EXPECT_EQ(stats.worse, stats.heldout_ncc_refined < stats.heldout_ncc_input ||
                             stats.energy_end < stats.energy_start);

  ASSERT_EQ(RunEval(config), 0);
  const YAML::Node metrics = YAML::LoadFile(config.output.dir + "/eval/metrics.json");
  // No ground truth: no displacement error, but held-out figures for every held-out view.
  EXPECT_TRUE(metrics["rms_coarse_mm"].IsNull());
  const YAML::Node views = metrics["frames"][0]["heldout"]["views"];
  ASSERT_EQ(views.size(), 4u);
  for (size_t h = 0; h < views.size(); ++h) {
    EXPECT_EQ(views[h]["camera"].as<std::string>(), config.validation.cameras[h]);
    EXPECT_EQ(views[h]["training"].size(), 4u);
    for (const char* key : {"ncc_input", "ncc_subdivided", "ncc_refined", "mad_input",
                            "mad_subdivided", "mad_refined"}) {
      const double value = views[h][key].as<double>();
      EXPECT_TRUE(std::isfinite(value)) << key;
    }
    // A visual hull of real photos correlates, if poorly, with its neighbours.
    EXPECT_GT(views[h]["ncc_input"].as<double>(), 0.0);
    EXPECT_GT(views[h]["ncc_pixels"].as<long>(), 10000);
    EXPECT_TRUE(fs::exists(config.output.dir + "/eval/heldout_000000_" +
                           config.validation.cameras[h] + ".png"));
  }
  EXPECT_NEAR(metrics["heldout_ncc_input"].as<double>(), stats.heldout_ncc_input, 1e-6);
  // Without subdivision the input as given and the subdivided input are one surface.
  EXPECT_EQ(metrics["heldout_ncc_subdivided"].as<double>(),
            metrics["heldout_ncc_input"].as<double>());
  EXPECT_NEAR(stats.heldout_ncc_subdivided, stats.heldout_ncc_input, 1e-9);
}

}  // namespace
}  // namespace finecap
