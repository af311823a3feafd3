#include "reference/objects.h"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <GeographicLib/LocalCartesian.hpp>

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace terravol::reference {

namespace {

std::uint8_t to_byte(double v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); }

// A model's triangles in its own frame, with float RGBA (0..1) per vertex.
struct Raw {
  std::vector<glm::dvec3> vertices;
  std::vector<glm::dvec4> colors;
  std::vector<std::uint32_t> triangles;
};

glm::dvec4 material_rgba(const aiMaterial* material) {
  aiColor4D c(0.6f, 0.6f, 0.6f, 1.0f);
  if (material != nullptr) {
    aiColor4D found;
    if (material->Get(AI_MATKEY_COLOR_DIFFUSE, found) == AI_SUCCESS || material->Get(AI_MATKEY_BASE_COLOR, found) == AI_SUCCESS) {
      c = found;
    }
    float opacity = 1.0f;
    if (material->Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS) c.a *= opacity;
  }
  return {c.r, c.g, c.b, c.a};
}

void collect(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent, Raw& raw) {
  const aiMatrix4x4 to_model = parent * node.mTransformation;
  for (unsigned k = 0; k < node.mNumMeshes; ++k) {
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[k]];
    const glm::dvec4 material =
        material_rgba(mesh.mMaterialIndex < scene.mNumMaterials ? scene.mMaterials[mesh.mMaterialIndex] : nullptr);
    const auto base = static_cast<std::uint32_t>(raw.vertices.size());
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D p = to_model * mesh.mVertices[v];
      raw.vertices.emplace_back(p.x, p.y, p.z);
      if (mesh.HasVertexColors(0)) {
        const aiColor4D& c = mesh.mColors[0][v];
        raw.colors.emplace_back(c.r, c.g, c.b, c.a * material.a);
      } else {
        raw.colors.push_back(material);
      }
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      for (unsigned c = 0; c < 3; ++c) raw.triangles.push_back(base + face.mIndices[c]);
    }
  }
  for (unsigned k = 0; k < node.mNumChildren; ++k) collect(scene, *node.mChildren[k], to_model, raw);
}

Raw read_raw(const std::filesystem::path& file) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file.string(), aiProcess_Triangulate);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error(file.string() + ": assimp cannot read it (" + importer.GetErrorString() + ")");
  }
  Raw raw;
  collect(*scene, *scene->mRootNode, aiMatrix4x4(), raw);
  if (raw.triangles.empty()) throw std::runtime_error(file.string() + ": no triangles");
  return raw;
}

}  // namespace

Mesh object(const ObjectStyle& style, const Frame& frame, const Dem* ground) {
  const Raw raw = read_raw(style.file);
  std::vector<glm::dvec3> body(raw.vertices.size());
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (std::size_t v = 0; v < body.size(); ++v) {
    const glm::dvec3& m = raw.vertices[v];
    body[v] = style.up_z ? m : glm::dvec3(-m.x, m.z, m.y);
    lo = glm::min(lo, body[v]);
    hi = glm::max(hi, body[v]);
  }
  const glm::dvec3 anchor(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), lo.z);

  double height = 0;
  if (style.height) {
    height = *style.height;
  } else {
    if (ground == nullptr) throw std::runtime_error(style.file.string() + ": placed above the ground, and no DEM was read");
    height = ground->height(style.lat, style.lon) + style.agl;
  }
  const GeographicLib::LocalCartesian enu(style.lat, style.lon, height);
  const double r = style.roll * M_PI / 180, p = style.pitch * M_PI / 180, h = style.heading * M_PI / 180;

  Mesh out;
  out.triangles = raw.triangles;
  out.vertices.reserve(body.size());
  out.colors.reserve(body.size());
  for (std::size_t v = 0; v < body.size(); ++v) {
    const glm::dvec3 b = (body[v] - anchor) * style.scale;
    // Roll about y: the right side (+x) goes down.
    const glm::dvec3 rolled(b.x * std::cos(r) + b.z * std::sin(r), b.y, -b.x * std::sin(r) + b.z * std::cos(r));
    // Pitch about x: the front (+y) goes up.
    const glm::dvec3 pitched(rolled.x, rolled.y * std::cos(p) - rolled.z * std::sin(p),
                             rolled.y * std::sin(p) + rolled.z * std::cos(p));
    // Heading about z, clockwise seen from above: the front (north) turns east.
    const double east = pitched.x * std::cos(h) + pitched.y * std::sin(h);
    const double north = -pitched.x * std::sin(h) + pitched.y * std::cos(h);
    double lat = 0, lon = 0, alt = 0;
    enu.Reverse(east, north, pitched.z, lat, lon, alt);
    out.vertices.push_back(frame.to_scene(lat, lon, alt));
    const glm::dvec4& c = raw.colors[v];
    out.colors.emplace_back(to_byte(c.r), to_byte(c.g), to_byte(c.b), to_byte(c.a * style.opacity));
  }
  return out;
}

}  // namespace terravol::reference
