// An item buffer (Weghorst, Hooper and Greenberg, "Improved Computational Methods for Ray
// Tracing", ACM TOG 3(1), 1984, section 3): a frame's triangles drawn by the same pipeline as
// the picture (the ordered mapper: the frame's order, no depth test, no blending), each in a
// flat colour that encodes its index, so that the image says which triangle shows at each
// pixel. The low-altitude suite counts with it the drawn triangles that cover no pixel (hidden)
// and the pixels each kind of triangle shows in.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "app/render/scene_renderer.h"
#include "mrbsp/terrain_tree.h"

namespace terravol::bench {

class ItemBuffer {
 public:
  // A renderer of the scene's tree at the scene's current window size. Throws what
  // SceneRenderer::make_renderer throws.
  explicit ItemBuffer(const app::render::SceneRenderer& scene);
  ~ItemBuffer();

  // Draws `frame` (a traversal of the scene's tree; at most 2^24 - 2 triangles, else
  // std::invalid_argument) from the scene's current camera and returns, per triangle of the
  // frame, the number of pixels it shows in (0: hidden, or outside the viewport).
  std::vector<std::uint32_t> pixels_per_triangle(const app::render::SceneRenderer& scene, const mrbsp::Frame& frame);

 private:
  std::unique_ptr<app::render::TerrainRenderer> renderer_;
};

}  // namespace terravol::bench
