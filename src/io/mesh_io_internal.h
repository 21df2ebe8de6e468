// The format-specific mesh readers and writers behind mesh_io.h (not part of the public API).
#ifndef FINECAP_SRC_MESH_IO_INTERNAL_H_
#define FINECAP_SRC_MESH_IO_INTERNAL_H_

#include <string>
#include <vector>

#include "finecap/geometry/mesh.h"
#include "finecap/io/mesh_io.h"

namespace finecap {
namespace internal {

// Collects vertices and triangles in file order, then builds the Mesh.
class MeshBuilder {
 public:
  explicit MeshBuilder(std::string path) : path_(std::move(path)) {}

  void AddVertex(double x, double y, double z);
  // `corners` are 0-based vertex ids; `where` locates the face in the file for error messages.
  // A face with other than three corners is refused.
  void AddFace(const std::vector<int>& corners, const std::string& where);
  int num_vertices() const { return static_cast<int>(coordinates_.size() / 3); }
  Mesh Build() const;

 private:
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
