// finecap export: a refined run where animation tools read it, in output.dir/export/:
// sequence.pc2, a PC2 point cache (Blender's Mesh Cache modifier plays it on first_frame.ply),
// and ply/<frame>.ply with the displacement as vertex quality (MeshLab colours by it).
#include <filesystem>
#include <iostream>

#include "commands/command_util.h"
#include "finecap/commands/commands.h"
#include "finecap/io/export.h"
#include "finecap/io/mesh_io.h"

namespace finecap {

int RunExport(const Config& config) {
  Capture capture = internal::OpenConfiguredCapture(config);
  const std::string out = internal::RefinedRunFolder(config);
  const std::vector<RefinedFrame> frames = internal::FindRefinedFrames(config, capture, out);
  const std::string folder = ExportFolder(out);
  std::filesystem::create_directories(folder + "/ply");

  const Mesh first = ReadMesh(frames.front().files.mesh);
  WriteMesh(folder + "/first_frame.ply", first, {ComputeVertexNormals(first), {}, {}});
  // Frames run one at a time: memory does not grow with the sequence.
  Pc2Writer cache(folder + "/sequence.pc2", first.num_vertices(),
                  static_cast<float>(frames.front().index));
  for (const RefinedFrame& frame : frames) {
    const Mesh mesh = ReadMesh(frame.files.mesh);
    RequireSameTopology(first, mesh, frame.files.mesh);
    const Eigen::VectorXd k = ReadDisplacement(frame.files.displacement, mesh.num_vertices());
    cache.Append(mesh.vertices);
    WriteDisplacementPly(folder + "/ply/" + frame.name + ".ply", mesh,
                         k.array().isFinite().select(k, 0.0));
  }
  cache.Finish();
  std::cout << "Exported " << frames.size() << " frames: " << folder
            << "/sequence.pc2 (with first_frame.ply) and " << folder << "/ply/\n";
  return 0;
}

}  // namespace finecap
