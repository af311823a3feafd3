// Translucent boxes given per frame, drawn in the tree's exact order (issue 15): the colour
// cubes of a volume density (Chamberlain et al. 1996, section 3), which change with every view
// and so cannot be merged into the tree (section 4.2 of Wiley et al. 1997: hundreds of ms per
// 100k triangles). TerrainTree::traverse() takes them as a span and orders their faces exactly
// with the terrain, the crack fills, the walls and every merged surface, without changing the
// tree (mrbsp/color_boxes.cpp says how).
#pragma once

#include <array>
#include <cstdint>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace terravol::mrbsp {

// An axis-aligned box of the scene frame (metres), drawn as those of its six faces that face
// the eye: face f lies in the plane x (f = 0, 1), y (2, 3) or z (4, 5) = lo (f even) or hi (f
// odd) and faces the eye when the eye lies strictly beyond that plane, outside the box
// (eye.x < lo.x for face 0, ...). A box holding the eye draws nothing. rgba[f] is the face's
// colour, straight (not premultiplied) sRGB and alpha, as the renderer blends merged polygons.
// Preconditions: lo < hi on every axis; boxes given to one traversal do not overlap.
struct ColorBox {
  glm::vec3 lo{0.0f}, hi{0.0f};
  std::array<glm::u8vec4, 6> rgba{};
};

// Frame::level of a triangle of a box face (beside kCrackLevel, kMergedLevel, kWallLevel).
inline constexpr std::int8_t kBoxLevel = -4;

// What ordering the boxes cost in one traversal (Frame::boxes).
struct BoxStats {
  std::size_t boxes = 0;       // given
  std::size_t parts = 0;       // pieces the tree's planes cut them into (a box in one region is one part)
  std::size_t faces = 0;       // face polygons drawn (after cuts)
  std::size_t dropped = 0;     // parts and faces found below the terrain and dropped
  std::size_t bsp_faces = 0;   // of the faces, those ordered inside merged surfaces' small BSPs
  double distribute_ms = 0.0;  // sending the boxes through the tree's planes
};

}  // namespace terravol::mrbsp
