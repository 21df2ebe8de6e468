// A triangle mesh: the coarse input surface of one frame, or a refined one. Every frame of a
// sequence shares one connectivity (`faces`); only `vertices` change over time.
#ifndef FINECAP_GEOMETRY_MESH_H_
#define FINECAP_GEOMETRY_MESH_H_

#include <string>

#include <Eigen/Core>

namespace finecap {

struct Mesh {
  Eigen::Matrix3Xd vertices;  // One column per vertex, metres.
  Eigen::Matrix3Xi faces;     // One column per triangle, counter-clockwise seen from outside.

  int num_vertices() const { return static_cast<int>(vertices.cols()); }
  int num_faces() const { return static_cast<int>(faces.cols()); }

  // Throws Error(where, ...) when the mesh has no faces, a face index out of range, a face that
  // repeats a vertex, or a non-finite vertex coordinate.
  void Validate(const std::string& where) const;
};

// Unit vertex normals, each the area-weighted mean of the normals of the faces around the vertex.
// A vertex that belongs to no face (or only to degenerate ones) gets a zero normal.
Eigen::Matrix3Xd ComputeVertexNormals(const Mesh& mesh);

// True when both meshes have the same number of vertices and identical faces.
bool HasSameTopology(const Mesh& a, const Mesh& b);

// Throws Error(where, ...) naming what differs unless `frame` has the topology of `reference`.
void RequireSameTopology(const Mesh& reference, const Mesh& frame, const std::string& where);

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_MESH_H_
