// A user-supplied subject: one mesh, or a folder of per-frame meshes sharing one topology. The
// true surface is its midpoint subdivision; folds are added along interpolated normals.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <unordered_map>
#include <vector>

#include "finecap/io/mesh_io.h"
#include "finecap/util/error.h"
#include "synth/synth_internal.h"

namespace finecap {
namespace synth_internal {
namespace {

// One level of midpoint subdivision: vertex old_count + k is the midpoint of edges[k]; every
// triangle becomes four (`faces`), keeping its orientation.
struct SubdivisionLevel {
  int old_count = 0;
  std::vector<std::pair<int, int>> edges;
  Eigen::Matrix3Xi faces;
};

SubdivisionLevel SubdivideOnce(const Eigen::Matrix3Xi& faces, int num_vertices) {
  SubdivisionLevel level;
  level.old_count = num_vertices;
  std::unordered_map<std::uint64_t, int> midpoint_of_edge;
  auto midpoint = [&](int a, int b) {
    const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                              static_cast<std::uint32_t>(std::max(a, b));
    const auto [it, inserted] =
        midpoint_of_edge.emplace(key, num_vertices + static_cast<int>(level.edges.size()));
    if (inserted) level.edges.emplace_back(a, b);
    return it->second;
  };
  level.faces.resize(3, 4 * faces.cols());
  for (int f = 0; f < faces.cols(); ++f) {
    const int a = faces(0, f);
    const int b = faces(1, f);
    const int c = faces(2, f);
    const int ab = midpoint(a, b);
    const int bc = midpoint(b, c);
    const int ca = midpoint(c, a);
    level.faces.col(4 * f) << a, ab, ca;
    level.faces.col(4 * f + 1) << ab, b, bc;
    level.faces.col(4 * f + 2) << ca, bc, c;
    level.faces.col(4 * f + 3) << ab, bc, ca;
  }
  return level;
}

// Carries per-vertex values through the levels: midpoints get the mean of their edge's ends,
// re-normalised when `unit` (normals).
Eigen::Matrix3Xd Interpolate(const std::vector<SubdivisionLevel>& levels, Eigen::Matrix3Xd values,
                             bool unit) {
  for (const SubdivisionLevel& level : levels) {
    Eigen::Matrix3Xd next(3, level.old_count + level.edges.size());
    next.leftCols(level.old_count) = values;
    for (size_t k = 0; k < level.edges.size(); ++k) {
      Eigen::Vector3d mean =
          0.5 * (values.col(level.edges[k].first) + values.col(level.edges[k].second));
      if (unit && mean.norm() > 0.0) mean.normalize();
      next.col(level.old_count + k) = mean;
    }
    values = std::move(next);
  }
  return values;
}

bool IsMeshFile(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".ply" || extension == ".obj" || extension == ".off" || extension == ".stl";
}

std::vector<std::string> ListFrameFiles(const std::string& path, int num_frames) {
  namespace fs = std::filesystem;
  Require(fs::exists(path), path, "the subject mesh or folder does not exist");
  if (!fs::is_directory(path)) return {path};
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(path)) {
    if (entry.is_regular_file() && IsMeshFile(entry.path())) files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  Require(static_cast<int>(files.size()) >= num_frames, path,
          "holds " + std::to_string(files.size()) + " meshes but " + std::to_string(num_frames) +
              " frames were asked for");
  return files;
}

class MeshSequence : public Subject {
 public:
  MeshSequence(const std::string& path, int num_frames, int refinement)
      : files_(ListFrameFiles(path, num_frames)), reference_(ReadMesh(files_[0])) {
    reference_.Validate(files_[0]);
    Eigen::Matrix3Xi faces = reference_.faces;
    int num_vertices = reference_.num_vertices();
    for (int size = 1; size < refinement; size *= 2) {
      levels_.push_back(SubdivideOnce(faces, num_vertices));
      faces = levels_.back().faces;
      num_vertices += static_cast<int>(levels_.back().edges.size());
    }
    coarse_faces = reference_.faces;
    fine_faces = faces;
    DescribeMaterial(Interpolate(levels_, reference_.vertices, false));
  }

  SmoothFrame Smooth(int frame) const override {
    const std::string& file = files_[std::min<size_t>(frame, files_.size() - 1)];
    Mesh mesh = frame == 0 || files_.size() == 1 ? reference_ : ReadMesh(file);
    mesh.Validate(file);
    RequireSameTopology(reference_, mesh, file);
    SmoothFrame smooth;
    smooth.coarse_vertices = mesh.vertices;
    smooth.coarse_normals = ComputeVertexNormals(mesh);
    smooth.fine_vertices = Interpolate(levels_, mesh.vertices, false);
    smooth.fine_normals = Interpolate(levels_, smooth.coarse_normals, true);
    return smooth;
  }

 private:
  // Material coordinates and a cylindrical texture layout around the vertical axis through the
  // first frame's centroid.
  void DescribeMaterial(const Eigen::Matrix3Xd& fine_rest) {
    const Eigen::Matrix3Xd& rest = reference_.vertices;
    const Eigen::Vector3d centroid = rest.rowwise().mean();
    const double top = rest.row(1).maxCoeff();
    surface_height = top - rest.row(1).minCoeff();
    Require(surface_height > 0.0, files_[0], "the subject has no height (world y must point up)");
    coarse_material = CylindricalCoordinates(rest, centroid, top);
    fine_material = CylindricalCoordinates(fine_rest, centroid, top);
    mean_radius = ((rest.row(0).array() - centroid.x()).square() +
                   (rest.row(2).array() - centroid.z()).square())
                      .sqrt()
                      .mean();
    circumference = 2.0 * M_PI * mean_radius;
    coarse_v = coarse_material.down / surface_height;
    center = 0.5 * (rest.rowwise().minCoeff() + rest.rowwise().maxCoeff());
    fine_corner_uvs.resize(2, 3 * fine_faces.cols());
    for (int f = 0; f < fine_faces.cols(); ++f) {
      double first_u = 0.0;
      for (int c = 0; c < 3; ++c) {
        const int vertex = fine_faces(c, f);
        double u = fine_material.theta(vertex) / (2.0 * M_PI);
        // Keep the corners of a triangle across the seam together: wrap-around addressing
        // makes u and u + 1 the same texel.
        if (c == 0) first_u = u;
        if (u - first_u > 0.5) u -= 1.0;
        if (first_u - u > 0.5) u += 1.0;
        fine_corner_uvs.col(3 * f + c) =
            Eigen::Vector2d(u, fine_material.down(vertex) / surface_height);
      }
    }
  }

  std::vector<std::string> files_;
  Mesh reference_;
  std::vector<SubdivisionLevel> levels_;
};

}  // namespace

MaterialCoordinates CylindricalCoordinates(const Eigen::Matrix3Xd& points,
                                           const Eigen::Vector3d& axis_point, double top) {
  MaterialCoordinates material;
  material.theta.resize(points.cols());
  material.down.resize(points.cols());
  for (int i = 0; i < points.cols(); ++i) {
    const double angle = std::atan2(points(2, i) - axis_point.z(), points(0, i) - axis_point.x());
    material.theta(i) = angle < 0.0 ? angle + 2.0 * M_PI : angle;
    material.down(i) = top - points(1, i);
  }
  return material;
}

std::unique_ptr<Subject> MakeMeshSubject(const std::string& path, int num_frames, int refinement) {
  return std::make_unique<MeshSequence>(path, num_frames, refinement);
}

}  // namespace synth_internal
}  // namespace finecap
