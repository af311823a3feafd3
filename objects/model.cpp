#include "objects/model.h"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <system_error>

#include "io/error.h"

namespace terravol::objects {

namespace {

std::uint8_t byte_of(float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

// The material's colour and opacity: its diffuse colour, else its glTF base colour, else
// assimp's default grey (0.6); alpha the colour's times the opacity.
aiColor4D material_color(const aiMaterial* m) {
  aiColor4D c(0.6f, 0.6f, 0.6f, 1.0f);
  if (m == nullptr) return c;
  if (m->Get(AI_MATKEY_COLOR_DIFFUSE, c) != AI_SUCCESS) m->Get(AI_MATKEY_BASE_COLOR, c);
  float opacity = 1.0f;
  if (m->Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS) c.a *= opacity;
  return c;
}

// One line: assimp's messages may hold newlines.
std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s.empty() ? "assimp could not read it" : s;
}

struct Collector {
  const aiScene* scene;
  const std::string& source;
  Model& model;

  void node(const aiNode* n, const aiMatrix4x4& parent) {
    const aiMatrix4x4 m = parent * n->mTransformation;
    for (unsigned k = 0; k < n->mNumMeshes; ++k) mesh(scene->mMeshes[n->mMeshes[k]], m);
    for (unsigned k = 0; k < n->mNumChildren; ++k) node(n->mChildren[k], m);
  }

  void mesh(const aiMesh* a, const aiMatrix4x4& m) {
    if ((a->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) return;
    volume::Mesh& out = model.mesh;
    const std::size_t base = out.vertices.size();
    const aiColor4D mc = material_color(a->mMaterialIndex < scene->mNumMaterials ? scene->mMaterials[a->mMaterialIndex] : nullptr);
    const bool per_vertex = a->HasVertexColors(0);
    model.vertex_colors = model.vertex_colors || per_vertex;
    std::size_t faces = 0;
    for (unsigned f = 0; f < a->mNumFaces; ++f) faces += a->mFaces[f].mNumIndices == 3 ? 1 : 0;
    if (faces == 0) return;
    if (out.triangle_count() + faces > kMaxModelTriangles) {
      throw io::FormatError(source, "more than " + std::to_string(kMaxModelTriangles) + " triangles; too large to place");
    }
    for (unsigned v = 0; v < a->mNumVertices; ++v) {
      const aiVector3D p = m * a->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw io::FormatError(source, "vertex " + std::to_string(v) + " of mesh '" + a->mName.C_Str() + "' is not finite");
      }
      out.vertices.emplace_back(p.x, p.y, p.z);
      const aiColor4D c = per_vertex ? a->mColors[0][v] : mc;
      out.colors.emplace_back(byte_of(c.r), byte_of(c.g), byte_of(c.b), byte_of(per_vertex ? c.a * mc.a : c.a));
    }
    for (unsigned f = 0; f < a->mNumFaces; ++f) {
      const aiFace& face = a->mFaces[f];
      if (face.mNumIndices != 3) continue;
      const unsigned i = face.mIndices[0], j = face.mIndices[1], k = face.mIndices[2];
      if (i == j || j == k || i == k) continue;
      for (const unsigned x : {i, j, k}) out.triangles.push_back(static_cast<std::uint32_t>(base + x));
    }
    ++model.meshes;
  }
};

}  // namespace

Model read_model(const std::filesystem::path& file) {
  const std::string source = file.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    throw io::FormatError(source, std::filesystem::exists(file, ec) ? "not a regular file" : "no such file");
  }
  const std::uintmax_t bytes = std::filesystem::file_size(file, ec);
  if (ec) throw io::FormatError(source, "cannot read (" + ec.message() + ")");
  if (bytes > kMaxModelBytes) throw io::FormatError(source, "larger than 1 GiB; too large for a model");
  if (bytes == 0) throw io::FormatError(source, "empty file");

  Assimp::Importer importer;
  // Normals, texture coordinates and the rest are not used: removed first, so that joining
  // identical vertices joins by position and colour.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                          aiComponent_TEXCOORDS | aiComponent_BONEWEIGHTS |
                                                          aiComponent_ANIMATIONS | aiComponent_CAMERAS |
                                                          aiComponent_LIGHTS | aiComponent_TEXTURES);
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(source, 0);
    if (scene != nullptr) {
      // Counted before the post-processing, which would take long on an absurd model: a polygon
      // of n vertices becomes n - 2 triangles.
      std::size_t triangles = 0;
      for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
        for (unsigned f = 0; f < scene->mMeshes[k]->mNumFaces; ++f) {
          triangles += std::max(scene->mMeshes[k]->mFaces[f].mNumIndices, 2u) - 2;
        }
      }
      if (triangles == 0) throw io::FormatError(source, "no triangles in the model");
      if (triangles > kMaxModelTriangles) {
        throw io::FormatError(source, std::to_string(triangles) + " triangles, more than " +
                                          std::to_string(kMaxModelTriangles) + "; too large to place");
      }
      scene = importer.ApplyPostProcessing(aiProcess_RemoveComponent | aiProcess_Triangulate | aiProcess_SortByPType |
                                           aiProcess_JoinIdenticalVertices | aiProcess_ValidateDataStructure);
    }
  } catch (const io::FormatError&) {
    throw;
  } catch (const std::exception& e) {
    throw io::FormatError(source, one_line(e.what()));
  }
  if (scene == nullptr) throw io::FormatError(source, one_line(importer.GetErrorString()));
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mRootNode == nullptr) {
    throw io::FormatError(source, "incomplete model (no scene graph)");
  }
  Model model;
  model.file = file;
  Collector{scene, source, model}.node(scene->mRootNode, aiMatrix4x4());
  if (model.mesh.empty()) throw io::FormatError(source, "no triangles in the model");
  return model;
}

}  // namespace terravol::objects
