#include "finecap/io/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "io/mesh_io_internal.h"
#include "util/io_util.h"

namespace finecap {
namespace internal {

void MeshBuilder::AddVertex(double x, double y, double z) {
  coordinates_.insert(coordinates_.end(), {x, y, z});
}

std::string MeshBuilder::NonTriangleProblem(size_t num_corners) {
  return "a face with " + std::to_string(num_corners) +
         " corners: only triangles are read (triangulate the sequence beforehand, the same way "
         "in every frame)";
}

Mesh MeshBuilder::Build() const {
  Mesh mesh;
  mesh.vertices = Eigen::Map<const Eigen::Matrix3Xd>(coordinates_.data(), 3, num_vertices());
  mesh.faces = Eigen::Map<const Eigen::Matrix3Xi>(corners_.data(), 3, corners_.size() / 3);
  mesh.Validate(path_);
  return mesh;
}

}  // namespace internal

namespace {

std::string LowerCaseExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// The transform from the one mesh's frame to the scene's: the product along the path of nodes
// to the node that holds it. False when the mesh is not held by exactly one node.
bool FindMeshTransform(const aiNode* node, const aiMatrix4x4& parent, aiMatrix4x4* transform,
                       int* holders) {
  const aiMatrix4x4 here = parent * node->mTransformation;
  if (node->mNumMeshes > 0) {
    *holders += static_cast<int>(node->mNumMeshes);
    *transform = here;
  }
  for (unsigned int i = 0; i < node->mNumChildren; ++i) {
    FindMeshTransform(node->mChildren[i], here, transform, holders);
  }
  return *holders == 1;
}

// Any format assimp knows, read without post-processing so its vertices stay as imported.
Mesh ReadWithAssimp(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
  Require(scene != nullptr && scene->mRootNode != nullptr, path,
          std::string("not a mesh file that can be read: ") + importer.GetErrorString());
  Require(scene->mNumMeshes == 1, path,
          "holds " + std::to_string(scene->mNumMeshes) + " meshes; exactly one is needed");
  aiMatrix4x4 transform;
  int holders = 0;
  Require(FindMeshTransform(scene->mRootNode, aiMatrix4x4(), &transform, &holders), path,
          "its mesh must be placed exactly once in the scene");
  const aiMesh* source = scene->mMeshes[0];
  internal::MeshBuilder builder(path);
  for (unsigned int v = 0; v < source->mNumVertices; ++v) {
    const aiVector3D p = transform * source->mVertices[v];
    builder.AddVertex(p.x, p.y, p.z);
  }
  for (unsigned int f = 0; f < source->mNumFaces; ++f) {
    const aiFace& face = source->mFaces[f];
    builder.AddFace(std::vector<int>(face.mIndices, face.mIndices + face.mNumIndices),
                    [&] { return path + " (face " + std::to_string(f) + ")"; });
  }
  return builder.Build();
}

void RequirePerVertex(Eigen::Index columns, const Mesh& mesh, const std::string& what,
                      const std::string& path) {
  Require(columns == 0 || columns == mesh.num_vertices(), path,
          what + " has " + std::to_string(columns) + " entries for " +
              std::to_string(mesh.num_vertices()) + " vertices");
}

}  // namespace

Mesh ReadMesh(const std::string& path) {
  const std::string extension = LowerCaseExtension(path);
  if (extension != ".ply" && extension != ".obj" && extension != ".off") {
    internal::RequireFile(path);
    return ReadWithAssimp(path);
  }
  const std::string contents = internal::ReadWholeFile(path);
  if (extension == ".ply") return internal::ParsePly(contents, path);
  if (extension == ".obj") return internal::ParseObj(contents, path);
  return internal::ParseOff(contents, path);
}

void WriteMesh(const std::string& path, const Mesh& mesh, const VertexAttributes& attributes,
               MeshFormat format) {
  mesh.Validate(path);
  RequirePerVertex(attributes.normals.cols(), mesh, "the normal matrix", path);
  RequirePerVertex(attributes.colors.cols(), mesh, "the colour matrix", path);
  RequirePerVertex(attributes.quality.size(), mesh, "the quality vector", path);
  WriteTextFileAtomically(path, format == MeshFormat::kPly ? internal::FormatPly(mesh, attributes)
                                                           : internal::FormatObj(mesh, attributes));
}

}  // namespace finecap
