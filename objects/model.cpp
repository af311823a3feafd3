#include "objects/model.h"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <vtkImageData.h>
#include <vtkImageReader2.h>
#include <vtkImageReader2Factory.h>
#include <vtkJPEGReader.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <system_error>
#include <unordered_map>

#include "io/error.h"
#include "volume/isolated.h"
#include "volume/vtk_smp.h"

namespace terravol::objects {

namespace {

std::uint8_t byte_of(float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

// The material's colour and opacity: its diffuse colour, else its glTF base colour, else
// assimp's default grey (0.6), or white when the material has a texture; alpha the colour's times
// the opacity.
aiColor4D material_color(const aiMaterial* m, bool textured) {
  const float grey = textured ? 1.0f : 0.6f;  // a textured material's colour factor is 1 by default (glTF)
  aiColor4D c(grey, grey, grey, 1.0f);
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

// A texture as RGBA bytes, row 0 at the bottom (VTK's order and assimp's: texture coordinate
// v = 0 is the image's last row).
struct Texture {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;

  // Bilinear, repeating (glTF's default sampler, and OBJ's), 0..1 per channel.
  std::array<float, 4> sample(float u, float v) const {
    const float x = u * static_cast<float>(width) - 0.5f, y = v * static_cast<float>(height) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const float ax = x - fx, ay = y - fy;
    const auto wrap = [](long i, int n) { return static_cast<std::size_t>(((i % n) + n) % n); };
    const long x0 = static_cast<long>(fx), y0 = static_cast<long>(fy);
    std::array<float, 4> out{};
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const float w = (dx ? ax : 1.0f - ax) * (dy ? ay : 1.0f - ay);
        const std::size_t at = 4 * (wrap(y0 + dy, height) * static_cast<std::size_t>(width) + wrap(x0 + dx, width));
        for (int c = 0; c < 4; ++c) out[static_cast<std::size_t>(c)] += w * static_cast<float>(rgba[at + static_cast<std::size_t>(c)]) / 255.0f;
      }
    return out;
  }
};

// The image a VTK reader decodes, as RGBA bytes (grey, grey and alpha, RGB or RGBA; 8 or 16
// bits), in an isolated child process (volume/isolated.h): VTK's PNG reader crashes the process
// on a truncated file (libpng's error jumps out of it), so a bad texture must cost only the
// child. `make` builds the reader in the child. Empty when it reads nothing or the child fails.
// Throws for more than kMaxTexturePixels pixels, checked from the header before the pixels are
// read.
std::optional<Texture> decode(const std::function<vtkSmartPointer<vtkImageReader2>()>& make, const std::string& source,
                              const std::string& name) {
  static std::mutex vtk;  // one child at a time: no other thread of ours inside VTK's readers when it forks
  const std::lock_guard<std::mutex> lock(vtk);
  const volume::detail::IsolatedRun run = volume::detail::run_isolated(
      [&]() -> std::string {
        volume::detail::use_sequential_vtk_smp();  // no TBB in the child
        vtkSmartPointer<vtkImageReader2> reader = make();
        if (!reader) return "none";
        reader->UpdateInformation();
        const int* extent = reader->GetDataExtent();
        const std::int64_t w = std::int64_t{extent[1]} - extent[0] + 1, h = std::int64_t{extent[3]} - extent[2] + 1;
        if (w <= 0 || h <= 0) return "none";
        if (static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h) > kMaxTexturePixels) {
          return "large " + std::to_string(w) + "x" + std::to_string(h);
        }
        reader->Update();
        vtkImageData* image = reader->GetOutput();
        const int* dims = image->GetDimensions();
        const int n = image->GetNumberOfScalarComponents();
        const int type = image->GetScalarType();
        if (dims[0] != w || dims[1] != h || n < 1 || n > 4 || (type != VTK_UNSIGNED_CHAR && type != VTK_UNSIGNED_SHORT)) return "none";
        const std::size_t pixels = static_cast<std::size_t>(w * h);
        std::string out = "rgba " + std::to_string(w) + " " + std::to_string(h) + "\n";
        const std::size_t header = out.size();
        out.resize(header + 4 * pixels);
        const void* data = image->GetScalarPointer();
        for (std::size_t p = 0; p < pixels; ++p) {
          std::array<std::uint8_t, 4> in{0, 0, 0, 255};
          for (int c = 0; c < n; ++c) {
            const std::size_t at = p * static_cast<std::size_t>(n) + static_cast<std::size_t>(c);
            in[static_cast<std::size_t>(c)] = type == VTK_UNSIGNED_CHAR ? static_cast<const std::uint8_t*>(data)[at]
                                                                        : static_cast<std::uint8_t>(static_cast<const std::uint16_t*>(data)[at] >> 8);
          }
          const bool grey = n <= 2;
          const std::array<std::uint8_t, 4> rgba{in[0], grey ? in[0] : in[1], grey ? in[0] : in[2],
                                                 n == 2 ? in[1] : n == 4 ? in[3] : std::uint8_t{255}};
          std::memcpy(out.data() + header + 4 * p, rgba.data(), 4);
        }
        return out;
      },
      // Room for the decoded image and its RGBA copy at the largest size allowed.
      std::size_t{9} * kMaxTexturePixels + (std::size_t{512} << 20), 120.0);
  if (!run.ok) return std::nullopt;
  const std::string& out = run.output;
  if (out.rfind("large ", 0) == 0) {
    throw io::FormatError(source, "texture '" + name + "' is " + out.substr(6) + " pixels, more than 16384x16384");
  }
  Texture t;
  const std::size_t eol = out.find('\n');
  if (out.rfind("rgba ", 0) != 0 || eol == std::string::npos ||
      std::sscanf(out.c_str() + 5, "%d %d", &t.width, &t.height) != 2 || t.width <= 0 || t.height <= 0 ||
      out.size() != eol + 1 + 4 * static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height)) {
    return std::nullopt;
  }
  t.rgba.assign(out.begin() + static_cast<std::ptrdiff_t>(eol + 1), out.end());
  return t;
}

// The material's diffuse (or glTF base-colour) texture and the texture-coordinate set it uses:
// embedded in the file (compressed PNG or JPEG, or raw texels), or a file beside the model.
// Empty when the material names none; `missing` gets the name of one that cannot be read.
std::optional<Texture> material_texture(const aiScene& scene, const aiMaterial& m, const std::filesystem::path& model,
                                        const std::string& source, unsigned& channel, std::vector<std::string>& missing) {
  aiString path;
  channel = 0;
  if (m.GetTexture(aiTextureType_BASE_COLOR, 0, &path, nullptr, &channel) != AI_SUCCESS &&
      m.GetTexture(aiTextureType_DIFFUSE, 0, &path, nullptr, &channel) != AI_SUCCESS) {
    return std::nullopt;
  }
  const std::string name = path.C_Str();
  std::optional<Texture> texture;
  if (const aiTexture* embedded = scene.GetEmbeddedTexture(path.C_Str())) {
    if (embedded->mHeight == 0) {  // a compressed file in memory, mWidth bytes
      const std::string hint = embedded->achFormatHint;
      texture = decode(
          [&]() -> vtkSmartPointer<vtkImageReader2> {
            vtkSmartPointer<vtkImageReader2> reader;
            if (hint == "png") reader = vtkSmartPointer<vtkPNGReader>::New();
            if (hint == "jpg" || hint == "jpeg") reader = vtkSmartPointer<vtkJPEGReader>::New();
            if (reader) {
              reader->SetMemoryBuffer(embedded->pcData);
              reader->SetMemoryBufferLength(embedded->mWidth);
            }
            return reader;
          },
          source, name);
    } else if (static_cast<std::uint64_t>(embedded->mWidth) * embedded->mHeight <= kMaxTexturePixels) {
      // Raw texels, the first row at the top.
      Texture t;
      t.width = static_cast<int>(embedded->mWidth);
      t.height = static_cast<int>(embedded->mHeight);
      t.rgba.resize(4 * static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height));
      for (int y = 0; y < t.height; ++y)
        for (int x = 0; x < t.width; ++x) {
          const aiTexel& texel = embedded->pcData[static_cast<std::size_t>(t.height - 1 - y) * static_cast<std::size_t>(t.width) + static_cast<std::size_t>(x)];
          const std::size_t at = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(t.width) + static_cast<std::size_t>(x));
          t.rgba[at] = texel.r;
          t.rgba[at + 1] = texel.g;
          t.rgba[at + 2] = texel.b;
          t.rgba[at + 3] = texel.a;
        }
      texture = std::move(t);
    }
  } else {
    std::string relative = name;
    std::replace(relative.begin(), relative.end(), '\\', '/');
    const std::filesystem::path file = model.parent_path() / relative;
    std::error_code ec;
    if (std::filesystem::is_regular_file(file, ec)) {
      texture = decode(
          [&]() -> vtkSmartPointer<vtkImageReader2> {
            vtkSmartPointer<vtkImageReader2> reader;
            reader.TakeReference(vtkImageReader2Factory::CreateImageReader2(file.string().c_str()));
            if (reader) reader->SetFileName(file.string().c_str());
            return reader;
          },
          source, name);
    }
  }
  if (!texture && std::find(missing.begin(), missing.end(), name) == missing.end()) missing.push_back(name);
  return texture;
}

// A vertex of a mesh as the weld sees it: the bits of the position's floats (as the file gives
// them) and the colour's bytes.
struct WeldKey {
  std::array<std::uint32_t, 4> bits;
  bool operator==(const WeldKey&) const = default;
  struct Hash {
    std::size_t operator()(const WeldKey& k) const {
      std::uint64_t h = 0x9E3779B97F4A7C15ull;
      for (const std::uint32_t b : k.bits) h = (h ^ b) * 0xBF58476D1CE4E5B9ull;
      return static_cast<std::size_t>(h ^ (h >> 31));
    }
  };
};

struct Collector {
  const aiScene* scene;
  const std::string& source;
  Model& model;
  // Each material's texture and its coordinate set, decoded once for every mesh (and every
  // node placing a mesh) that uses the material.
  struct MaterialTexture {
    std::optional<Texture> texture;
    unsigned channel = 0;
  };
  std::unordered_map<unsigned, MaterialTexture> textures;

  const MaterialTexture& texture_of(unsigned index, const aiMaterial& material) {
    const auto [it, fresh] = textures.try_emplace(index);
    if (fresh) it->second.texture = material_texture(*scene, material, model.file, source, it->second.channel, model.missing_textures);
    return it->second;
  }

  void node(const aiNode* n, const aiMatrix4x4& parent) {
    const aiMatrix4x4 m = parent * n->mTransformation;
    for (unsigned k = 0; k < n->mNumMeshes; ++k) mesh(scene->mMeshes[n->mMeshes[k]], m);
    for (unsigned k = 0; k < n->mNumChildren; ++k) node(n->mChildren[k], m);
  }

  void mesh(const aiMesh* a, const aiMatrix4x4& m) {
    if ((a->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) return;
    volume::Mesh& out = model.mesh;
    const aiMaterial* material = a->mMaterialIndex < scene->mNumMaterials ? scene->mMaterials[a->mMaterialIndex] : nullptr;
    const bool per_vertex = a->HasVertexColors(0);
    model.vertex_colors = model.vertex_colors || per_vertex;
    const MaterialTexture* mt = material != nullptr ? &texture_of(a->mMaterialIndex, *material) : nullptr;
    const Texture* texture = mt != nullptr && mt->texture && a->HasTextureCoords(mt->channel) ? &*mt->texture : nullptr;
    const unsigned channel = texture != nullptr ? mt->channel : 0;
    if (texture != nullptr) ++model.textured_meshes;
    const aiColor4D mc = material_color(material, texture != nullptr);
    std::size_t faces = 0;
    for (unsigned f = 0; f < a->mNumFaces; ++f) faces += a->mFaces[f].mNumIndices == 3 ? 1 : 0;
    if (faces == 0) return;
    if (out.triangle_count() + faces > kMaxModelTriangles) {
      throw io::FormatError(source, "more than " + std::to_string(kMaxModelTriangles) + " triangles; too large to place");
    }
    // Vertices with the same position and colour are one (texture coordinates told them apart
    // while the texture was sampled).
    std::unordered_map<WeldKey, std::uint32_t, WeldKey::Hash> welded;
    std::vector<std::uint32_t> index(a->mNumVertices);
    for (unsigned v = 0; v < a->mNumVertices; ++v) {
      const aiVector3D p = m * a->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw io::FormatError(source, "vertex " + std::to_string(v) + " of mesh '" + a->mName.C_Str() + "' is not finite");
      }
      aiColor4D c = per_vertex ? a->mColors[0][v] : mc;
      if (per_vertex) c.a *= mc.a;
      if (texture) {
        const aiVector3D& uv = a->mTextureCoords[channel][v];
        const std::array<float, 4> t = texture->sample(uv.x, uv.y);
        c = aiColor4D(c.r * t[0], c.g * t[1], c.b * t[2], c.a * t[3]);
      }
      const std::array<std::uint8_t, 4> rgba{byte_of(c.r), byte_of(c.g), byte_of(c.b), byte_of(c.a)};
      const aiVector3D& at = a->mVertices[v];
      WeldKey key{};
      const float xyz[3] = {at.x, at.y, at.z};
      std::memcpy(key.bits.data(), xyz, 12);
      std::memcpy(&key.bits[3], rgba.data(), 4);
      const auto [it, fresh] = welded.try_emplace(key, static_cast<std::uint32_t>(out.vertices.size()));
      index[v] = it->second;
      if (!fresh) continue;
      out.vertices.emplace_back(p.x, p.y, p.z);
      out.colors.emplace_back(rgba[0], rgba[1], rgba[2], rgba[3]);
    }
    for (unsigned f = 0; f < a->mNumFaces; ++f) {
      const aiFace& face = a->mFaces[f];
      if (face.mNumIndices != 3) continue;
      const std::uint32_t i = index[face.mIndices[0]], j = index[face.mIndices[1]], k = index[face.mIndices[2]];
      if (i == j || j == k || i == k) continue;
      for (const std::uint32_t x : {i, j, k}) out.triangles.push_back(x);
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
  // Normals and the rest are not used: removed first. Texture coordinates and embedded
  // textures are kept for the textures' colours.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                          aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
                                                          aiComponent_CAMERAS | aiComponent_LIGHTS);
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
  Collector{scene, source, model, {}}.node(scene->mRootNode, aiMatrix4x4());
  if (model.mesh.empty()) throw io::FormatError(source, "no triangles in the model");
  return model;
}

}  // namespace terravol::objects
