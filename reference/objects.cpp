#include "reference/objects.h"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <GeographicLib/LocalCartesian.hpp>

#include <vtkImageData.h>
#include <vtkImageReader2.h>
#include <vtkImageReader2Factory.h>
#include <vtkJPEGReader.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
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

// A decoded texture: texel (x, y) at rgba[4 * (y * width + x)], y = 0 the image's bottom row
// (where texture coordinate v = 0 is, in assimp's convention).
struct Image {
  int width = 0, height = 0;
  std::vector<double> rgba;  // 0..1
};

// The material's diffuse or base-colour texture, decoded by VTK's reader for its kind (PNG or
// JPEG bytes embedded in the file, or a file beside the model); empty when there is none or it
// cannot be read. `uv` is the texture-coordinate set it names.
std::optional<Image> texture_of(const aiScene& scene, const aiMaterial* material, const std::filesystem::path& model, unsigned& uv) {
  aiString name;
  uv = 0;
  if (material == nullptr) return std::nullopt;
  bool found = false;
  for (const aiTextureType type : {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}) {
    if (!found && material->GetTexture(type, 0, &name, nullptr, &uv) == AI_SUCCESS) found = true;
  }
  if (!found) return std::nullopt;
  vtkSmartPointer<vtkImageReader2> reader;
  if (const aiTexture* inside = scene.GetEmbeddedTexture(name.C_Str())) {
    if (inside->mHeight != 0) return std::nullopt;  // raw texels: no test model has them
    const std::string kind = inside->achFormatHint;
    if (kind == "png") reader = vtkSmartPointer<vtkPNGReader>::New();
    else if (kind == "jpg" || kind == "jpeg") reader = vtkSmartPointer<vtkJPEGReader>::New();
    else return std::nullopt;
    reader->SetMemoryBuffer(inside->pcData);
    reader->SetMemoryBufferLength(inside->mWidth);
  } else {
    std::string relative = name.C_Str();
    std::replace(relative.begin(), relative.end(), '\\', '/');
    const std::string file = (model.parent_path() / relative).string();
    reader.TakeReference(vtkImageReader2Factory::CreateImageReader2(file.c_str()));
    if (!reader) return std::nullopt;
    reader->SetFileName(file.c_str());
  }
  reader->Update();
  vtkImageData* data = reader->GetOutput();
  Image image;
  image.width = data->GetDimensions()[0];
  image.height = data->GetDimensions()[1];
  const int n = data->GetNumberOfScalarComponents();
  const double scale = data->GetScalarType() == VTK_UNSIGNED_SHORT ? 65535.0 : 255.0;
  image.rgba.resize(4 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height));
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      double c[4];
      for (int k = 0; k < 4; ++k) c[k] = k < n ? data->GetScalarComponentAsDouble(x, y, 0, k) / scale : 1.0;
      double* out = &image.rgba[4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(x))];
      if (n <= 2) {  // grey, with alpha when two
        out[0] = out[1] = out[2] = c[0];
        out[3] = n == 2 ? c[1] : 1.0;
      } else {
        for (int k = 0; k < 4; ++k) out[k] = k < n ? c[k] : 1.0;
      }
    }
  return image;
}

// The texture at (u, v): the four texels around the point weighted by their distance to it
// (texel centres at half-integers), indices wrapping around both ways.
glm::dvec4 sampled(const Image& image, double u, double v) {
  const double px = u * image.width - 0.5, py = v * image.height - 0.5;
  const double x0 = std::floor(px), y0 = std::floor(py);
  glm::dvec4 sum(0.0);
  for (const double yy : {y0, y0 + 1.0})
    for (const double xx : {x0, x0 + 1.0}) {
      const double weight = (1.0 - std::abs(px - xx)) * (1.0 - std::abs(py - yy));
      const auto xi = static_cast<std::size_t>(std::fmod(std::fmod(xx, image.width) + image.width, image.width));
      const auto yi = static_cast<std::size_t>(std::fmod(std::fmod(yy, image.height) + image.height, image.height));
      const double* texel = &image.rgba[4 * (yi * static_cast<std::size_t>(image.width) + xi)];
      sum += weight * glm::dvec4(texel[0], texel[1], texel[2], texel[3]);
    }
  return sum;
}

glm::dvec4 material_rgba(const aiMaterial* material, bool textured) {
  // Without a colour of its own a material is assimp's grey, or white (glTF's factor 1) when
  // it has a texture.
  const float grey = textured ? 1.0f : 0.6f;
  aiColor4D c(grey, grey, grey, 1.0f);
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

void collect(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent, const std::filesystem::path& file, Raw& raw) {
  const aiMatrix4x4 to_model = parent * node.mTransformation;
  for (unsigned k = 0; k < node.mNumMeshes; ++k) {
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[k]];
    const aiMaterial* material_of = mesh.mMaterialIndex < scene.mNumMaterials ? scene.mMaterials[mesh.mMaterialIndex] : nullptr;
    unsigned uv = 0;
    std::optional<Image> texture = texture_of(scene, material_of, file, uv);
    if (texture && !mesh.HasTextureCoords(uv)) texture.reset();
    const glm::dvec4 material = material_rgba(material_of, texture.has_value());
    // A mesh's vertices with the same position and colour (to the byte) are one
    // (docs/scene-file.md: the model's normals are not read, and its texture coordinates only
    // give the colours), which decides where its surface is smooth for the sunlight below.
    std::map<std::array<double, 7>, std::uint32_t> welded;
    std::vector<std::uint32_t> index(mesh.mNumVertices);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& m = mesh.mVertices[v];
      glm::dvec4 color = material;
      if (mesh.HasVertexColors(0)) {
        const aiColor4D c = mesh.mColors[0][v];
        color = {c.r, c.g, c.b, c.a * material.a};
      }
      if (texture) color *= sampled(*texture, mesh.mTextureCoords[uv][v].x, mesh.mTextureCoords[uv][v].y);
      const std::array<double, 7> key{m.x, m.y, m.z, static_cast<double>(to_byte(color.r)), static_cast<double>(to_byte(color.g)),
                                      static_cast<double>(to_byte(color.b)), static_cast<double>(to_byte(color.a))};
      const auto [at, fresh] = welded.try_emplace(key, static_cast<std::uint32_t>(raw.vertices.size()));
      index[v] = at->second;
      if (!fresh) continue;
      const aiVector3D p = to_model * m;
      raw.vertices.emplace_back(p.x, p.y, p.z);
      raw.colors.push_back(color);
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      const std::uint32_t a = index[face.mIndices[0]], b = index[face.mIndices[1]], c = index[face.mIndices[2]];
      if (a == b || b == c || a == c) continue;  // collapsed by the weld
      for (const std::uint32_t corner : {a, b, c}) raw.triangles.push_back(corner);
    }
  }
  for (unsigned k = 0; k < node.mNumChildren; ++k) collect(scene, *node.mChildren[k], to_model, file, raw);
}

Raw read_raw(const std::filesystem::path& file) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file.string(), aiProcess_Triangulate);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error(file.string() + ": assimp cannot read it (" + importer.GetErrorString() + ")");
  }
  Raw raw;
  collect(*scene, *scene->mRootNode, aiMatrix4x4(), file, raw);
  if (raw.triangles.empty()) throw std::runtime_error(file.string() + ": no triangles");
  return raw;
}

// Vertex normals as objects::sunlit is specified to make them (vtkPolyDataNormals with
// splitting at kFeatureAngle), written again here: around each vertex its triangles are joined
// across the edges they share through it where their normals differ by at most the feature
// angle; each group's normal is the normalised sum of its triangles' unit normals. Returns
// the mesh with a vertex per (vertex, group) and each triangle's corners renumbered.
constexpr double kFeatureAngleDeg = 40.0;

struct Lit {
  std::vector<glm::dvec3> vertices, normals;
  std::vector<std::size_t> source;  // the input vertex of each
  std::vector<std::uint32_t> triangles;
};

Lit split_normals(const std::vector<glm::dvec3>& vertices, const std::vector<std::uint32_t>& triangles) {
  const std::size_t nt = triangles.size() / 3;
  std::vector<glm::dvec3> face(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const glm::dvec3 a = vertices[triangles[3 * t]], b = vertices[triangles[3 * t + 1]], c = vertices[triangles[3 * t + 2]];
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double len = glm::length(n);
    face[t] = len > 0 ? n / len : glm::dvec3(0);
  }
  std::vector<std::vector<std::size_t>> around(vertices.size());
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) around[triangles[3 * t + static_cast<std::size_t>(k)]].push_back(t);
  const double smooth = std::cos(kFeatureAngleDeg * M_PI / 180.0);
  Lit out;
  out.triangles = triangles;
  std::vector<std::size_t> group;
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    const std::vector<std::size_t>& ts = around[v];
    // Union-find over the triangles around v.
    std::vector<std::size_t> parent(ts.size());
    for (std::size_t i = 0; i < ts.size(); ++i) parent[i] = i;
    const auto root = [&](std::size_t i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    const auto other_corners = [&](std::size_t t, std::uint32_t out2[2]) {
      int n = 0;
      for (int k = 0; k < 3; ++k)
        if (triangles[3 * t + static_cast<std::size_t>(k)] != v && n < 2) out2[n++] = triangles[3 * t + static_cast<std::size_t>(k)];
    };
    for (std::size_t i = 0; i < ts.size(); ++i) {
      std::uint32_t a[2];
      other_corners(ts[i], a);
      for (std::size_t j = i + 1; j < ts.size(); ++j) {
        std::uint32_t b[2];
        other_corners(ts[j], b);
        const bool share = a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1];
        if (share && glm::dot(face[ts[i]], face[ts[j]]) >= smooth) parent[root(i)] = root(j);
      }
    }
    group.assign(ts.size(), static_cast<std::size_t>(-1));
    for (std::size_t i = 0; i < ts.size(); ++i) {
      const std::size_t r = root(i);
      if (group[r] == static_cast<std::size_t>(-1)) {
        group[r] = out.vertices.size();
        out.vertices.push_back(vertices[v]);
        out.normals.emplace_back(0.0);
        out.source.push_back(v);
      }
      const std::size_t g = group[r];
      out.normals[g] += face[ts[i]];
      for (int k = 0; k < 3; ++k) {
        std::uint32_t& corner = out.triangles[3 * ts[i] + static_cast<std::size_t>(k)];
        if (triangles[3 * ts[i] + static_cast<std::size_t>(k)] == v) corner = static_cast<std::uint32_t>(g);
      }
    }
  }
  for (glm::dvec3& n : out.normals) {
    const double len = glm::length(n);
    if (len > 0) n /= len;
  }
  return out;
}

}  // namespace

Mesh object(const ObjectStyle& style, const Sun& sun, const Frame& frame, const Dem* ground) {
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

  std::vector<glm::dvec3> placed;
  placed.reserve(body.size());
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
    placed.push_back(frame.to_scene(lat, lon, alt));
  }

  // Sunlight, two-sided, as the terrain's hillshade: 1 on a face turned up, at most 1.3.
  const Lit lit = split_normals(placed, raw.triangles);
  const double az = sun.azimuth_deg * M_PI / 180, el = sun.elevation_deg * M_PI / 180;
  const glm::dvec3 towards(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
  Mesh out;
  out.vertices = lit.vertices;
  out.triangles = lit.triangles;
  for (std::size_t v = 0; v < lit.vertices.size(); ++v) {
    const double s = std::min(sun.ambient + (1 - sun.ambient) * std::abs(glm::dot(lit.normals[v], towards)) / std::sin(el), 1.3);
    const glm::dvec4& c = raw.colors[lit.source[v]];
    // The model's colour to bytes first, then lit (the renderer lights the bytes it placed).
    const auto lit_byte = [&](double x) { return static_cast<std::uint8_t>(std::min(std::lround(to_byte(x) * s), 255L)); };
    out.colors.emplace_back(lit_byte(c.r), lit_byte(c.g), lit_byte(c.b), to_byte(c.a * style.opacity));
  }
  return out;
}

}  // namespace terravol::reference
