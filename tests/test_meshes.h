// Small procedural meshes shared by the topology tests and benchmarks.
#ifndef FINECAP_TESTS_TEST_MESHES_H_
#define FINECAP_TESTS_TEST_MESHES_H_

#include <cmath>
#include <vector>

#include "finecap/geometry/mesh.h"

namespace finecap {
namespace testing_meshes {

// Vertex id of grid point (x, y) in a grid `columns` wide.
inline int GridId(int x, int y, int columns) { return y * columns + x; }

// A planar grid on z = 0 with unit spacing, vertex (x, y) at GridId(x, y). Each cell is split
// along its (x, y)-(x + 1, y + 1) diagonal, so every interior vertex has valence 6 with neighbours
// at offsets (+-1, 0), (0, +-1), (1, 1), (-1, -1). Triangles are counter-clockwise seen from +z.
inline Mesh GridMesh(int columns, int rows) {
  Mesh mesh;
  mesh.vertices.resize(3, columns * rows);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < columns; ++x) mesh.vertices.col(GridId(x, y, columns)) << x, y, 0.0;
  }
  mesh.faces.resize(3, 2 * (columns - 1) * (rows - 1));
  int f = 0;
  for (int y = 0; y + 1 < rows; ++y) {
    for (int x = 0; x + 1 < columns; ++x) {
      const int v00 = GridId(x, y, columns), v10 = GridId(x + 1, y, columns);
      const int v01 = GridId(x, y + 1, columns), v11 = GridId(x + 1, y + 1, columns);
      mesh.faces.col(f++) << v00, v10, v11;
      mesh.faces.col(f++) << v00, v11, v01;
    }
  }
  return mesh;
}

// The regular icosahedron with its 12 vertices on the unit sphere, triangles facing outwards.
inline Mesh Icosahedron() {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  Mesh mesh;
  mesh.vertices.resize(3, 12);
  mesh.vertices << -1, 1, -1, 1, 0, 0, 0, 0, p, p, -p, -p,  //
      p, p, -p, -p, -1, 1, -1, 1, 0, 0, 0, 0,               //
      0, 0, 0, 0, p, p, -p, -p, -1, 1, -1, 1;
  mesh.vertices.colwise().normalize();
  mesh.faces.resize(3, 20);
  mesh.faces << 0, 0, 0, 0, 0, 1, 5, 11, 10, 7, 3, 3, 3, 3, 3, 4, 2, 6, 8, 9,  //
      11, 5, 1, 7, 10, 5, 11, 10, 7, 1, 9, 4, 2, 6, 8, 9, 4, 2, 6, 8,          //
      5, 1, 7, 10, 11, 9, 4, 2, 6, 8, 4, 2, 6, 8, 9, 5, 11, 10, 7, 1;
  return mesh;
}

// An open cylinder (a skirt) around the z axis: `rings` circles of `segments` vertices from
// z = 0 to z = height, vertex (segment, ring) at ring * segments + segment, triangles facing out.
inline Mesh TubeMesh(int segments, int rings, double radius = 1.0, double height = 1.0) {
  Mesh mesh;
  mesh.vertices.resize(3, segments * rings);
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const double angle = 2.0 * M_PI * s / segments;
      mesh.vertices.col(r * segments + s) << radius * std::cos(angle), radius * std::sin(angle),
          height * r / (rings - 1);
    }
  }
  mesh.faces.resize(3, 2 * segments * (rings - 1));
  int f = 0;
  for (int r = 0; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const int a = r * segments + s, b = r * segments + (s + 1) % segments;
      const int c = a + segments, d = b + segments;
      mesh.faces.col(f++) << a, b, d;
      mesh.faces.col(f++) << a, d, c;
    }
  }
  return mesh;
}

// A latitude-longitude sphere: rings + 1 rows of `segments` vertices from pole to pole (each
// pole repeated `segments` times), without the zero-area triangles at the poles.
inline Mesh SphereMesh(const Eigen::Vector3d& center, double radius, int rings, int segments) {
  Mesh mesh;
  mesh.vertices.resize(3, (rings + 1) * segments);
  for (int i = 0; i <= rings; ++i) {
    const double theta = M_PI * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2.0 * M_PI * j / segments;
      mesh.vertices.col(i * segments + j) =
          center + radius * Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::cos(theta),
                                            std::sin(theta) * std::sin(phi));
    }
  }
  std::vector<Eigen::Vector3i> faces;
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = i * segments + j;
      const int b = i * segments + (j + 1) % segments;
      if (i > 0) faces.emplace_back(a, b, a + segments);
      if (i + 1 < rings) faces.emplace_back(b, b + segments, a + segments);
    }
  }
  mesh.faces.resize(3, faces.size());
  for (size_t f = 0; f < faces.size(); ++f) mesh.faces.col(f) = faces[f];
  return mesh;
}

// Root mean square over the vertices of the normal part of each vertex's uniform Laplacian (the
// mean of its neighbours minus the vertex): how bumpy a mesh is at the scale of its edges.
inline double Roughness(const Mesh& mesh) {
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(mesh);
  Eigen::Matrix3Xd sum = Eigen::Matrix3Xd::Zero(3, mesh.num_vertices());
  Eigen::VectorXd count = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int c = 0; c < 3; ++c) {
      // An interior edge is seen from both of its triangles, so its neighbours count twice.
      const int a = mesh.faces(c, f);
      const int b = mesh.faces((c + 1) % 3, f);
      sum.col(a) += mesh.vertices.col(b);
      sum.col(b) += mesh.vertices.col(a);
      count(a) += 1.0;
      count(b) += 1.0;
    }
  }
  double squares = 0.0;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (count(v) == 0.0) continue;
    const Eigen::Vector3d laplacian = sum.col(v) / count(v) - mesh.vertices.col(v);
    squares += std::pow(laplacian.dot(normals.col(v)), 2);
  }
  return std::sqrt(squares / mesh.num_vertices());
}

}  // namespace testing_meshes
}  // namespace finecap

#endif  // FINECAP_TESTS_TEST_MESHES_H_
