#include "finecap/synth/synth.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>

#include "finecap/geometry/render.h"
#include "finecap/io/camera_io.h"
#include "finecap/io/mesh_io.h"
#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "test_meshes.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

// A fresh, empty folder path under the test temp dir (the folder itself is not created).
std::string FreshPath(const std::string& name) {
  const fs::path path = fs::path(::testing::TempDir()) / ("finecap_synth_" + name);
  fs::remove_all(path);
  return path.string();
}

SynthOptions TinyOptions() { return testing_util::TinySynthOptions(); }

std::string ReadText(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

TEST(SynthTest, WritesTheCaptureLayoutAndItReadsBack) {
  const SynthOptions options = TinyOptions();
  const std::string out = FreshPath("layout");
  GenerateSyntheticCapture(options, out);

  const std::vector<Camera> cameras = ReadCamerasYaml(out + "/cameras.yaml");
  ASSERT_EQ(cameras.size(), 2u);
  const SyntheticCapture capture(options);
  for (size_t c = 0; c < cameras.size(); ++c) {
    EXPECT_EQ(cameras[c].name, capture.true_cameras()[c].name);
    EXPECT_LT((cameras[c].K - capture.true_cameras()[c].K).norm(), 1e-9);
    EXPECT_LT((cameras[c].R - capture.true_cameras()[c].R).norm(), 1e-9);
    EXPECT_LT((cameras[c].t - capture.true_cameras()[c].t).norm(), 1e-9);
  }
  for (int index = 0; index < 2; ++index) {
    const std::string name = index == 0 ? "000000" : "000001";
    const SyntheticFrame frame = capture.Frame(index);
    const Mesh coarse = ReadMesh(out + "/meshes/" + name + ".ply");
    EXPECT_EQ(coarse.num_vertices(), 160);
    EXPECT_EQ(coarse.faces, frame.coarse.faces);
    EXPECT_LT((coarse.vertices - frame.coarse.vertices).cwiseAbs().maxCoeff(), 1e-6);
    const Mesh truth = ReadMesh(out + "/gt/" + name + ".ply");
    EXPECT_EQ(truth.num_vertices(), frame.truth.num_vertices());
    EXPECT_GT(truth.num_vertices(), 10 * coarse.num_vertices());
    std::istringstream k_text(ReadText(out + "/gt/" + name + "_k.txt"));
    std::string line;
    int lines = 0;
    while (std::getline(k_text, line)) {
      const double k = line == "nan" ? NAN : std::stod(line);
      if (!std::isnan(frame.true_k(lines))) {
        EXPECT_NEAR(k, frame.true_k(lines), 1e-8);
      }
      ++lines;
    }
    EXPECT_EQ(lines, 160);
    for (const Camera& camera : cameras) {
      const cv::Mat image = cv::imread(out + "/images/" + camera.name + "/" + name + ".png");
      ASSERT_FALSE(image.empty()) << camera.name << "/" << name;
      EXPECT_EQ(image.cols, 64);
      EXPECT_EQ(image.rows, 64);
    }
  }
  EXPECT_TRUE(fs::exists(out + "/gt/textureless.txt"));
  EXPECT_EQ(ReadText(out + "/gt/textureless.txt"), "");
}

TEST(SynthTest, TrueVerticesProjectOntoTheRenderedSubject) {
  SynthOptions options = TinyOptions();
  options.cameras.width = options.cameras.height = 128;
  options.cameras.focal = 120.0;
  const SyntheticCapture capture(options);
  const SyntheticFrame frame = capture.Frame(1);
  int checked = 0;
  for (const Camera& camera : capture.true_cameras()) {
    const DepthMap map = RenderDepth(camera, frame.truth);
    for (int v = 0; v < frame.truth.num_vertices(); v += 7) {
      const Eigen::Vector3d point = frame.truth.vertices.col(v);
      // Only points on the side of the skirt that faces the camera, away from its silhouette.
      const Eigen::Vector3d radial(point.x(), 0.0, point.z());
      const Eigen::Vector3d to_camera = camera.Center() - point;
      const Eigen::Vector3d level(to_camera.x(), 0.0, to_camera.z());
      if (radial.normalized().dot(level.normalized()) < 0.7) continue;
      if (point.y() > 0.97 || point.y() < 0.43) continue;  // Waist at 1 m, hem at 0.4 m.
      const Eigen::Vector2d pixel = camera.Project(point);
      const int x = static_cast<int>(std::lround(pixel.x()));
      const int y = static_cast<int>(std::lround(pixel.y()));
      ASSERT_TRUE(x >= 0 && y >= 0 && x < camera.width && y < camera.height);
      EXPECT_NE(map.triangle_ids.at<int>(y, x), -1) << camera.name << " vertex " << v;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(SynthTest, TrueDisplacementEqualsTheFoldWhereNormalsAgree) {
  SynthOptions options = TinyOptions();
  options.skirt.around = 48;
  options.skirt.down = 16;
  options.truth_refinement = 4;
  const SyntheticCapture capture(options);
  const SyntheticFrame frame = capture.Frame(1);
  const Eigen::Matrix3Xd coarse_normals = ComputeVertexNormals(frame.coarse);
  int checked = 0;
  // The waist and hem rings are left out: the surface ends there, so a tilted ray can miss it.
  for (int v = options.skirt.around; v < frame.coarse.num_vertices() - options.skirt.around; ++v) {
    const double cosine = coarse_normals.col(v).dot(frame.smooth_normals.col(v));
    if (cosine < std::cos(2.0 * M_PI / 180.0)) continue;
    ASSERT_FALSE(std::isnan(frame.true_k(v))) << v;
    EXPECT_NEAR(frame.true_k(v), frame.folds_at_coarse(v), 1e-4) << v;
    ++checked;
  }
  EXPECT_GT(checked, frame.coarse.num_vertices() / 2);
  EXPECT_GT(frame.folds_at_coarse.cwiseAbs().maxCoeff(), 0.005);  // The folds are really there.
}

TEST(SynthTest, FoldsFollowTheDocumentedFormula) {
  SynthOptions options = TinyOptions();
  FoldComponent fold;
  fold.amplitude = 0.01;
  fold.wavelength = 0.1;
  fold.orientation = 0.0;
  fold.phase = 30.0;
  fold.drift = 20.0;
  options.folds = {fold};
  options.fold_ramp_frames = 4;  // The ramp itself is under test.
  options.num_frames = 3;
  const SyntheticCapture capture(options);
  const double mean_radius = 0.5 * (options.skirt.waist_radius + options.skirt.hem_radius);
  const double waves = std::round(2.0 * M_PI * mean_radius / fold.wavelength);
  const int frame_index = 2;
  const double x = frame_index / 4.0;
  const double ramp = x * x * (3.0 - 2.0 * x);
  const SyntheticFrame frame = capture.Frame(frame_index);
  for (int v = 0; v < frame.coarse.num_vertices(); ++v) {
    const double theta = 2.0 * M_PI * (v % options.skirt.around) / options.skirt.around;
    const double expected = ramp * fold.amplitude *
                            std::sin(waves * theta + (30.0 + 20.0 * frame_index) * M_PI / 180.0);
    EXPECT_NEAR(frame.folds_at_coarse(v), expected, 1e-12);
  }
  // With a ramp, frame 0 is the smooth pose.
  EXPECT_EQ(capture.Frame(0).folds_at_coarse.cwiseAbs().maxCoeff(), 0.0);
}

TEST(SynthTest, TheReferenceFrameHasFoldsByDefault) {
  SynthOptions options = TinyOptions();
  options.fold_ramp_frames = SynthOptions().fold_ramp_frames;
  EXPECT_EQ(options.fold_ramp_frames, 0);
  const SyntheticFrame first = SyntheticCapture(options).Frame(0);
  EXPECT_GT(first.folds_at_coarse.cwiseAbs().maxCoeff(), 0.005);
  int folded = 0;
  for (int v = 0; v < first.true_k.size(); ++v) folded += std::abs(first.true_k(v)) > 0.002;
  EXPECT_GT(folded, first.true_k.size() / 4);
}

TEST(SynthTest, SmoothedCoarseMeshesAreSmoothedCopiesOfTheTruth) {
  SynthOptions options = TinyOptions();
  options.skirt.around = 48;
  options.skirt.down = 16;
  const SyntheticFrame unfolded = SyntheticCapture(options).Frame(1);
  options.coarse = CoarseInput::kSmoothed;
  const SyntheticFrame smoothed = SyntheticCapture(options).Frame(1);
  EXPECT_EQ(smoothed.truth.vertices, unfolded.truth.vertices);
  EXPECT_EQ(smoothed.coarse.faces, unfolded.coarse.faces);
  // The truth at the coarse vertices, unsmoothed: the unfolded surface plus the folds.
  Mesh detailed = unfolded.coarse;
  detailed.vertices += unfolded.smooth_normals * unfolded.folds_at_coarse.asDiagonal();
  EXPECT_LT(testing_meshes::Roughness(smoothed.coarse), 0.5 * testing_meshes::Roughness(detailed))
      << testing_meshes::Roughness(smoothed.coarse) << " vs "
      << testing_meshes::Roughness(detailed);
  // Some of the folds stay in the input (30 iterations damp the longest ones little), and what
  // is gone is in the ground truth: k_true is smaller than for the unfolded input but not zero.
  const auto rms = [](const Eigen::VectorXd& k) {
    double squares = 0.0;
    int count = 0;
    for (int v = 0; v < k.size(); ++v) {
      if (std::isnan(k(v))) continue;
      squares += k(v) * k(v);
      ++count;
    }
    return std::sqrt(squares / count);
  };
  EXPECT_GT(rms(smoothed.true_k), 0.0005);
  EXPECT_LT(rms(smoothed.true_k), rms(unfolded.true_k));
  // More iterations take more of the detail away.
  options.smoothing.iterations = 120;
  const SyntheticFrame stronger = SyntheticCapture(options).Frame(1);
  EXPECT_GT(rms(stronger.true_k), rms(smoothed.true_k));
}

TEST(SynthTest, ExactCoarseMeshesLieOnTheTruthAtTheirVertices) {
  SynthOptions options = TinyOptions();
  const SyntheticFrame unfolded = SyntheticCapture(options).Frame(1);
  options.coarse = CoarseInput::kExact;
  const SyntheticFrame exact = SyntheticCapture(options).Frame(1);
  EXPECT_EQ(exact.truth.vertices, unfolded.truth.vertices);
  EXPECT_EQ(exact.coarse.faces, unfolded.coarse.faces);
  // Every coarse vertex is a vertex of the true mesh: the nearest true vertex is where it is, and
  // the ground truth measured from it is 0.
  for (int v = 0; v < exact.coarse.num_vertices(); ++v) {
    const double nearest =
        (exact.truth.vertices.colwise() - exact.coarse.vertices.col(v)).colwise().norm().minCoeff();
    ASSERT_LT(nearest, 1e-9) << "coarse vertex " << v;
    ASSERT_NEAR(exact.true_k(v), 0.0, 1e-9) << "coarse vertex " << v;
  }
  // Where there are folds it is not the unfolded input: it is moved by the fold along the smooth
  // normal.
  const Eigen::VectorXd moved = (exact.coarse.vertices - unfolded.coarse.vertices).colwise().norm();
  EXPECT_GT(unfolded.folds_at_coarse.cwiseAbs().maxCoeff(), 0.005);
  for (int v = 0; v < exact.coarse.num_vertices(); ++v) {
    EXPECT_NEAR(moved(v), std::abs(unfolded.folds_at_coarse(v)), 1e-9) << "coarse vertex " << v;
  }
}

TEST(SynthTest, BadSmoothingStrengthIsRefusedNamingTheKey) {
  SynthOptions options = TinyOptions();
  options.coarse = CoarseInput::kSmoothed;
  options.smoothing.iterations = 0;
  const std::string out = FreshPath("bad_smoothing");
  try {
    GenerateSyntheticCapture(options, out);
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("SynthOptions::smoothing.iterations"),
              std::string::npos)
        << error.what();
  }
  EXPECT_FALSE(fs::exists(out));
}

TEST(SynthTest, MisalignmentMovesOnlyTheCoarseMeshByAFewMillimetres) {
  SynthOptions options = TinyOptions();
  const SyntheticFrame aligned = SyntheticCapture(options).Frame(1);
  options.misalignment = 0.004;
  const SyntheticFrame misaligned = SyntheticCapture(options).Frame(1);
  EXPECT_EQ(aligned.truth.vertices, misaligned.truth.vertices);
  const Eigen::VectorXd offsets =
      (misaligned.coarse.vertices - aligned.coarse.vertices).colwise().norm();
  EXPECT_LE(offsets.maxCoeff(), 0.004 + 1e-12);
  EXPECT_GT(offsets.maxCoeff(), 0.001);
}

TEST(SynthTest, TexturelessBandListsItsCoarseVertices) {
  SynthOptions options = TinyOptions();
  options.texture.textureless_begin = 0.3;
  options.texture.textureless_end = 0.6;
  const std::string out = FreshPath("textureless");
  GenerateSyntheticCapture(options, out);
  const SyntheticCapture capture(options);
  const std::vector<int>& ids = capture.textureless_vertices();
  // Rows j of the 10-row grid whose arc-length fraction lies in [0.3, 0.6]: a few, not all.
  ASSERT_FALSE(ids.empty());
  EXPECT_LT(ids.size(), 160u);
  EXPECT_EQ(ids.size() % 16, 0u);  // Whole rings of the grid.
  std::string expected;
  for (int id : ids) expected += std::to_string(id) + "\n";
  EXPECT_EQ(ReadText(out + "/gt/textureless.txt"), expected);
}

TEST(SynthTest, RefusesANonEmptyOutputFolder) {
  const std::string out = FreshPath("occupied");
  fs::create_directories(out);
  WriteTextFileAtomically(out + "/precious.txt", "keep me");
  try {
    GenerateSyntheticCapture(TinyOptions(), out);
    FAIL() << "no error";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(out), std::string::npos) << message;
    EXPECT_NE(message.find("not empty"), std::string::npos) << message;
  }
  EXPECT_EQ(ReadText(out + "/precious.txt"), "keep me");
  EXPECT_FALSE(fs::exists(out + "/cameras.yaml"));
}

// Every file under `root`, relative path -> contents.
std::map<std::string, std::string> ReadTree(const std::string& root) {
  std::map<std::string, std::string> tree;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.is_regular_file()) {
      tree[fs::relative(entry.path(), root).string()] = ReadText(entry.path().string());
    }
  }
  return tree;
}

TEST(SynthTest, SameSeedGivesIdenticalFiles) {
  SynthOptions options = TinyOptions();
  options.render.noise_sigma = 3.0;
  options.misalignment = 0.003;
  options.cameras.rotation_noise = 0.2;
  const std::string first = FreshPath("seed_a");
  const std::string second = FreshPath("seed_b");
  const std::string other = FreshPath("seed_c");
  GenerateSyntheticCapture(options, first);
  GenerateSyntheticCapture(options, second);
  options.seed = 2;
  GenerateSyntheticCapture(options, other);
  const auto a = ReadTree(first);
  EXPECT_EQ(a.size(), 1u + 2 * 3 + 1 + 2 * 2);  // cameras, 2 x (mesh, gt, k), textureless, images.
  EXPECT_TRUE(a == ReadTree(second));
  const auto c = ReadTree(other);
  EXPECT_NE(a.at("images/cam00/000000.png"), c.at("images/cam00/000000.png"));
  EXPECT_NE(a.at("cameras.yaml"), c.at("cameras.yaml"));
}

TEST(SynthTest, CalibrationNoisePerturbsOnlyTheWrittenCameras) {
  SynthOptions options = TinyOptions();
  options.cameras.rotation_noise = 0.5;
  options.cameras.translation_noise = 0.01;
  options.cameras.focal_noise = 0.01;
  const SyntheticCapture capture(options);
  for (size_t c = 0; c < capture.true_cameras().size(); ++c) {
    const Camera& truth = capture.true_cameras()[c];
    const Camera& stated = capture.calibrated_cameras()[c];
    const double angle = Eigen::AngleAxisd(stated.R * truth.R.transpose()).angle() * 180.0 / M_PI;
    EXPECT_GT(angle, 0.0);
    EXPECT_LT(angle, 0.5 * 6.0);
    EXPECT_LT((stated.Center() - truth.Center()).norm(), 0.01 * 6.0);
    EXPECT_NE(stated.K(0, 0), truth.K(0, 0));
    EXPECT_NO_THROW(stated.Validate("stated"));
  }
}

TEST(SynthTest, DistortedImagesUndistortBackToThePinholeRender) {
  SynthOptions options = TinyOptions();
  options.cameras.count = 1;
  options.cameras.width = 128;
  options.cameras.height = 128;
  options.cameras.focal = 140.0;
  options.cameras.distance = 1.0;  // Close, so that the skirt reaches where distortion is strong.
  options.render.supersampling = 2;
  options.texture.pattern =
      TexturePattern::kNoise;  // Smooth, so that resampling twice blurs little.
  const SyntheticCapture pinhole(options);
  options.cameras.distortion = {-0.35, 0.1, 0.001, -0.002, 0.0};
  const SyntheticCapture distorted(options);
  const SyntheticFrame frame = pinhole.Frame(0);
  const cv::Mat reference = pinhole.Image(frame, 0, 0);
  const cv::Mat raw = distorted.Image(frame, 0, 0);
  const Camera& camera = distorted.calibrated_cameras()[0];
  cv::Mat K;
  cv::eigen2cv(camera.K, K);
  const std::vector<double> coefficients(camera.distortion.begin(), camera.distortion.end());
  cv::Mat undistorted;
  cv::undistort(raw, undistorted, K, coefficients);
  // Away from the corners, where undistortion reaches outside the raw image.
  const cv::Rect centre(16, 16, 96, 96);
  const double before = cv::norm(raw(centre), reference(centre), cv::NORM_L1) / centre.area();
  const double after =
      cv::norm(undistorted(centre), reference(centre), cv::NORM_L1) / centre.area();
  // What remains is the blur of resampling twice along the silhouette; a wrong model leaves the
  // silhouette displaced and the error near `before`.
  EXPECT_LT(after, 0.45 * before) << "before " << before << " after " << after;
}

TEST(SynthTest, UserMeshGetsSubdividedAndFolded) {
  const std::string folder = FreshPath("user_meshes");
  fs::create_directories(folder);
  SynthOptions skirt = TinyOptions();
  skirt.folds.clear();
  const SyntheticCapture source(skirt);
  WriteMesh(folder + "/a.ply", source.Frame(0).coarse);
  WriteMesh(folder + "/b.ply", source.Frame(1).coarse);

  SynthOptions options = TinyOptions();
  options.subject = SynthSubject::kMesh;
  options.mesh_path = folder;
  options.truth_refinement = 2;
  const SyntheticCapture capture(options);
  const SyntheticFrame frame = capture.Frame(1);
  const Mesh input = ReadMesh(folder + "/b.ply");
  EXPECT_EQ(frame.coarse.faces, input.faces);
  EXPECT_EQ(frame.truth.num_faces(), 4 * input.num_faces());
  // V + E vertices: the closed-around tube of 16 x 10 has 16 * 9 + 16 * 10 + 16 * 9 edges.
  EXPECT_EQ(frame.truth.num_vertices(), 160 + 16 * 9 + 16 * 10 + 16 * 9);
  // Smooth normals are the input's own, so k is the fold wherever the ray finds the surface.
  for (int v = 0; v < frame.coarse.num_vertices(); ++v) {
    ASSERT_FALSE(std::isnan(frame.true_k(v)));
    EXPECT_NEAR(frame.true_k(v), frame.folds_at_coarse(v), 1e-9);
  }
  EXPECT_GT(frame.folds_at_coarse.cwiseAbs().maxCoeff(), 0.005);
}

TEST(SynthTest, UserMeshFolderWithChangingTopologyIsRefused) {
  const std::string folder = FreshPath("bad_meshes");
  fs::create_directories(folder);
  const SyntheticCapture source(TinyOptions());
  Mesh first = source.Frame(0).coarse;
  WriteMesh(folder + "/000.ply", first);
  Mesh second = first;
  std::swap(second.faces(1, 0), second.faces(2, 0));
  WriteMesh(folder + "/001.ply", second);
  SynthOptions options = TinyOptions();
  options.subject = SynthSubject::kMesh;
  options.mesh_path = folder;
  options.truth_refinement = 2;
  const SyntheticCapture capture(options);
  try {
    capture.Frame(1);
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("001.ply"), std::string::npos) << error.what();
  }
}

TEST(SynthTest, InvalidOptionsNameTheField) {
  SynthOptions options = TinyOptions();
  options.folds[1].wavelength = 0.0;
  try {
    options.Check();
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("SynthOptions::folds[1].wavelength"),
              std::string::npos);
  }
  options = TinyOptions();
  options.subject = SynthSubject::kMesh;
  options.truth_refinement = 3;
  options.mesh_path = "x.ply";
  EXPECT_THROW(options.Check(), Error);
  options = TinyOptions();
  options.cameras.heights.clear();
  EXPECT_THROW(GenerateSyntheticCapture(options, FreshPath("never")), Error);
  EXPECT_FALSE(fs::exists(FreshPath("never")));
}

}  // namespace
}  // namespace finecap
