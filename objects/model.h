// 3D models of things placed on the terrain (masts, buildings, vehicles, aircraft), read from
// the common formats by assimp (glTF/GLB, OBJ, PLY, STL, FBX, 3DS, Collada and the others assimp
// reads), as one flat indexed triangle mesh with a colour per vertex.
#pragma once

#include <cstddef>
#include <filesystem>

#include "volume/geometry.h"

namespace terravol::objects {

// The largest model read: more triangles than this is refused as absurd (merging into the
// terrain tree costs microseconds per piece and a triangle becomes several pieces, so a model of
// millions of triangles would take minutes to place).
inline constexpr std::size_t kMaxModelTriangles = 2'000'000;
// The largest model file read, bytes (1 GiB).
inline constexpr std::uintmax_t kMaxModelBytes = std::uintmax_t{1} << 30;

struct Model {
  std::filesystem::path file;
  // In the model's own frame: the file's units and axes, every node's transform applied (a mesh
  // that several nodes use appears once per node). Triangles only (assimp triangulates
  // polygons; points and lines are dropped), vertices shared where assimp joins identical ones,
  // triangles with a repeated vertex dropped. Colours (sRGB and alpha, 0..255): the vertex's
  // first colour set where the mesh has one, else the material's diffuse colour (or its glTF
  // base colour), else assimp's default grey; alpha times the material's opacity. Textures are
  // not sampled: a textured surface has its material's colour.
  volume::Mesh mesh;
  std::size_t meshes = 0;        // assimp meshes that gave triangles, counting every node using one
  bool vertex_colors = false;    // some mesh had per-vertex colours
};

// Reads a model with assimp. Throws io::FormatError("FILE: what is wrong", one line) for a
// missing or unreadable file, one larger than kMaxModelBytes, a format assimp does not read or
// a malformed file (assimp's own message), a model without triangles, one with more than
// kMaxModelTriangles triangles and one with a non-finite coordinate.
Model read_model(const std::filesystem::path& file);

}  // namespace terravol::objects
