// Reading meshes (PLY, OBJ, OFF and whatever else assimp reads) and writing refined ones.
//
// Why PLY, OBJ and OFF have readers of their own: a sequence's frames share one topology, so the
// reader must return the vertices exactly as the file lists them, in order and number. assimp
// (5.2) does not guarantee that: its OBJ importer makes one vertex per face corner (6 vertices for
// two triangles sharing an edge), and the usual cure, aiProcess_JoinIdenticalVertices, merges
// vertices that happen to coincide, which can differ from frame to frame. Its PLY and OFF
// importers keep the file's indexing today, but only as an implementation detail of one version.
// So PLY (ascii, binary little- and big-endian), OBJ and OFF are parsed here; any other extension
// goes through assimp without post-processing (which may split vertices, e.g. STL has no shared
// vertices at all) and must hold exactly one mesh.
#ifndef FINECAP_MESH_IO_H_
#define FINECAP_MESH_IO_H_

#include <string>

#include <Eigen/Core>

#include "finecap/geometry/mesh.h"

namespace finecap {

// Reads a triangle mesh. Vertices are kept exactly as stored: no merging, reordering or
// re-triangulation that would break a sequence's shared topology. A face with more than three
// corners is refused (triangulate the sequence once, the same way for every frame, beforehand):
// a triangulation chosen here could not be checked against the other frames'.
// Throws Error naming the file when it is missing, not a mesh, empty, truncated, has a polygon or
// a non-finite value, or fails Mesh::Validate.
Mesh ReadMesh(const std::string& path);

enum class MeshFormat { kPly, kObj };  // PLY is written binary little-endian.

// Optional per-vertex attributes of a written mesh; an empty member is not written.
struct VertexAttributes {
  Eigen::Matrix3Xd normals;  // Unit normals.
  Eigen::Matrix3Xd colors;   // RGB in [0, 1]; PLY stores uchar red/green/blue (clamped, rounded).
  Eigen::VectorXd quality;   // A scalar per vertex, e.g. the displacement k (PLY `float quality`;
                             // OBJ has no place for it and leaves it out).
};

// Writes atomically (see atomic_file.h): PLY with `double x, y, z` (so that reading back gives the
// same vertices), `float nx, ny, nz`, `uchar red, green, blue`, `float quality`, and faces as
// `list uchar int vertex_indices`; OBJ with `v x y z [r g b]`, `vn` and `f a//a b//b c//c`.
// Throws Error naming the file when the mesh fails Mesh::Validate, an attribute has not one column
// per vertex, or the file cannot be written.
void WriteMesh(const std::string& path, const Mesh& mesh, const VertexAttributes& attributes = {},
               MeshFormat format = MeshFormat::kPly);

}  // namespace finecap

#endif  // FINECAP_MESH_IO_H_
