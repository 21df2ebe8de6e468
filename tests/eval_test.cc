// finecap eval: the figures of the evaluation against independent computations, and the whole
// command on a tiny refined synthetic run (metrics.json, pictures, report), plus its bad input.
#include "eval/mesh_viewer.h"
#include "finecap/eval/evaluation.h"
#include "finecap/io/export.h"
#include "finecap/io/mesh_io.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>

#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/refine/run_folder.h"
#include "finecap/refine/sequence.h"
#include "finecap/synth/synth.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectErrorMentions;
using testing_util::FileBytes;
using testing_util::MakeTempDir;

// A flat 3 x 3 grid of vertices in the plane z = 0, normals along +z.
Mesh FlatGrid() {
  Mesh mesh;
  mesh.vertices.resize(3, 9);
  for (int v = 0; v < 9; ++v) mesh.vertices.col(v) << v % 3, v / 3, 0.0;
  mesh.faces.resize(3, 8);
  int f = 0;
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 2; ++col) {
      const int a = 3 * row + col;
      mesh.faces.col(f++) << a, a + 1, a + 4;
      mesh.faces.col(f++) << a, a + 4, a + 3;
    }
  }
  return mesh;
}

TEST(EvaluationTest, FiguresMatchAHandComputation) {
  const Mesh input = FlatGrid();
  Eigen::VectorXd k_true = Eigen::VectorXd::Zero(9);
  k_true[4] = 0.5;  // The centre vertex bulges: its four neighbours tilt.
  Eigen::VectorXd k = 0.5 * k_true;
  k[0] = std::nan("");  // Not refined: left out of both the input's and the refinement's error.
  Mesh refined = input;
  refined.vertices(2, 4) = k[4];
  const std::vector<int> region = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  // The coarse mesh as given lies twice as far from the truth as its subdivision.
  const Eigen::VectorXd coarse_error = 2.0 * k_true;
  const EvaluationSamples samples =
      MakeEvaluationSamples(input, input, refined, k, k_true, coarse_error, region, {4}, "grid");
  EXPECT_EQ(samples.textureless, std::vector<int>{4});
  EXPECT_EQ(samples.textured.size(), 8u);

  const EvaluationFigures figures = ComputeEvaluationFigures(samples);
  EXPECT_EQ(figures.all.coarse.count, 8);
  EXPECT_EQ(figures.all.subdivided.count, 8);
  EXPECT_NEAR(figures.all.coarse.rms, std::sqrt(1.0 / 8), 1e-12);
  EXPECT_NEAR(figures.all.subdivided.rms, std::sqrt(0.25 / 8), 1e-12);
  EXPECT_NEAR(figures.all.refined.rms, std::sqrt(0.0625 / 8), 1e-12);
  // Against the input as given, not its subdivision (which would give 0.5).
  EXPECT_NEAR(figures.all.detail_recovered, 0.75, 1e-12);
  EXPECT_NEAR(figures.textureless.refined.rms, 0.25, 1e-12);
  EXPECT_NEAR(figures.textured.refined.rms, 0.0, 1e-12);
  // The input is flat, so its normal error is the true normals' mean tilt from +z; the refined
  // bulge is half as high, so it tilts less and errs less.
  double tilt = 0.0;
  for (int v = 1; v < 9; ++v) {
    tilt += std::acos(std::min(1.0, samples.normals_true.col(v).normalized().z())) * 180.0 / M_PI;
  }
  EXPECT_NEAR(figures.all.normal_error_coarse_deg, tilt / 8, 1e-9);
  EXPECT_NEAR(figures.all.normal_error_subdivided_deg, tilt / 8, 1e-9);
  EXPECT_GT(figures.all.normal_error_refined_deg, 0.0);
  EXPECT_LT(figures.all.normal_error_refined_deg, figures.all.normal_error_coarse_deg);
}

TEST(EvaluationTest, PooledSamplesGiveTheFiguresOfBothFrames) {
  const Mesh input = FlatGrid();
  const Eigen::VectorXd k = Eigen::VectorXd::Zero(9);
  const std::vector<int> region = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  EvaluationSamples pooled;
  const Eigen::VectorXd first = Eigen::VectorXd::Constant(9, 0.1);
  const Eigen::VectorXd second = Eigen::VectorXd::Constant(9, 0.3);
  pooled.Append(MakeEvaluationSamples(input, input, input, k, first, first, region, {}, "first"));
  pooled.Append(
      MakeEvaluationSamples(input, input, input, k, second, 2.0 * second, region, {}, "second"));
  EXPECT_EQ(pooled.all.size(), 18u);
  EXPECT_EQ(pooled.all.back(), 17);
  const EvaluationFigures figures = ComputeEvaluationFigures(pooled);
  EXPECT_NEAR(figures.all.refined.rms, std::sqrt((0.01 + 0.09) / 2), 1e-12);
  EXPECT_NEAR(figures.all.subdivided.rms, std::sqrt((0.01 + 0.09) / 2), 1e-12);
  EXPECT_NEAR(figures.all.coarse.rms, std::sqrt((0.01 + 0.36) / 2), 1e-12);
}

TEST(EvaluationTest, RefusesMismatchedInputs) {
  const Mesh input = FlatGrid();
  const Eigen::VectorXd nine = Eigen::VectorXd::Zero(9);
  ExpectErrorMentions(
      [&] {
        MakeEvaluationSamples(input, input, input, Eigen::VectorXd::Zero(8), nine, nine, {}, {},
                              "frame_7.ply");
      },
      {"frame_7.ply", "expected 9 displacements"});
  ExpectErrorMentions(
      [&] {
        MakeEvaluationSamples(input, input, input, nine, nine, Eigen::VectorXd::Zero(8), {}, {},
                              "frame_7.ply");
      },
      {"frame_7.ply", "8 of the coarse mesh"});
  ExpectErrorMentions(
      [&] { MakeEvaluationSamples(input, input, input, nine, nine, nine, {9}, {}, "frame_7.ply"); },
      {"frame_7.ply", "vertex id 9"});
}

TEST(EvaluationTest, HeatMapRunsFromBlueToRedAndGreysUnknowns) {
  const Eigen::Matrix3Xd colors = HeatMapColors(Eigen::Vector3d(0.0, 2.0, std::nan("")), 1.0);
  EXPECT_GT(colors(2, 0), colors(0, 0));  // Zero error: blue dominates.
  EXPECT_GT(colors(0, 1), colors(2, 1));  // Saturated: red dominates.
  EXPECT_EQ(colors.col(2), Eigen::Vector3d::Constant(0.5));
  EXPECT_THROW(HeatMapColors(Eigen::VectorXd::Zero(1), 0.0), Error);
}

// 3 cameras of 96 x 96 that see the skirt large, a 16 x 8 skirt, 3 frames.
SynthOptions TinyCapture() { return testing_util::TinyRefinableSynthOptions(3); }

Config RunConfig(const std::string& capture, const std::string& out) {
  Config config;
  config.capture.dir = capture;
  config.output.dir = out;
  config.runtime.threads = 1;
  config.refine.solver.max_iterations = 5;
  config.refine.solver.num_threads = 1;
  return config;
}

// True when `path` is a PNG of `width` x `height` pixels.
bool IsPngOfSize(const std::string& path, int width, int height) {
  const std::string bytes = FileBytes(path);
  if (bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return false;
  const cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  return image.cols == width && image.rows == height;
}

TEST(EvalCommandTest, WritesMetricsPicturesPlotsAndReport) {
  const std::string root = MakeTempDir("eval");
  const std::string capture = root + "/capture";
  const std::string out = root + "/run";
  GenerateSyntheticCapture(TinyCapture(), capture);
  const Config config = RunConfig(capture, out);
  ASSERT_EQ(RunRefine(config), 0);
  const auto refined_files = testing_util::FilesIn(out + "/meshes");
  ASSERT_EQ(RunEval(config), 0);

  const YAML::Node metrics = YAML::LoadFile(out + "/eval/metrics.json");  // JSON is YAML.
  const double rms_coarse = metrics["rms_coarse_mm"].as<double>();
  EXPECT_TRUE(std::isfinite(rms_coarse));
  EXPECT_GT(rms_coarse, 0.0);
  EXPECT_TRUE(std::isfinite(metrics["rms_refined_mm"].as<double>()));
  EXPECT_TRUE(std::isfinite(metrics["normal_error_coarse_deg"].as<double>()));
  // Optical flow needs no ground truth: finite figures, and the improvement from them.
  const double flow_coarse = metrics["flow_coarse_px"].as<double>();
  const double flow_refined = metrics["flow_refined_px"].as<double>();
  EXPECT_TRUE(std::isfinite(flow_coarse));
  EXPECT_GE(flow_coarse, 0.0);
  EXPECT_TRUE(std::isfinite(flow_refined));
  EXPECT_NEAR(metrics["flow_improvement_percent"].as<double>(),
              100.0 * (flow_coarse - flow_refined) / flow_coarse, 1e-6);
  EXPECT_TRUE(std::isfinite(metrics["frames"][0]["flow_refined_px"].as<double>()));
  // Frame 0, the reference frame, is refined: the refined mesh has its own texture.
  EXPECT_EQ(metrics["flow_refined_texture"].as<std::string>(), "refined_reference_mesh");
  EXPECT_EQ(metrics["frames"].size(), 3u);
  EXPECT_DOUBLE_EQ(metrics["sequence"]["all"]["rms_coarse_mm"].as<double>(), rms_coarse);
  // The subdivided input beside the input as given, and detail recovered against the latter.
  const double rms_subdivided = metrics["rms_subdivided_mm"].as<double>();
  EXPECT_TRUE(std::isfinite(rms_subdivided));
  EXPECT_NE(rms_subdivided, rms_coarse);
  EXPECT_NEAR(metrics["detail_recovered"].as<double>(),
              1.0 - metrics["rms_refined_mm"].as<double>() / rms_coarse, 1e-9);
  EXPECT_TRUE(std::isfinite(metrics["normal_error_subdivided_deg"].as<double>()));

  // Refine measures the textured region of each frame the same way, independently of eval.
  for (int i = 0; i < 3; ++i) {
    const YAML::Node figures = metrics["frames"][i]["figures"]["textured"];
    const std::string name = metrics["frames"][i]["frame"].as<std::string>();
    const YAML::Node stats = YAML::LoadFile(out + "/frames/" + name + ".json");
    EXPECT_NEAR(figures["rms_coarse_mm"].as<double>(), stats["rms_coarse_mm"].as<double>(), 1e-6);
    EXPECT_NEAR(figures["rms_subdivided_mm"].as<double>(), stats["rms_subdivided_mm"].as<double>(),
                1e-6);
    EXPECT_NEAR(figures["rms_refined_mm"].as<double>(), stats["rms_refined_mm"].as<double>(), 1e-6);
    // And the flicker since the frame before, which the first frame lacks.
    for (const char* flicker :
         {"flicker_coarse_mm", "flicker_subdivided_mm", "flicker_refined_mm"}) {
      if (i == 0) {
        EXPECT_TRUE(figures[flicker].IsNull()) << flicker;
        EXPECT_TRUE(stats[flicker].IsNull()) << flicker;
        continue;
      }
      EXPECT_GT(figures[flicker].as<double>(), 0.0) << flicker;
      EXPECT_NEAR(figures[flicker].as<double>(), stats[flicker].as<double>(), 1e-6) << flicker;
    }
  }
  EXPECT_TRUE(std::isfinite(metrics["flicker_refined_mm"].as<double>()));
  for (const std::string frame : {"000000", "000001", "000002"}) {
    // Every picture is cut to the same box around the subject, inside the 96 x 96 view.
    const cv::Mat error = cv::imread(out + "/eval/error_" + frame + ".png");
    ASSERT_FALSE(error.empty()) << frame;
    EXPECT_LE(error.cols, 96);
    EXPECT_LE(error.rows, 96);
    EXPECT_GT(error.cols, 16);
    EXPECT_TRUE(IsPngOfSize(out + "/eval/frame_" + frame + ".png", 3 * error.cols, error.rows));
    EXPECT_TRUE(IsPngOfSize(out + "/eval/flow_" + frame + ".png", 2 * error.cols, error.rows));
  }
  EXPECT_TRUE(IsPngOfSize(out + "/eval/rms.png", 800, 500));
  EXPECT_TRUE(IsPngOfSize(out + "/eval/normal_error.png", 800, 500));
  EXPECT_TRUE(IsPngOfSize(out + "/eval/flicker.png", 800, 500));
  EXPECT_TRUE(IsPngOfSize(out + "/eval/flow.png", 800, 500));
  const std::string csv = FileBytes(out + "/eval/flow.csv");
  EXPECT_EQ(csv.rfind("frame,flow_coarse_px,flow_refined_px,flow_improvement_percent\n000000,", 0),
            0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);
  const std::string report = FileBytes(out + "/eval/report.html");
  EXPECT_NE(report.find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(report.find("detail recovered"), std::string::npos);
  EXPECT_NE(report.find("RMS subdivided mm"), std::string::npos);
  EXPECT_NE(report.find("flow refined px"), std::string::npos);
  // The 3D view where three.js is installed, a note in its place otherwise.
  if (FindThreeJs()) {
    EXPECT_NE(report.find("id=\"finecap-viewer\""), std::string::npos);
    EXPECT_NE(report.find("\"name\": \"000002\""), std::string::npos);  // The last frame.
  } else {
    EXPECT_NE(report.find("three.js was not found"), std::string::npos);
  }
  EXPECT_EQ(testing_util::FilesIn(out + "/meshes"), refined_files);  // Nothing else touched.

  // eval.flow: none leaves the flow figures out.
  Config without_flow = config;
  without_flow.eval.flow = "none";
  ASSERT_EQ(RunEval(without_flow), 0);
  const YAML::Node unmeasured = YAML::LoadFile(out + "/eval/metrics.json");
  EXPECT_TRUE(unmeasured["flow_coarse_px"].IsNull());
  EXPECT_TRUE(unmeasured["flow_improvement_percent"].IsNull());
  EXPECT_TRUE(unmeasured["flow_refined_texture"].IsNull());
  EXPECT_TRUE(unmeasured["frames"][1]["flow_refined_px"].IsNull());

  // The same run exported: one PC2 sample per frame holding the refined vertices.
  ASSERT_EQ(RunExport(config), 0);
  const Pc2Cache cache = ReadPc2(out + "/export/sequence.pc2");
  const Mesh last = ReadMesh(out + "/meshes/000002.ply");
  ASSERT_EQ(cache.header.num_samples, 3);
  ASSERT_EQ(cache.header.num_points, last.num_vertices());
  EXPECT_LT((cache.samples.back().cast<double>() - last.vertices).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(testing_util::FilesIn(out + "/export/ply").size(), 3u);
}

// Writes the truth of every frame of `capture_dir` into the run folder `out` as if refinement had
// found it: the subdivided input mesh moved along its normals by the true displacement.
void WriteTruthAsRun(const std::string& capture_dir, const Config& config, const std::string& out) {
  const Capture capture = Capture::Open(capture_dir);
  const SequenceModel model(capture.ReadCoarseMesh(0), capture.vertex_mask(), config.refine,
                            capture_dir);
  PrepareRunSubfolders(out, false);
  for (int frame = 0; frame < capture.num_frames(); ++frame) {
    const Mesh coarse = capture.ReadCoarseMesh(frame);
    Mesh truth = model.Subdivide(coarse);
    Eigen::VectorXd k = TrueFineGroundTruth(capture, model, coarse, frame).k_true;
    ASSERT_EQ(k.size(), truth.num_vertices());
    k = k.array().isFinite().select(k, 0.0);
    const Eigen::Matrix3Xd normals = ComputeVertexNormals(truth);
    truth.vertices += normals * k.asDiagonal();
    const FrameFiles files = FrameFilesIn(out, capture.frame_name(frame), MeshFormat::kPly);
    WriteMesh(files.mesh, truth);
    WriteDisplacement(files.displacement, k);
    std::ofstream(files.stats) << "{}\n";
  }
}

double RootMeanSquareOfFinite(const Eigen::VectorXd& values) {
  double squares = 0.0;
  int count = 0;
  for (double value : values) {
    if (!std::isfinite(value)) continue;
    squares += value * value;
    ++count;
  }
  return std::sqrt(squares / count);
}

TEST(EvaluationTest, AnExactInputIsMeasuredAsGivenNotAsSubdivided) {
  // The coarse vertices lie on the truth: the input as given errs only between them, while Loop's
  // subdivision moves the coarse vertices themselves off the truth.
  const std::string capture_dir = MakeTempDir("eval_exact") + "/capture";
  SynthOptions synth = TinyCapture();
  synth.coarse = CoarseInput::kExact;
  GenerateSyntheticCapture(synth, capture_dir);
  const Capture capture = Capture::Open(capture_dir);
  const SequenceModel model(capture.ReadCoarseMesh(0), capture.vertex_mask(), RefineOptions(),
                            capture_dir);
  const Mesh coarse = capture.ReadCoarseMesh(1);
  const FineGroundTruth truth = TrueFineGroundTruth(capture, model, coarse, 1);
  ASSERT_EQ(truth.coarse_error.size(), model.num_fine_vertices());
  ASSERT_EQ(truth.k_true.size(), model.num_fine_vertices());
  double at_coarse_vertices = 0.0, subdivided_at_coarse_vertices = 0.0;
  for (int v = 0; v < coarse.num_vertices(); ++v) {
    ASSERT_TRUE(std::isfinite(truth.coarse_error[v])) << "coarse vertex " << v;
    at_coarse_vertices = std::max(at_coarse_vertices, std::abs(truth.coarse_error[v]));
    subdivided_at_coarse_vertices =
        std::max(subdivided_at_coarse_vertices, std::abs(truth.k_true[v]));
  }
  EXPECT_LT(at_coarse_vertices, 1e-6);  // The PLY stores single precision.
  EXPECT_GT(subdivided_at_coarse_vertices, 1e-4);
  const double given = RootMeanSquareOfFinite(truth.coarse_error);
  const double subdivided = RootMeanSquareOfFinite(truth.k_true);
  EXPECT_GT(given, 0.0);
  EXPECT_GT(std::abs(given - subdivided), 0.05 * given) << given << " vs " << subdivided;
}

TEST(EvalCommandTest, FlowTexturesTheRefinedMeshFromItsOwnReferenceSurface) {
  // Folds at full amplitude from frame 0, the reference frame: the input mesh is wrong there.
  const std::string root = MakeTempDir("eval_flow_texture");
  const std::string capture = root + "/capture";
  const std::string out = root + "/truth";
  // 6 cameras of 128 x 128: each face is seen by more than the camera that textures it, so a
  // texture on a wrong surface shows as flow.
  SynthOptions synth = testing_util::TinyRefinableSynthOptions(3);
  synth.cameras.count = 6;
  synth.cameras.width = 128;
  synth.cameras.height = 128;
  synth.cameras.focal = 400.0;
  GenerateSyntheticCapture(synth, capture);
  Config config = RunConfig(capture, out);
  WriteTruthAsRun(capture, config, out);
  config.capture.frames = "1:3";  // The later frames, where the texture has moved with the cloth.
  ASSERT_EQ(RunEval(config), 0);
  const YAML::Node own = YAML::LoadFile(out + "/eval/metrics.json");
  EXPECT_EQ(own["flow_refined_texture"].as<std::string>(), "refined_reference_mesh");

  // Without the refined reference frame the input's texture paints both meshes (the old rule).
  fs::remove(FrameFilesIn(out, "000000", MeshFormat::kPly).stats);
  ::testing::internal::CaptureStderr();
  ASSERT_EQ(RunEval(config), 0);
  const std::string warning = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(warning.find("reference frame 000000 is not refined"), std::string::npos) << warning;
  const YAML::Node shared = YAML::LoadFile(out + "/eval/metrics.json");
  EXPECT_EQ(shared["flow_refined_texture"].as<std::string>(), "input_reference_mesh");

  // The input's figure does not depend on the refined mesh's texture.
  const double input_px = own["flow_coarse_px"].as<double>();
  EXPECT_EQ(input_px, shared["flow_coarse_px"].as<double>());
  // The truth, textured from its own surface, flows clearly less than the input, and clearly
  // less than when its texture was projected onto the input's wrong surface.
  const double own_px = own["flow_refined_px"].as<double>();
  const double shared_px = shared["flow_refined_px"].as<double>();
  EXPECT_LT(own_px, 0.5 * input_px);
  EXPECT_LT(own_px, 0.6 * shared_px);
}

TEST(EvalCommandTest, RefusesAFolderWithoutARefinedRun) {
  const std::string root = MakeTempDir("eval_empty");
  const std::string capture = root + "/capture";
  SynthOptions options = TinyCapture();
  options.num_frames = 1;
  GenerateSyntheticCapture(options, capture);
  const std::string empty = root + "/not_a_run";
  fs::create_directories(empty);
  ExpectErrorMentions([&] { RunEval(RunConfig(capture, empty)); },
                      {"not_a_run", "no refined run", "finecap refine"});
  EXPECT_TRUE(testing_util::FilesIn(empty).empty());  // No eval/ folder left behind.
}

}  // namespace
}  // namespace finecap
