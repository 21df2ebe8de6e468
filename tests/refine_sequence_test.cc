// A sequence refined frame after frame (sequence.h): how one frame's result seeds the next (warm
// start) when bias compensation and kept inputs are involved, the reference colours' recipe, what
// the observer hears.
#include "finecap/refine/sequence.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>
#include <utility>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/geometry/subdivision.h"
#include "finecap/io/mesh_io.h"
#include "finecap/refine/frame_stats.h"
#include "finecap/refine/refine.h"
#include "finecap/refine/run_folder.h"
#include "finecap/synth/synth.h"
#include "finecap/util/atomic_file.h"
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

FrameStats Record(const std::string& out, const std::string& frame) {
  return ReadFrameStats(FrameFilesIn(out, frame, MeshFormat::kPly).stats);
}

// A frame whose input was kept has, as solved, displacement 0: the frame after it starts there,
// as a frame without a predecessor does, and not at -sigma_hat (its saved 0 with the bias
// compensation taken off as if it had been added).
TEST(RefineSequenceTest, TheFrameAfterAKeptInputStartsWhereAFirstFrameStarts) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("sequence_after_kept");
  const std::string capture = root + "/capture";
  // No folds: the input is the true surface, so the 4 cm the bias compensation of wide Gaussians
  // adds without an iteration makes frame 0 worse in the held-out camera, and its input is kept.
  SynthOptions options = testing_util::TinyRefinableSynthOptions(2);
  options.cameras.count = 6;
  options.folds.clear();
  GenerateSyntheticCapture(options, capture);
  Config config = testing_util::TinyRunConfig(capture, root + "/sequence", 0);
  config.eval.flow = "none";
  config.validation.cameras = {"cam05"};
  config.refine.sigma_hat = 0.04;
  config.refine.scene_lengths.sigma_hat = false;
  config.refine.bias_compensation = true;
  config.refine.keep_input_if_worse = true;
  config.refine.warm_start = true;
  config.refine.sweep.samples = 0;  // A frame without a predecessor starts at zero.
  ASSERT_EQ(RunRefine(config), 0);
  ASSERT_TRUE(Record(config.output.dir, "000000").kept_input);

  Config alone = config;
  alone.output.dir = root + "/alone";
  alone.capture.frames = "1:2";
  ASSERT_EQ(RunRefine(alone), 0);
  const FrameStats after_kept = Record(config.output.dir, "000001");
  const FrameStats first = Record(alone.output.dir, "000001");
  ASSERT_TRUE(std::isfinite(first.energy_start));
  EXPECT_EQ(after_kept.energy_start, first.energy_start);
  EXPECT_EQ(after_kept.kept_input, first.kept_input);
}

// What refine writes depends on the training views alone: a held-out view is scored, never solved
// against, so with refine.keep_input_if_worse off (with it on, the score decides by design) its
// pixels may change without changing a byte of the meshes or displacements written.
TEST(RefineSequenceTest, HeldOutImagesDoNotChangeWhatIsWritten) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("sequence_heldout_blind");
  const std::string capture = root + "/capture";
  GenerateSyntheticCapture(testing_util::TinyRefinableSynthOptions(2), capture);
  Config config = testing_util::TinyRunConfig(capture, root + "/seen", 5);
  config.eval.flow = "none";
  config.validation.cameras = {"cam05"};
  ASSERT_FALSE(config.refine.keep_input_if_worse);  // The default.
  ASSERT_EQ(RunRefine(config), 0);

  // The held-out camera's images replaced by their negatives.
  for (const auto& entry : fs::directory_iterator(capture + "/images/cam05")) {
    const cv::Mat image = cv::imread(entry.path().string());
    ASSERT_FALSE(image.empty()) << entry.path();
    cv::imwrite(entry.path().string(), cv::Scalar::all(255) - image);
  }
  Config negative = config;
  negative.output.dir = root + "/negative";
  ASSERT_EQ(RunRefine(negative), 0);

  for (const std::string frame : {"000000", "000001"}) {
    const FrameFiles seen = FrameFilesIn(config.output.dir, frame, MeshFormat::kPly);
    const FrameFiles blind = FrameFilesIn(negative.output.dir, frame, MeshFormat::kPly);
    EXPECT_EQ(FileBytes(seen.mesh), FileBytes(blind.mesh)) << frame;
    EXPECT_EQ(FileBytes(seen.displacement), FileBytes(blind.displacement)) << frame;
    // The negatives were read: they score differently.
    const double seen_score = Record(config.output.dir, frame).heldout_ncc_refined;
    const double blind_score = Record(negative.output.dir, frame).heldout_ncc_refined;
    ASSERT_TRUE(std::isfinite(seen_score) && std::isfinite(blind_score)) << frame;
    EXPECT_NE(seen_score, blind_score) << frame;
  }
}

// Counts what RefineSequence reports.
class CountingObserver : public SequenceObserver {
 public:
  void Starting(int num_frames, const FrameInput& first, const ProblemSize& size) override {
    started_frames = num_frames;
    first_cameras = static_cast<int>(first.cameras.size());
    surface_gaussians = size.num_surface_gaussians;
  }
  void FrameAlreadyDone(const std::string&) override { ++already_done; }
  void FrameRefined(const FrameStats& stats) override { refined.push_back(stats.frame); }

  int started_frames = 0, first_cameras = 0, already_done = 0;
  long surface_gaussians = 0;
  std::vector<std::string> refined;
};

TEST(RefineSequenceTest, RefinesTheFramesLeftAndReportsThem) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("sequence_library");
  const SynthOptions synth = testing_util::TinyRefinableSynthOptions(2);
  GenerateSyntheticCapture(synth, root + "/capture");
  Capture capture = Capture::Open(root + "/capture");
  SequenceOptions options = testing_util::QuickSequenceOptions();
  options.held_out_cameras = {"cam02"};
  const std::string out = root + "/run";
  fs::create_directories(out);

  CountingObserver first_run;
  const SequenceResult first = RefineSequence(&capture, {0, 1}, options, out, &first_run);
  EXPECT_EQ(first.refined, 1);
  EXPECT_EQ(first_run.started_frames, 1);
  // The held-out camera is not refinement's.
  EXPECT_EQ(first_run.first_cameras, synth.cameras.count - 1);
  EXPECT_GT(first_run.surface_gaussians, 0);
  EXPECT_EQ(first_run.refined, std::vector<std::string>{"000000"});
  EXPECT_TRUE(FrameDone(FrameFilesIn(out, "000000", MeshFormat::kPly)));
  EXPECT_FALSE(FrameDone(FrameFilesIn(out, "000001", MeshFormat::kPly)));
  // The frame's CPU: some, and no more than its time on every core of the machine.
  const FrameStats record = Record(out, "000000");
  EXPECT_GT(record.cpu_seconds, 0.0);
  EXPECT_LE(record.cpu_seconds, record.seconds * std::max(1u, std::thread::hardware_concurrency()));

  CountingObserver second_run;
  const SequenceResult second = RefineSequence(&capture, {0, 2}, options, out, &second_run);
  EXPECT_EQ(second.already_done, 1);
  EXPECT_EQ(second.refined, 1);
  EXPECT_EQ(second_run.refined, std::vector<std::string>{"000001"});
  EXPECT_TRUE(FrameDone(FrameFilesIn(out, "000001", MeshFormat::kPly)));
  EXPECT_EQ(second.measured, 1);  // The synthetic capture has ground truth.
  EXPECT_TRUE(std::isfinite(second.rms_refined_mm));

  options.refine.sigma_hat = -1.0;
  ExpectErrorMentions([&] { RefineSequence(&capture, {0, 2}, options, out); }, {"sigma_hat"});
}

// Each frame's flicker is measured against the frame before it: none for the first frame, and
// the same whether the frame before was refined by the same call or read back from the run
// folder (a resumed run, the next shard).
TEST(RefineSequenceTest, FlickerFollowsTheFrameBeforeAcrossResumesAndShards) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("sequence_flicker");
  Capture capture = testing_util::OpenTinyCapture(root, 3);
  const SequenceOptions options = testing_util::QuickSequenceOptions();
  const std::string whole = root + "/whole", parts = root + "/parts";
  const SequenceResult result = RefineSequence(&capture, {0, 3}, options, whole);
  EXPECT_TRUE(std::isnan(Record(whole, "000000").flicker_refined_mm));
  EXPECT_TRUE(std::isnan(Record(whole, "000000").flicker_subdivided_mm));
  double sum2 = 0.0;
  for (const std::string frame : {"000001", "000002"}) {
    const FrameStats record = Record(whole, frame);
    EXPECT_GT(record.flicker_refined_mm, 0.0) << frame;
    EXPECT_GT(record.flicker_subdivided_mm, 0.0) << frame;  // The folds drift.
    EXPECT_GT(record.flicker_coarse_mm, 0.0) << frame;
    sum2 += record.flicker_refined_mm * record.flicker_refined_mm;
  }
  EXPECT_EQ(result.flickered, 2);
  EXPECT_NEAR(result.flicker_refined_mm, std::sqrt(sum2 / 2), 1e-6);

  // Frame 0, then frame 1 resumed, then frame 2 as a shard of its own.
  for (const FrameRange part : {FrameRange{0, 1}, FrameRange{0, 2}, FrameRange{2, 3}}) {
    RefineSequence(&capture, part, options, parts);
  }
  for (const std::string frame : {"000001", "000002"}) {
    const FrameStats expected = Record(whole, frame), actual = Record(parts, frame);
    EXPECT_NEAR(actual.flicker_refined_mm, expected.flicker_refined_mm, 1e-9) << frame;
    EXPECT_NEAR(actual.flicker_subdivided_mm, expected.flicker_subdivided_mm, 1e-9) << frame;
    EXPECT_NEAR(actual.flicker_coarse_mm, expected.flicker_coarse_mm, 1e-9) << frame;
  }
}

// energy.consensus.shared_appearance: each frame saves the colours its refined surface showed at
// its samples, and the frame after compares its patches with them too, read from that file, so
// that frame 1 resumed and frame 2 refined by a run of its own give what one run gives. The first
// frame has no frame before and is refined as without the option.
TEST(RefineSequenceTest, TheSharedAppearanceComesFromTheFrameBeforesFile) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("sequence_appearance");
  Capture capture = testing_util::OpenTinyCapture(root, 3);
  const int num_vertices = SequenceModel(capture.ReadCoarseMesh(0), {},
                                         testing_util::QuickSequenceOptions().refine, "test")
                               .num_fine_vertices();
  SequenceOptions shared_options = testing_util::QuickSequenceOptions();
  shared_options.refine.energy.consensus.shared_appearance = true;
  const std::string plain = root + "/plain", shared = root + "/shared", parts = root + "/parts";
  RefineSequence(&capture, {0, 3}, testing_util::QuickSequenceOptions(), plain);
  RefineSequence(&capture, {0, 3}, shared_options, shared);
  EXPECT_FALSE(fs::exists(AppearanceFolder(plain)));
  for (const std::string frame : {"000000", "000001", "000002"}) {
    const Eigen::Matrix3Xd appearance = ReadAppearance(AppearancePath(shared, frame));
    EXPECT_GT(appearance.cols(), 4 * num_vertices) << frame;  // Finer than the vertices.
    EXPECT_GT(appearance.array().isFinite().count(), appearance.size() / 2) << frame;
  }
  EXPECT_EQ(FileBytes(FrameFilesIn(shared, "000000", MeshFormat::kPly).displacement),
            FileBytes(FrameFilesIn(plain, "000000", MeshFormat::kPly).displacement));
  EXPECT_NE(FileBytes(FrameFilesIn(shared, "000001", MeshFormat::kPly).displacement),
            FileBytes(FrameFilesIn(plain, "000001", MeshFormat::kPly).displacement));

  testing_util::RefineInParts(&capture, shared_options, parts);
  for (const std::string frame : {"000001", "000002"}) {
    EXPECT_EQ(FileBytes(AppearancePath(parts, frame)), FileBytes(AppearancePath(shared, frame)))
        << frame;
    EXPECT_LT(testing_util::LargestDisplacementDifference(shared, parts, frame, num_vertices), 1e-9)
        << frame;
  }
}

// appearance/<frame>.txt reads back to the very doubles written, nan included; a line that is not
// three numbers is refused, naming the file.
TEST(RefineSequenceTest, AppearanceFilesReadBackExactly) {
  const std::string root = MakeTempDir("appearance_file");
  Eigen::Matrix3Xd appearance(3, 3);
  appearance << 0.1, 1.0 / 3.0, std::nan(""), -2.5e-7, 0.7, std::nan(""), 1.0, 2.0 / 7.0,
      std::nan("");
  const std::string path = root + "/a.txt";
  WriteAppearance(path, appearance);
  const Eigen::Matrix3Xd read = ReadAppearance(path);
  ASSERT_EQ(read.cols(), 3);
  for (int j = 0; j < 3; ++j) {
    for (int channel = 0; channel < 3; ++channel) {
      if (std::isnan(appearance(channel, j))) {
        EXPECT_TRUE(std::isnan(read(channel, j)));
      } else {
        EXPECT_EQ(read(channel, j), appearance(channel, j));
      }
    }
  }
  WriteTextFileAtomically(path, "# colours\n0.1 0.2 0.3\n0.4 0.5\n");
  ExpectErrorMentions([&] { ReadAppearance(path); }, {path, "line 3"});
  WriteTextFileAtomically(path, "0.1 0.2 0.3 0.4\n");
  ExpectErrorMentions([&] { ReadAppearance(path); }, {path, "line 1"});
}

// The reference colours are saved with what they were made of; a run that would make them
// otherwise (here: another quad-tree depth, which the file's own fields do not show) is refused,
// while a file saved before recipes were still resumes.
TEST(RefineSequenceTest, ReferenceColoursOfAnotherRecipeAreRefused) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("sequence_recipe");
  Capture capture = testing_util::OpenTinyCapture(root, 2);
  const SequenceOptions options = testing_util::QuickSequenceOptions();
  const std::string out = root + "/run";
  fs::create_directories(out);
  RefineSequence(&capture, {0, 1}, options, out);
  const std::string colors = FileBytes(ReferenceColorsPath(out));
  EXPECT_NE(colors.find("recipe " + ReferenceColorRecipe(options) + "\n"), std::string::npos);

  SequenceOptions deeper = options;
  deeper.refine.image.max_depth = options.refine.image.max_depth - 1;
  EXPECT_NE(ReferenceColorRecipe(deeper), ReferenceColorRecipe(options));
  ExpectErrorMentions(
      [&] {
        RefineSequence(&capture, {1, 2}, deeper, out);
      },
      {"reference_colors.txt", "max_depth=8", "max_depth=7"});
  EXPECT_FALSE(FrameDone(FrameFilesIn(out, "000001", MeshFormat::kPly)));
  SequenceOptions held_out = options;
  held_out.held_out_cameras = {"cam01"};
  ExpectErrorMentions(
      [&] {
        RefineSequence(&capture, {1, 2}, held_out, out);
      },
      {"reference_colors.txt", "held_out="});

  // A file of an older version, without its recipe: checked on what it holds, and reused.
  const size_t recipe = colors.find("recipe ");
  WriteTextFileAtomically(ReferenceColorsPath(out),
                          colors.substr(0, recipe) + colors.substr(colors.find('\n', recipe) + 1));
  EXPECT_EQ(RefineSequence(&capture, {1, 2}, deeper, out).refined, 1);
  SequenceOptions wider = options;
  wider.refine.sigma_hat = 2.0 * options.refine.sigma_hat;
  ExpectErrorMentions(
      [&] {
        RefineSequence(&capture, {0, 2}, wider, out);
      },
      {"reference_colors.txt", "sigma_hat"});
}

// The refined mesh (meshes/<frame>.ply) is the subdivided input moved along its normals; with the
// butterfly scheme and nothing solved it is the subdivided input itself, whose first vertices are
// the input's own, bit for bit, where Loop's scheme moves them.
TEST(RefineSequenceTest, ButterflyWithoutIterationsWritesTheInputVerticesUnmoved) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("sequence_butterfly");
  const std::string capture = root + "/capture";
  GenerateSyntheticCapture(testing_util::TinyRefinableSynthOptions(1), capture);
  const Mesh coarse = Capture::Open(capture).ReadCoarseMesh(0);
  const int num_coarse = coarse.num_vertices();
  auto refine = [&](SubdivisionScheme scheme) {
    Config config = testing_util::TinyRunConfig(capture, root + "/" + EnumToString(scheme), 0);
    config.eval.flow = "none";
    config.refine.subdivision = scheme;
    config.refine.sweep.samples = 0;
    EXPECT_EQ(RunRefine(config), 0);
    return ReadMesh(FrameFilesIn(config.output.dir, "000000", MeshFormat::kPly).mesh);
  };

  const Mesh butterfly = refine(SubdivisionScheme::kButterfly);
  const SubdivisionStencil stencil = BuildButterflySubdivision(coarse, 1);
  ASSERT_EQ(butterfly.num_vertices(), stencil.num_fine_vertices());
  EXPECT_EQ(butterfly.faces, stencil.faces);
  EXPECT_TRUE((butterfly.vertices.leftCols(num_coarse).array() == coarse.vertices.array()).all());
  const Mesh subdivided = ApplySubdivision(stencil, coarse.vertices);
  EXPECT_LT((butterfly.vertices - subdivided.vertices).cwiseAbs().maxCoeff(), 1e-12);

  const Mesh loop = refine(SubdivisionScheme::kLoop);
  ASSERT_EQ(loop.num_vertices(), butterfly.num_vertices());
  EXPECT_GT((loop.vertices.leftCols(num_coarse) - coarse.vertices).cwiseAbs().maxCoeff(), 1e-4);

  // The reference colours of one scheme do not serve the other.
  SequenceOptions options;
  const std::string loop_recipe = ReferenceColorRecipe(options);
  options.refine.subdivision = SubdivisionScheme::kButterfly;
  EXPECT_EQ(loop_recipe.find("subdivision="), std::string::npos);
  EXPECT_NE(ReferenceColorRecipe(options).find(" subdivision=butterfly"), std::string::npos);
}

// Ceres leaves the frame ahead one of the threads it was given, keeps at least one, and the rest
// of the options as they were.
TEST(RefineSequenceTest, CeresBesideTheFrameAheadTakesOneThreadFewer) {
  SolverOptions configured;
  configured.max_iterations = 7;
  configured.num_threads = 4;
  const SolverOptions beside = SolverOptionsBesideWorkAhead(configured);
  EXPECT_EQ(beside.num_threads, 3);
  EXPECT_EQ(beside.max_iterations, 7);
  configured.num_threads = 1;
  EXPECT_EQ(SolverOptionsBesideWorkAhead(configured).num_threads, 1);
  configured.num_threads = 0;  // All cores.
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  EXPECT_EQ(SolverOptionsBesideWorkAhead(configured).num_threads, std::max(1, cores - 1));
}

}  // namespace
}  // namespace finecap
