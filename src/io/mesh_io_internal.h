// The format-specific mesh readers and writers behind mesh_io.h (not part of the public API).
#ifndef FINECAP_SRC_MESH_IO_INTERNAL_H_
#define FINECAP_SRC_MESH_IO_INTERNAL_H_

#include <string>
#include <vector>

#include "finecap/geometry/mesh.h"
#include "finecap/io/mesh_io.h"
#include "finecap/util/error.h"

namespace finecap {
namespace internal {

// Collects vertices and triangles in file order, then builds the Mesh.
class MeshBuilder {
 public:
  explicit MeshBuilder(std::string path) : path_(std::move(path)) {}

  void AddVertex(double x, double y, double z);
  // `corners` are 0-based vertex ids. A face with other than three corners is refused, in an
  // error located by `where()` (the face's place in the file), which is called only then: a
  // string built for each of a mesh's faces would cost more than reading them.
  template <typename Where>
  void AddFace(const std::vector<int>& corners, const Where& where) {
    if (corners.size() != 3) throw Error(where(), NonTriangleProblem(corners.size()));
    corners_.insert(corners_.end(), corners.begin(), corners.end());
  }
  int num_vertices() const { return static_cast<int>(coordinates_.size() / 3); }
  Mesh Build() const;

 private:
  static std::string NonTriangleProblem(size_t num_corners);

  std::string path_;
  std::vector<double> coordinates_;
  std::vector<int> corners_;
};

// Each parses `contents`, the whole file at `path` (named in errors).
Mesh ParsePly(const std::string& contents, const std::string& path);
Mesh ParseObj(const std::string& contents, const std::string& path);
Mesh ParseOff(const std::string& contents, const std::string& path);

// The whole file's contents.
std::string FormatPly(const Mesh& mesh, const VertexAttributes& attributes);
std::string FormatObj(const Mesh& mesh, const VertexAttributes& attributes);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_MESH_IO_INTERNAL_H_
