// The baseline of the benchmarks: the pipeline a user would build in ParaView or plain VTK for
// the same scene. The terrain at FULL resolution and the translucent overlay (isosurfaces,
// slices) are two static vtkPolyData, uploaded to the GPU once and drawn each frame by VTK's
// ordinary vtkPolyDataMapper with the depth test; only the camera changes between frames.
// Translucency is VTK's: depth peeling with ParaView's default settings, depth peeling run to
// exactness, or VTK 9.1's default translucent pass. Nothing of the tree is used here.
#pragma once

#include <vtkNew.h>

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "app/render/terrain_renderer.h"
#include "app/scene/terrain_colors.h"
#include "mrbsp/terrain_tree.h"

class vtkActor;
class vtkPolyData;
class vtkPolyDataMapper;
class vtkRenderer;
class vtkRenderWindow;

namespace terravol::bench {

// How the translucent overlay is composited. The terrain is opaque and depth-tested in every
// mode.
enum class Translucency : std::uint8_t {
  // Depth peeling as ParaView's render view sets it by default (and as vtkRenderer starts):
  // at most 4 peels, occlusion ratio 0. VTK 9.1 uses dual depth peeling (Bavoil and Myers
  // 2008) where the context supports it (it does on Mesa llvmpipe): each peel takes the
  // nearest and the farthest remaining layer, so 4 peels composite 8 layers exactly; the
  // fragments left when the peels run out are alpha-blended in draw order, unsorted.
  kPeel4,
  // Depth peeling run until a peel writes no pixel (occlusion ratio 0, no practical limit on
  // peels): the sorted "over" composite of every layer, up to 8-bit rounding per layer.
  // (MaximumNumberOfPeels is not set to 0, vtkRenderer's "no limit": dual depth peeling
  // takes 0 literally and peels nothing; see plain_vtk.cpp.)
  kPeelExact,
  // What VTK 9.1 does with depth peeling off: weighted blended order-independent translucency
  // (McGuire and Bavoil 2013), an approximation that is exact for one layer only.
  kVtkDefault,
};

struct PlainVtkOptions {
  int width = 1280, height = 720;  // pixels, > 0
  Translucency translucency = Translucency::kPeel4;
  app::scene::Rgb background{205, 222, 240};  // one colour: no gradient, no haze
};

// Index triples of the full-resolution triangles of an
// (cells+1) x (cells+1) lattice (vertex j * (cells + 1) + i, row 0 south, column 0 west), two
// per cell, split along the south-west to north-east diagonal as mrbsp::TerrainTree splits
// its cells: (sw, se, ne) then (sw, ne, nw), counter-clockwise seen from above, cells in
// row-major order from the south-west. 2 * cells^2 triangles.
// Throws std::invalid_argument when cells < 1 or (cells + 1)^2 does not fit an int32 index
// (VTK's 32-bit connectivity).
std::vector<std::uint32_t> lattice_triangles(int cells);

class PlainVtkScene {
 public:
  // terrain: positions (scene frame, metres), per-vertex RGBA already shaded
  // (app::scene::TerrainShading rgba: drawn as they are, lighting off, like
  // app::render::TerrainRenderer), index triples into the positions; drawn opaque (alpha ignored).
  // overlay: positions (scene frame, metres), per-vertex RGBA whose alpha is the opacity, index
  // triples; drawn translucent as options.translucency says, both faces, lighting off. May be
  // empty (no translucent actor then); so may the terrain.
  // Opens an offscreen render window (require_x_display first). Throws std::invalid_argument
  // when colours and positions differ in count, an index list is not a multiple of 3 or
  // holds an index out of range, or the size is not positive; std::runtime_error without an
  // X display.
  PlainVtkScene(std::span<const glm::vec3> terrain_positions,
                std::span<const app::scene::Rgba> terrain_rgba,
                std::span<const std::uint32_t> terrain_triangles,
                std::span<const glm::dvec3> overlay_positions,
                std::span<const glm::u8vec4> overlay_rgba,
                std::span<const std::uint32_t> overlay_triangles, const PlainVtkOptions& options);
  ~PlainVtkScene();
  PlainVtkScene(const PlainVtkScene&) = delete;
  PlainVtkScene& operator=(const PlainVtkScene&) = delete;

  // The view, as app::render::TerrainRenderer sets it (app::render::apply_camera): clipping
  // range [camera.near_plane, far_plane] metres. camera.width/height are not used: the image
  // has the options' size.
  void set_camera(const mrbsp::Camera& camera, double far_plane);

  // Draws one frame and waits for the GPU to finish it (WaitForCompletion: glFinish); returns
  // wall milliseconds. The first frame also uploads the geometry.
  double render();

  // The last rendered image: width * height * 3 bytes, RGB, top row first. Empty before the
  // first render().
  std::vector<std::uint8_t> rgb() const;

  // Whether VTK peels with vtkDualDepthPeelingPass (two layers per peel) rather than
  // vtkDepthPeelingPass (one). Asks the OpenGL context, so call it after render().
  bool dual_depth_peeling();

  // Triangles drawn per frame: terrain plus overlay.
  std::size_t triangles() const { return terrain_triangles_ + overlay_triangles_; }

  const PlainVtkOptions& options() const { return options_; }
  vtkRenderer* renderer() { return renderer_; }
  vtkRenderWindow* window() { return window_; }

 private:
  PlainVtkOptions options_;
  std::size_t terrain_triangles_ = 0, overlay_triangles_ = 0;
  bool rendered_ = false;
  vtkNew<vtkPolyData> terrain_;
  vtkNew<vtkPolyDataMapper> terrain_mapper_;
  vtkNew<vtkActor> terrain_actor_;
  vtkNew<vtkPolyData> overlay_;
  vtkNew<vtkPolyDataMapper> overlay_mapper_;
  vtkNew<vtkActor> overlay_actor_;
  vtkNew<vtkRenderer> renderer_;
  vtkNew<vtkRenderWindow> window_;
};

}  // namespace terravol::bench
