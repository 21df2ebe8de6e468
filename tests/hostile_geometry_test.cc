// Degenerate geometry through the real pipeline, on a tiny synthetic capture modified in code:
// each case either refines (every output finite, no crash) or is refused with an Error naming the
// file and the problem.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "finecap/commands/commands.h"
#include "finecap/geometry/mesh_diagnostics.h"
#include "finecap/io/camera_io.h"
#include "finecap/io/capture.h"
#include "finecap/io/mesh_io.h"
#include "finecap/refine/frame_reader.h"
#include "finecap/refine/frame_stats.h"
#include "finecap/refine/refine.h"
#include "finecap/synth/synth.h"
#include "refine/scene_scale.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;

// A one-frame tiny capture (2 cameras of 64 x 64, a 16 x 10 skirt).
std::string MakeTinyCapture(const std::string& name) {
  const std::string dir = MakeTempDir(name) + "/capture";
  SynthOptions options = testing_util::TinySynthOptions();
  options.num_frames = 1;
  GenerateSyntheticCapture(options, dir);
  return dir;
}

// Frame 0 of the capture in `capture_dir`.
FrameInput ReadFrame(const std::string& capture_dir) {
  Capture capture = Capture::Open(capture_dir);
  return ReadFrameInput(&capture, 0);
}

RefineOptions FastOptions() {
  RefineOptions options;
  options.solver.max_iterations = 3;
  options.solver.num_threads = 1;
  return options;
}

FrameResult Refine(const FrameInput& input, const RefineOptions& options) {
  const SequenceModel model(input.coarse, {}, options, "test mesh");
  const ReferenceColors colors = ComputeSequenceColors(model, input, options);
  return RefineFrame(model, colors, input, options);
}

// Every refined vertex and normal finite; k finite or NaN (not refined), never infinite.
void ExpectFiniteResult(const FrameResult& result) {
  EXPECT_TRUE(result.refined.vertices.allFinite());
  EXPECT_TRUE(result.normals.allFinite());
  for (int v = 0; v < result.k.size(); ++v) EXPECT_FALSE(std::isinf(result.k[v])) << v;
}

TEST(HostileGeometry, ZeroAreaTrianglesRefine) {
  FrameInput input = ReadFrame(MakeTinyCapture("zero_area"));
  // Vertex 37 moved onto its neighbour 38: the two triangles on their edge collapse.
  input.coarse.vertices.col(37) = input.coarse.vertices.col(38);
  ASSERT_EQ(DiagnoseMesh(input.coarse).num_degenerate_faces, 2);
  const FrameResult result = Refine(input, FastOptions());
  ExpectFiniteResult(result);
  EXPECT_GT(result.num_surface_gaussians, 0);
}

TEST(HostileGeometry, IsolatedVertexGetsNoDisplacement) {
  FrameInput input = ReadFrame(MakeTinyCapture("isolated"));
  const int isolated = input.coarse.num_vertices();
  input.coarse.vertices.conservativeResize(3, isolated + 1);
  input.coarse.vertices.col(isolated) = input.coarse.vertices.col(40);  // In view, on the skirt.
  ASSERT_EQ(DiagnoseMesh(input.coarse).num_isolated_vertices, 1);
  const FrameResult result = Refine(input, FastOptions());
  ExpectFiniteResult(result);
  // No face, no normal: nothing to slide along. It stays where it was.
  EXPECT_TRUE(std::isnan(result.k[isolated]));
  EXPECT_EQ(result.refined.vertices.col(isolated), input.coarse.vertices.col(40));
}

// Adds a vertex and a triangle on the interior edge (37, 38), which is then in three triangles.
Mesh WithNonManifoldEdge(Mesh mesh) {
  const int extra = mesh.num_vertices();
  mesh.vertices.conservativeResize(3, extra + 1);
  mesh.vertices.col(extra) = mesh.vertices.col(37) + Eigen::Vector3d(0.0, 0.0, 0.05);
  mesh.faces.conservativeResize(3, mesh.num_faces() + 1);
  mesh.faces.col(mesh.num_faces() - 1) << 37, 38, extra;
  return mesh;
}

TEST(HostileGeometry, NonManifoldEdgeIsRefusedBySubdivisionNamingTheFile) {
  const std::string capture = MakeTinyCapture("non_manifold");
  const std::string mesh_path = capture + "/meshes/000000.ply";
  WriteMesh(mesh_path + ".tmp.ply", WithNonManifoldEdge(ReadMesh(mesh_path)));
  std::filesystem::rename(mesh_path + ".tmp.ply", mesh_path);
  ASSERT_EQ(DiagnoseMesh(ReadMesh(mesh_path)).num_non_manifold_edges, 1);
  const Config config = testing_util::TinyRunConfig(capture, capture + "/../out", 2);
  ExpectErrorMentions([&] { RunRefine(config); },
                      {"meshes/000000.ply", "non-manifold", "37", "38", "3 triangles"});
}

TEST(HostileGeometry, NonManifoldEdgeRefinesWithoutSubdivision) {
  FrameInput input = ReadFrame(MakeTinyCapture("non_manifold_flat"));
  input.coarse = WithNonManifoldEdge(input.coarse);
  RefineOptions options = FastOptions();
  options.subdivision_levels = 0;
  const FrameResult result = Refine(input, options);
  ExpectFiniteResult(result);
  EXPECT_GT(result.num_surface_gaussians, 0);
}

TEST(HostileGeometry, VerticesSeenByNoCameraGetNoGaussian) {
  FrameInput input = ReadFrame(MakeTinyCapture("unseen"));
  input.cameras.resize(1);  // One camera sees the front of the skirt only.
  input.images.resize(1);
  const FrameResult result = Refine(input, FastOptions());
  ExpectFiniteResult(result);
  // Exactly the vertices that the camera sees on the input surface have a displacement.
  const Mesh fine = SequenceModel(input.coarse, {}, FastOptions(), "test").Subdivide(input.coarse);
  const auto visible =
      ComputeFrameVisibility(fine, ComputeVertexNormals(fine), input.cameras,
                             FastOptions().visibility, FallbackCamerasWanted(FastOptions()));
  int unseen = 0;
  for (int v = 0; v < result.k.size(); ++v) {
    EXPECT_EQ(std::isnan(result.k[v]), visible[0][v] == 0) << v;
    unseen += visible[0][v] == 0 ? 1 : 0;
  }
  EXPECT_GT(unseen, result.k.size() / 3);  // At least the back of the skirt.
  EXPECT_EQ(result.num_surface_gaussians, result.k.size() - unseen);
}

// Camera `camera` turned round about its own y axis: everything it saw is now behind it.
Camera TurnedAround(Camera camera) {
  const Eigen::Matrix3d flip = Eigen::Vector3d(-1.0, 1.0, -1.0).asDiagonal();
  camera.R = flip * camera.R;
  camera.t = flip * camera.t;
  camera.name += "_behind";
  return camera;
}

TEST(HostileGeometry, ACameraWithTheMeshBehindItContributesNothing) {
  const FrameInput input = ReadFrame(MakeTinyCapture("behind_one"));
  FrameInput with_blind = input;
  with_blind.cameras.push_back(TurnedAround(input.cameras[0]));
  with_blind.images.push_back(input.images[0]);
  const FrameResult plain = Refine(input, FastOptions());
  const FrameResult blind = Refine(with_blind, FastOptions());
  ExpectFiniteResult(blind);
  EXPECT_EQ(blind.num_surface_gaussians, plain.num_surface_gaussians);
  EXPECT_EQ(blind.num_pairs, plain.num_pairs);
  for (int v = 0; v < plain.k.size(); ++v) {
    EXPECT_EQ(std::isnan(plain.k[v]), std::isnan(blind.k[v])) << v;
  }
}

TEST(HostileGeometry, NoCameraSeesTheMesh) {
  const FrameInput input = ReadFrame(MakeTinyCapture("behind_all"));
  FrameInput blind = input;
  for (Camera& camera : blind.cameras) camera = TurnedAround(camera);
  const FrameResult result = Refine(blind, FastOptions());
  ExpectFiniteResult(result);
  EXPECT_EQ(result.num_surface_gaussians, 0);
}

TEST(HostileGeometry, RefineKeepsTheInputWhenEveryCameraHasTheMeshBehindIt) {
  const std::string capture = MakeTinyCapture("behind_all_command");
  std::vector<Camera> cameras = ReadCamerasYaml(capture + "/cameras.yaml");
  for (Camera& camera : cameras) camera = TurnedAround(camera);
  for (Camera& camera : cameras) camera.name.resize(camera.name.size() - 7);  // Keep the names.
  std::filesystem::remove(capture + "/cameras.yaml");
  WriteCamerasYaml(cameras, capture + "/cameras.yaml");
  const Config config = testing_util::TinyRunConfig(capture, capture + "/../out", 3);
  ASSERT_EQ(RunRefine(config), 0);
  const std::string record = testing_util::FileBytes(capture + "/../out/frames/000000.json");
  const FrameStats stats = ParseFrameStats(record, "000000.json");
  EXPECT_TRUE(stats.kept_input);
  EXPECT_EQ(stats.surface_gaussians, 0);
  const Mesh written = ReadMesh(capture + "/../out/meshes/000000.ply");
  const Mesh input = ReadMesh(capture + "/meshes/000000.ply");
  const Mesh fine = SequenceModel(input, {}, config.refine, "test").Subdivide(input);
  EXPECT_LT((written.vertices - fine.vertices).cwiseAbs().maxCoeff(), 1e-12);
}

// A square of side `side` in the z = 0 plane, two triangles.
Mesh Square(double side) {
  Mesh mesh;
  mesh.vertices.resize(3, 4);
  mesh.vertices << 0, side, side, 0, 0, 0, side, side, 0, 0, 0, 0;
  mesh.faces.resize(3, 2);
  mesh.faces << 0, 0, 1, 2, 2, 3;
  return mesh;
}

TEST(SceneScale, MeasuresTheBoundingBoxAgainstSigmaHat) {
  EXPECT_DOUBLE_EQ(BoundingBoxDiagonal(Square(3.0)), 3.0 * std::sqrt(2.0));
  // 1 m: 202 sigma_hat of 7 mm, a subject in metres.
  EXPECT_NO_THROW(RequirePlausibleSceneScale(Square(1.0), 0.007, "m.ply"));
  // The same square in millimetres: 202,000 sigma_hat.
  ExpectErrorMentions([] { RequirePlausibleSceneScale(Square(1000.0), 0.007, "mm.ply"); },
                      {"mm.ply", "1414 across", "2.02e+05 times RefineOptions::sigma_hat",
                       "millimetres", "convert the capture"});
  // 1 cm: 2 sigma_hat, the Gaussians would cover it whole.
  ExpectErrorMentions([] { RequirePlausibleSceneScale(Square(0.01), 0.007, "tiny.ply"); },
                      {"tiny.ply", "2.02 times", "too small", "0.035 m"});
  // Scaling sigma_hat with the subject is accepted.
  EXPECT_NO_THROW(RequirePlausibleSceneScale(Square(0.01), 0.00007, "tiny.ply"));
  SceneScaleLimits bad;
  bad.max_sigmas = bad.min_sigmas;
  EXPECT_THROW(RequirePlausibleSceneScale(Square(1.0), 0.007, "m.ply", bad), Error);
}

TEST(SceneScale, RefineRefusesACaptureInMillimetresBeforeWritingAnything) {
  const std::string capture = MakeTinyCapture("millimetres");
  const std::string mesh_path = capture + "/meshes/000000.ply";
  Mesh mesh = ReadMesh(mesh_path);
  mesh.vertices *= 1000.0;
  std::filesystem::remove(mesh_path);
  WriteMesh(mesh_path, mesh);
  std::vector<Camera> cameras = ReadCamerasYaml(capture + "/cameras.yaml");
  for (Camera& camera : cameras) camera.t *= 1000.0;
  std::filesystem::remove(capture + "/cameras.yaml");
  WriteCamerasYaml(cameras, capture + "/cameras.yaml");
  const Config config = testing_util::TinyRunConfig(capture, capture + "/../out", 2);
  ExpectErrorMentions([&] { RunRefine(config); }, {mesh_path, "millimetres"});
  EXPECT_FALSE(std::filesystem::exists(capture + "/../out"));
}

}  // namespace
}  // namespace finecap
