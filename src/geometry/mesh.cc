#include "finecap/geometry/mesh.h"

#include <Eigen/Geometry>

#include "finecap/util/error.h"

namespace finecap {

void Mesh::Validate(const std::string& where) const {
  Require(num_faces() > 0, where, "the mesh has no triangles");
  Require(vertices.allFinite(), where, "the mesh has a NaN or infinite vertex coordinate");
  // Checked with `if` rather than Require: building the message for each of a large mesh's
  // triangles would cost more than the checks themselves.
  for (int f = 0; f < num_faces(); ++f) {
    const Eigen::Vector3i face = faces.col(f);
    if (face.minCoeff() < 0 || face.maxCoeff() >= num_vertices()) {
      throw Error(where,
                  "triangle " + std::to_string(f) + " refers to a vertex that does not exist");
    }
    if (face(0) == face(1) || face(1) == face(2) || face(0) == face(2)) {
      throw Error(where, "triangle " + std::to_string(f) + " repeats a vertex");
    }
  }
}

Eigen::Matrix3Xd ComputeVertexNormals(const Mesh& mesh) {
  Eigen::Matrix3Xd normals = Eigen::Matrix3Xd::Zero(3, mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3i face = mesh.faces.col(f);
    const Eigen::Vector3d a = mesh.vertices.col(face(0));
    // The cross product's length is twice the area: summing it weights each face by its area.
    const Eigen::Vector3d area_normal =
        (mesh.vertices.col(face(1)) - a).cross(mesh.vertices.col(face(2)) - a);
    for (int corner = 0; corner < 3; ++corner) normals.col(face(corner)) += area_normal;
  }
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const double length = normals.col(v).norm();
    if (length > 0.0) normals.col(v) /= length;
  }
  return normals;
}

bool HasSameTopology(const Mesh& a, const Mesh& b) {
  return a.num_vertices() == b.num_vertices() && a.faces == b.faces;
}

void RequireSameTopology(const Mesh& reference, const Mesh& frame, const std::string& where) {
  Require(frame.num_vertices() == reference.num_vertices(), where,
          "has " + std::to_string(frame.num_vertices()) + " vertices but the first frame has " +
              std::to_string(reference.num_vertices()) + ": every frame must share one topology");
  Require(frame.faces == reference.faces, where,
          "its triangles differ from the first frame's: every frame must share one topology");
}

}  // namespace finecap
