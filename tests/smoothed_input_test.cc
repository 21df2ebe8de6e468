// The smoothed-input workflow end to end, as a user with a detailed mesh sequence of their own
// would run it: the sequence becomes a synthetic capture whose coarse meshes are its smoothed
// copies (finecap synth), which is refined (finecap refine) and measured against the sequence
// itself (finecap eval).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <Eigen/Dense>

#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/io/mesh_io.h"
#include "finecap/synth/synth.h"
#include "test_meshes.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

constexpr int kFrames = 2;

// A detailed tube standing on the floor's axis (world y up, around 1 m high), 24 x 12 vertices,
// radius 0.25 m, whose surface carries 6 bumps around and 2 along it, 6 mm high, drifting
// around from frame to frame.
Mesh BumpyTubeFrame(int frame) {
  Mesh tube = testing_meshes::TubeMesh(24, 12, 0.25, 0.5);
  for (int v = 0; v < tube.num_vertices(); ++v) {
    const Eigen::Vector3d p = tube.vertices.col(v);  // Around the z axis, z from 0 to 0.5.
    const double theta = std::atan2(p.y(), p.x());
    const double bump =
        0.006 * std::sin(6.0 * theta + 0.4 * frame) * std::cos(2.0 * M_PI * 2.0 * p.z() / 0.5);
    const double scale = (0.25 + bump) / 0.25;
    // Turned so that the axis is world y (a rotation about x keeps the triangles' orientation).
    tube.vertices.col(v) << scale * p.x(), 0.75 + p.z(), -scale * p.y();
  }
  return tube;
}

// RMS over the vertices of the distance from the world y axis minus the tube's radius.
double BumpRms(const Mesh& mesh) {
  const Eigen::ArrayXd radii =
      (mesh.vertices.row(0).array().square() + mesh.vertices.row(2).array().square()).sqrt();
  return std::sqrt((radii - 0.25).square().mean());
}

std::vector<double> ReadDisplacements(const std::string& path) {
  std::ifstream file(path);
  std::vector<double> k;
  for (std::string line; std::getline(file, line);)
    k.push_back(line == "nan" ? NAN : std::stod(line));
  return k;
}

// Distance from `point` to the nearest triangle of `mesh` it projects into (barycentric
// coordinates within a small tolerance), by brute force: independent of the ray caster that
// made the ground truth.
double DistanceToSurface(const Mesh& mesh, const Eigen::Vector3d& point) {
  double nearest = INFINITY;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.col(mesh.faces(0, f));
    const Eigen::Vector3d ab = mesh.vertices.col(mesh.faces(1, f)) - a;
    const Eigen::Vector3d ac = mesh.vertices.col(mesh.faces(2, f)) - a;
    const Eigen::Vector3d normal = ab.cross(ac).normalized();
    const Eigen::Vector3d in_plane = point - a - (point - a).dot(normal) * normal;
    Eigen::Matrix<double, 3, 2> basis;
    basis << ab, ac;
    const Eigen::Vector2d uv = basis.colPivHouseholderQr().solve(in_plane);
    constexpr double kTolerance = 1e-4;  // Rounding of the files' coordinates.
    if (uv.minCoeff() < -kTolerance || uv.sum() > 1.0 + kTolerance) continue;
    nearest = std::min(nearest, std::abs((point - a).dot(normal)));
  }
  return nearest;
}

TEST(SmoothedInputTest, DetailedUserSequenceBecomesARefinableBenchmark) {
  const std::string root = testing_util::MakeTempDir("smoothed_input");
  const std::string sequence = root + "/sequence";
  std::filesystem::create_directories(sequence);
  for (int frame = 0; frame < kFrames; ++frame) {
    WriteMesh(sequence + "/tube_" + std::to_string(frame) + ".ply", BumpyTubeFrame(frame));
  }

  // The sequence is the truth (no subdivision, no procedural folds); its smoothed copies are the
  // input. 3 cameras of 96 x 96.
  SynthOptions synth = testing_util::TinyRefinableSynthOptions(kFrames);
  synth.subject = SynthSubject::kMesh;
  synth.mesh_path = sequence;
  synth.truth_refinement = 1;
  synth.folds.clear();
  synth.coarse = CoarseInput::kSmoothed;
  const std::string capture = root + "/capture";
  Config config = testing_util::TinyRunConfig(capture, root + "/run", 5);
  config.synth = synth;
  config.output.dir = capture;
  ASSERT_EQ(RunSynth(config), 0);

  for (int frame = 0; frame < kFrames; ++frame) {
    SCOPED_TRACE(frame);
    const std::string name = frame == 0 ? "000000" : "000001";
    const Mesh truth = ReadMesh(capture + "/gt/" + name + ".ply");
    const Mesh coarse = ReadMesh(capture + "/meshes/" + name + ".ply");
    const Mesh detailed = BumpyTubeFrame(frame);
    EXPECT_LT((truth.vertices - detailed.vertices).cwiseAbs().maxCoeff(), 1e-5);
    ASSERT_EQ(coarse.faces, detailed.faces);
    // Smoother than the truth: the bumps, the radius' departure from the tube's 0.25 m, mostly
    // gone.
    EXPECT_LT(BumpRms(coarse), 0.3 * BumpRms(truth)) << BumpRms(coarse) << " " << BumpRms(truth);
    EXPECT_GT(BumpRms(truth), 0.002);

    // The ground truth: non-zero, and coarse + k_true * normal lies on the true surface.
    const std::vector<double> k = ReadDisplacements(capture + "/gt/" + name + "_k.txt");
    ASSERT_EQ(static_cast<int>(k.size()), coarse.num_vertices());
    const Eigen::Matrix3Xd normals = ComputeVertexNormals(coarse);
    double squares = 0.0;
    int hits = 0;
    for (int v = 0; v < coarse.num_vertices(); ++v) {
      if (std::isnan(k[v])) continue;
      ++hits;
      squares += k[v] * k[v];
      const Eigen::Vector3d recovered = coarse.vertices.col(v) + k[v] * normals.col(v);
      // 10 micrometres: the files' rounding, against bumps of 6 mm.
      EXPECT_LT(DistanceToSurface(truth, recovered), 1e-5) << "vertex " << v;
    }
    EXPECT_GT(hits, coarse.num_vertices() * 3 / 4);  // Rays from the open ends may miss.
    EXPECT_GT(std::sqrt(squares / hits), 0.001);     // Metres: the smoothing took millimetres away.
  }

  config.output.dir = root + "/run";
  ASSERT_EQ(RunRefine(config), 0);
  ASSERT_EQ(RunEval(config), 0);
  const YAML::Node metrics = YAML::LoadFile(root + "/run/eval/metrics.json");
  EXPECT_EQ(metrics["frames"].size(), static_cast<size_t>(kFrames));
  EXPECT_GT(metrics["rms_coarse_mm"].as<double>(), 1.0);
  EXPECT_TRUE(std::isfinite(metrics["rms_refined_mm"].as<double>()));
  EXPECT_TRUE(std::isfinite(metrics["detail_recovered"].as<double>()));
}

}  // namespace
}  // namespace finecap
