// 3D models of things placed on the terrain (masts, buildings, vehicles, aircraft), read from
// the common formats by assimp (glTF/GLB, OBJ, PLY, STL, FBX, 3DS, Collada and the others assimp
// reads), as one flat indexed triangle mesh with a colour per vertex.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "volume/geometry.h"

namespace terravol::objects {

// The largest model read: more triangles than this is refused as absurd (merging into the
// terrain tree costs microseconds per piece and a triangle becomes several pieces, so a model of
// millions of triangles would take minutes to place).
inline constexpr std::size_t kMaxModelTriangles = 2'000'000;
// The largest model file read, bytes (1 GiB).
inline constexpr std::uintmax_t kMaxModelBytes = std::uintmax_t{1} << 30;
// The largest texture read, pixels (16384 x 16384).
inline constexpr std::uint64_t kMaxTexturePixels = std::uint64_t{1} << 28;

struct Model {
  std::filesystem::path file;
  // In the model's own frame: the file's units and axes, every node's transform applied (a mesh
  // that several nodes use appears once per node). Triangles only (assimp triangulates
  // polygons; points and lines are dropped), vertices shared where assimp joins identical ones,
  // triangles with a repeated vertex dropped. Colours (sRGB and alpha, 0..255): the vertex's
  // first colour set where the mesh has one, else the material's diffuse colour (or its glTF
  // base colour), else assimp's default grey; alpha times the material's opacity. Where the
  // material has a diffuse or base-colour texture (a file beside the model, or embedded), that
  // colour is multiplied by the texture's, sampled bilinearly (repeating) at the vertex's
  // texture coordinates: the texture is baked into the vertex colours, so detail finer than
  // the mesh's vertices is lost. Vertices of a mesh with the same position and colour are one.
  volume::Mesh mesh;
  std::size_t meshes = 0;        // assimp meshes that gave triangles, counting every node using one
  bool vertex_colors = false;    // some mesh had per-vertex colours
  std::size_t textured_meshes = 0;  // meshes whose colours were sampled from a texture
  // Textures named by a material that could not be read (missing or undecodable files): those
  // meshes keep their material's colour.
  std::vector<std::string> missing_textures;
};

// Reads a model with assimp. Throws io::FormatError("FILE: what is wrong", one line) for a
// missing or unreadable file, one larger than kMaxModelBytes, a format assimp does not read or
// a malformed file (assimp's own message), a model without triangles, one with more than
// kMaxModelTriangles triangles, one with a non-finite coordinate and one with a texture of more
// than kMaxTexturePixels pixels.
Model read_model(const std::filesystem::path& file);

}  // namespace terravol::objects
