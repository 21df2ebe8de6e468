// Degenerate geometry through the real pipeline, on a tiny synthetic capture modified in code:
// each case either refines (every output finite, no crash) or is refused with an Error naming the
// file and the problem.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "finecap/camera_io.h"
#include "finecap/capture.h"
#include "finecap/commands.h"
#include "finecap/mesh_diagnostics.h"
#include "finecap/mesh_io.h"
#include "finecap/refine.h"
#include "finecap/synth.h"
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

FrameInput ReadFrame(const std::string& capture_dir) {
  Capture capture = Capture::Open(capture_dir);
  FrameInput input;
  input.coarse = capture.ReadCoarseMesh(0);
  input.cameras = capture.cameras();
  for (int c = 0; c < capture.num_cameras(); ++c) input.images.push_back(capture.ReadImage(c, 0));
  return input;
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
  Config config;
  config.capture.dir = capture;
  config.output.dir = capture + "/../out";
  config.refine.solver.max_iterations = 2;
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
  const auto visible = ComputeFrameVisibility(result.refined, result.normals, input.cameras,
                                              FastOptions().visibility);
  int unrefined = 0;
  for (int v = 0; v < result.k.size(); ++v) unrefined += std::isnan(result.k[v]) ? 1 : 0;
  EXPECT_EQ(result.num_surface_gaussians + unrefined, result.k.size());
  EXPECT_GT(unrefined, result.k.size() / 3);  // At least the back, out of a camera's sight.
  EXPECT_GT(result.num_surface_gaussians, 0);
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

}  // namespace
}  // namespace finecap
