// Reading meshes (PLY, OBJ, OFF and whatever else assimp reads) and writing refined ones.
#ifndef FINECAP_MESH_IO_H_
#define FINECAP_MESH_IO_H_

#include <string>

#include <Eigen/Core>

#include "finecap/mesh.h"

namespace finecap {

// Reads a triangle mesh. Vertices are kept exactly as stored: no merging, reordering or
// re-triangulation that would break a sequence's shared topology (polygons are refused).
// Throws Error naming the file when it is missing, not a mesh, empty, or has non-finite values.
Mesh ReadMesh(const std::string& path);

enum class MeshFormat { kPly, kObj };  // PLY is written binary little-endian.

// Optional per-vertex attributes of a written mesh; an empty member is not written.
struct VertexAttributes {
  Eigen::Matrix3Xd normals;  // Unit normals.
  Eigen::Matrix3Xd colors;   // RGB in [0, 1].
  Eigen::VectorXd quality;   // A scalar per vertex, e.g. the displacement k (PLY only).
};

// Writes atomically (see atomic_file.h). Throws Error naming the file on failure.
void WriteMesh(const std::string& path, const Mesh& mesh, const VertexAttributes& attributes = {},
               MeshFormat format = MeshFormat::kPly);

}  // namespace finecap

#endif  // FINECAP_MESH_IO_H_
