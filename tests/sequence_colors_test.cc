// The colours of a sequence (sequence.h, ReferenceColorOptions): taken at the refined reference
// surface instead of the coarse one, following the sequence while anchored to the reference, their
// recipes, and a resumed run that follows them exactly as a run that never stopped.
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/config/config.h"
#include "finecap/refine/sequence.h"
#include "finecap/synth/synth.h"
#include "finecap/util/error.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectErrorMentions;
using testing_util::FileBytes;
using testing_util::MakeTempDir;
using testing_util::OneWorkerThread;

// Refines quickly with the similarity that compares reference colours.
SequenceOptions SurfaceColorOptions() {
  SequenceOptions options;
  options.refine.energy.similarity = SimilarityType::kSurfaceColor;
  options.refine.solver.max_iterations = 3;
  options.refine.solver.num_threads = 1;
  options.refine.sweep.samples = 0;
  return options;
}

// A tiny capture with folds in every frame, so the refined reference surface is not the coarse.
std::string MakeCapture(const std::string& root, int num_frames) {
  const std::string dir = root + "/capture";
  SynthOptions synth = testing_util::TinyRefinableSynthOptions(num_frames);
  synth.cameras.width = synth.cameras.height = 160;
  synth.cameras.focal = 500.0;
  GenerateSyntheticCapture(synth, dir);
  return dir;
}

std::string MakeRunFolder(const std::string& path) {
  fs::create_directories(path);
  return path;
}

// How many vertices valid in both have colours further apart than `tolerance`.
int CountDiffering(const ReferenceColors& a, const ReferenceColors& b, float tolerance = 1e-6f) {
  int count = 0;
  for (size_t v = 0; v < a.colors.size(); ++v) {
    if (a.valid[v] && b.valid[v] && (a.colors[v] - b.colors[v]).norm() > tolerance) ++count;
  }
  return count;
}

int CountValid(const ReferenceColors& colors) {
  int count = 0;
  for (unsigned char valid : colors.valid) count += valid;
  return count;
}

ReferenceColors ColorsOf(Capture* capture, const SequenceOptions& options, const std::string& out) {
  const SequenceModel model(capture->ReadCoarseMesh(0), capture->vertex_mask(), options.refine,
                            capture->mesh_path(0));
  return LoadOrComputeReferenceColors(model, options, capture, ReferenceColorsPath(out));
}

TEST(SequenceColorsTest, ColoursAtTheRefinedSurfaceDifferFromTheCoarseOnes) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("colors_refined_surface");
  Capture capture = Capture::Open(MakeCapture(root, 1));
  SequenceOptions coarse = SurfaceColorOptions();
  coarse.colors.reference_surface = ReferenceSurface::kCoarse;
  SequenceOptions refined = coarse;
  refined.colors.reference_surface = ReferenceSurface::kRefined;

  const ReferenceColors at_coarse = ColorsOf(&capture, coarse, MakeRunFolder(root + "/coarse"));
  const ReferenceColors at_refined = ColorsOf(&capture, refined, MakeRunFolder(root + "/refined"));
  ASSERT_GT(CountValid(at_coarse), 100);
  // The folds move most of the surface: most colours come from other surface points.
  EXPECT_GT(CountDiffering(at_coarse, at_refined), CountValid(at_coarse) / 2);
  EXPECT_NE(at_refined.recipe.find("reference_surface=refined"), std::string::npos);
  EXPECT_EQ(at_coarse.recipe.find("reference_surface"), std::string::npos);

  // The consensus similarity uses no colours, so it does not refine the reference frame for them.
  SequenceOptions consensus = refined;
  consensus.refine.energy.similarity = SimilarityType::kConsensus;
  EXPECT_EQ(ReferenceColorRecipe(consensus).find("reference_surface"), std::string::npos);
}

TEST(SequenceColorsTest, ColoursOfTheOtherReferenceSurfaceAreRefused) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("colors_surface_recipe");
  Capture capture = Capture::Open(MakeCapture(root, 2));
  SequenceOptions coarse = SurfaceColorOptions();
  coarse.colors.reference_surface = ReferenceSurface::kCoarse;
  const std::string out = MakeRunFolder(root + "/run");
  RefineSequence(&capture, {0, 1}, coarse, out);
  SequenceOptions refined = coarse;
  refined.colors.reference_surface = ReferenceSurface::kRefined;
  ExpectErrorMentions(
      [&] {
        RefineSequence(&capture, {1, 2}, refined, out);
      },
      {"reference_colors.txt", "reference_surface=refined"});
  EXPECT_FALSE(FrameDone(FrameFilesIn(out, "000001", MeshFormat::kPly)));
}

ReferenceColors UniformColors(int n, const Eigen::Vector3f& color) {
  ReferenceColors colors;
  colors.colors.assign(n, color);
  colors.valid.assign(n, 1);
  return colors;
}

// A steady change of the images is followed to the share r (1 - a) / (r + a - r a) of it, never
// beyond: the reference stays the anchor. Without the anchor, it is followed entirely.
TEST(SequenceColorsTest, FollowedColoursTrackASteadyChangeAndStayAnchored) {
  const ReferenceColors reference = UniformColors(3, Eigen::Vector3f(0.2f, 0.3f, 0.5f));
  const Eigen::Vector3f change(0.1f, -0.05f, 0.0f);
  ReferenceColors frame = UniformColors(3, reference.colors[0] + change);
  frame.valid[2] = 0;  // Not seen in the frames: only pulled back.
  ReferenceColors unseen_reference = reference;
  ReferenceColorOptions options;
  options.follow_colors = 0.3;
  options.follow_anchor = 0.1;
  ReferenceColors followed = reference;
  followed.colors[2] += change;
  for (int t = 0; t < 200; ++t) {
    const ReferenceColors next = FollowColors(followed, frame, reference, options);
    // Each step moves towards the images, never past them.
    EXPECT_LE((next.colors[0] - reference.colors[0]).norm(), change.norm() + 1e-6f);
    followed = next;
  }
  const double r = options.follow_colors, a = options.follow_anchor;
  const double share = r * (1 - a) / (r + a - r * a);
  EXPECT_NEAR((followed.colors[0] - reference.colors[0]).norm() / change.norm(), share, 1e-4);
  EXPECT_NEAR((followed.colors[2] - reference.colors[2]).norm(), 0.0, 1e-6);

  options.follow_anchor = 0.0;
  followed = reference;
  for (int t = 0; t < 200; ++t) followed = FollowColors(followed, frame, reference, options);
  EXPECT_NEAR((followed.colors[0] - frame.colors[0]).norm(), 0.0, 1e-5);

  // A vertex without a reference colour has no Gaussian: it stays as it is.
  unseen_reference.valid[1] = 0;
  const ReferenceColors untouched = FollowColors(reference, frame, unseen_reference, options);
  EXPECT_EQ(untouched.colors[1], reference.colors[1]);
}

SequenceOptions FollowingOptions() {
  SequenceOptions options = SurfaceColorOptions();
  options.colors.follow_colors = 0.5;
  return options;
}

ReferenceColors FollowedAfter(const std::string& out, const std::string& frame) {
  return ReadReferenceColors(FollowedColorsPath(out, frame));
}

TEST(SequenceColorsTest, FollowedColoursChangeWithTheFrame) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("colors_follow");
  Capture capture = Capture::Open(MakeCapture(root, 3));
  const SequenceOptions options = FollowingOptions();
  const std::string out = MakeRunFolder(root + "/run");
  ASSERT_EQ(RefineSequence(&capture, {0, 3}, options, out).refined, 3);
  const ReferenceColors reference = ReadReferenceColors(ReferenceColorsPath(out));
  const ReferenceColors after0 = FollowedAfter(out, "000000");
  const ReferenceColors after1 = FollowedAfter(out, "000001");
  EXPECT_EQ(after1.recipe, FollowedColorRecipe(options));
  EXPECT_GT(CountDiffering(reference, after0), 0);
  EXPECT_GT(CountDiffering(after0, after1), 0);

  // Fixed colours on this folder would mix two kinds of frames.
  SequenceOptions fixed = options;
  fixed.colors.follow_colors = 0.0;
  ExpectErrorMentions(
      [&] {
        RefineSequence(&capture, {0, 3}, fixed, out);
      },
      {"colors", "follow_colors"});
}

// A run killed after frame 1 and resumed writes frame 2 byte for byte as a run that never stopped;
// another rate, or a frame whose predecessor is missing (a shard), is refused.
TEST(SequenceColorsTest, AResumedRunFollowsTheColoursAsAnUninterruptedOne) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("colors_resume");
  Capture capture = Capture::Open(MakeCapture(root, 3));
  const SequenceOptions options = FollowingOptions();
  const std::string whole = MakeRunFolder(root + "/whole");
  const std::string resumed = MakeRunFolder(root + "/resumed");
  RefineSequence(&capture, {0, 3}, options, whole);
  RefineSequence(&capture, {0, 2}, options, resumed);
  SequenceOptions faster = options;
  faster.colors.follow_colors = 0.9;
  ExpectErrorMentions(
      [&] {
        RefineSequence(&capture, {0, 3}, faster, resumed);
      },
      {"000001.txt", "follow_colors=0.5", "follow_colors=0.9"});
  EXPECT_EQ(RefineSequence(&capture, {0, 3}, options, resumed).refined, 1);
  const FrameFiles a = FrameFilesIn(whole, "000002", MeshFormat::kPly);
  const FrameFiles b = FrameFilesIn(resumed, "000002", MeshFormat::kPly);
  EXPECT_EQ(FileBytes(a.displacement), FileBytes(b.displacement));
  EXPECT_EQ(FileBytes(FollowedColorsPath(whole, "000002")),
            FileBytes(FollowedColorsPath(resumed, "000002")));

  const std::string shard = MakeRunFolder(root + "/shard");
  ExpectErrorMentions(
      [&] {
        RefineSequence(&capture, {2, 3}, options, shard);
      },
      {"follow_colors", "000001", "sequential"});
  EXPECT_FALSE(FrameDone(FrameFilesIn(shard, "000002", MeshFormat::kPly)));
}

TEST(SequenceColorsTest, ConfigKeysAreCheckedAndFollowingRefusesShards) {
  const Config config = LoadConfig("", {{"model.reference_surface", "coarse", "--set"},
                                        {"model.follow_colors", "0.25", "--set"},
                                        {"model.follow_anchor", "0.05", "--set"}});
  EXPECT_EQ(config.colors.reference_surface, ReferenceSurface::kCoarse);
  EXPECT_EQ(config.colors.follow_colors, 0.25);
  EXPECT_EQ(config.colors.follow_anchor, 0.05);
  EXPECT_EQ(Config().colors.reference_surface, ReferenceSurface::kRefined);
  EXPECT_EQ(Config().colors.follow_colors, 0.0);
  // Out of range or not a choice: one error naming the key and the value.
  const std::vector<std::pair<std::string, std::string>> wrong = {
      {"model.follow_colors", "1.5"},
      {"model.follow_anchor", "-0.1"},
      {"model.reference_surface", "fine"}};
  for (const auto& [key, value] : wrong) {
    ExpectErrorMentions([&] { LoadConfig("", {{key, value, "--set"}}); }, {key, value});
  }
  ExpectErrorMentions(
      [] {
        LoadConfig("",
                   {{"model.follow_colors", "0.3", "--set"}, {"runtime.shard", "1/2", "--set"}});
      },
      {"model.follow_colors", "runtime.shard", "1/2"});
  EXPECT_NO_THROW(LoadConfig("", {{"runtime.shard", "1/2", "--set"}}));
}

}  // namespace
}  // namespace finecap
