// The VTK side of a terrain render: one vtkPolyData holding every vertex of the tree (positions,
// RGBA, texture coordinates, uploaded once), whose triangle list is replaced by each traversal, drawn
// either in tree order with no depth test (OrderedPolyDataMapper) or with VTK's ordinary
// depth-tested mapper (the references), into an offscreen window. Merged polygons (isosurfaces,
// slices: Frame::level kMergedLevel) are drawn with their own RGBA; the terrain with its
// texture.
#pragma once

#include <vtkBillboardTextActor3D.h>
#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "app/render/legend_image.h"
#include "app/render/ordered_mapper.h"
#include "app/scene/style.h"
#include "app/scene/terrain_colors.h"
#include "app/scene/volume_layer.h"
#include "mrbsp/terrain_tree.h"

class vtkActor;
class vtkFramebufferPass;
class vtkCellArray;
class vtkCamera;
class vtkImageData;
class vtkPolyData;
class vtkPolyDataMapper;
class vtkRenderer;
class vtkRenderWindow;
class vtkActor2D;
class vtkTexture;

namespace terravol::app::render {

struct RenderSettings {
  int width = 1280, height = 720;  // pixels
  scene::DrawOrder order = scene::DrawOrder::kBsp;
  int peels = 0;  // kPeel: most depth peels, 0 = no limit (exact; ParaView's default is 4)
  bool wireframe = false;
  bool lod_colors = false;              // per-triangle colours from Frame::level
  scene::Rgb background{205, 222, 240};     // uniform, or the bottom of the gradient
  scene::Rgb background_top{95, 145, 210};  // used when gradient
  bool gradient = true;                 // a sky gradient, bottom to top
  // Aerial perspective: colours fade toward haze_color with depth d (metres along the view
  // axis) by 1 - exp(-d / haze_distance), at most 85%; 0 turns it off. Computed per vertex in
  // the vertex shader and mixed in by the fragment shader, so the vertex colours (and
  // --export-vtp) are unhazed.
  double haze_distance = 0.0;
  scene::Rgb haze_color{214, 226, 238};
  // false: an on-screen window (terravol view), whose interactor the caller attaches.
  bool offscreen = true;
};

// The lattice colours as one texture (side x side texels, row 0 south): when given, the
// terrain's colour at every pixel comes from the full-resolution colours whatever LOD the
// geometry is drawn at (bilinear, no mipmaps), instead of being interpolated between the
// vertices of coarse triangles. Not drawn while lod_colors is on.
struct ColorTexture {
  int side = 0;                       // n + 1; 0: no texture, per-vertex colours
  std::span<const scene::Rgba> rgba;  // side * side
};

// Index triples as a vtkCellArray of triangles with 32-bit connectivity (offsets 0, 3, 6, ...),
// the form the ordered mapper uploads as its index buffer without a copy. Precondition: every
// index fits an int32 (VTK's 32-bit connectivity).
vtkSmartPointer<vtkCellArray> triangle_cells(std::span<const std::uint32_t> indices);

// The last frame drawn in `window` (its back buffer, RGB, not re-rendered): width * height * 3
// bytes, top row first (what a PNG encoder or a video encoder takes).
std::vector<std::uint8_t> window_rgb(vtkRenderWindow* window);

// Throws std::runtime_error (one line: "WHO needs an X display ...", naming $DISPLAY and
// xvfb-run) when no X display can be opened: VTK 9.1 on Debian renders through GLX even
// offscreen, and aborts without a display. `who` names what needs it for the user (the
// command, e.g. "profile -o"). The connection it opens stays open for the process and serves
// every TerrainRenderer.
void require_x_display(const std::string& who = "render");

// Puts `window` (any VTK render window, e.g. a vtkContextView's) on that one connection
// (require_x_display(who) first), so that closing it closes no connection: a window with its
// own connection inside a running viewer left the viewer's X event loop polling a closed one.
void use_shared_display(vtkRenderWindow* window, const std::string& who = "render");

// The legend card of a volume layer's legend (the slice's map, each isosurface level marked on
// it and given a swatch; a categorical slice's swatches first); none for an empty legend.
std::optional<LegendCard> legend_card(const scene::Legend& legend);

class TerrainRenderer {
 public:
  // positions: TerrainTree::positions(); shading: per vertex, the same count (vertex_shading).
  // Opens a render window (offscreen unless settings.offscreen is false) on the process's X
  // connection (require_x_display).
  // Throws std::invalid_argument when the counts differ or the size is not positive, and
  // std::runtime_error without an X display.
  TerrainRenderer(const std::vector<glm::vec3>& positions, const scene::TerrainShading& shading,
                  const RenderSettings& settings, const ColorTexture& texture = {});
  ~TerrainRenderer();
  TerrainRenderer(const TerrainRenderer&) = delete;
  TerrainRenderer& operator=(const TerrainRenderer&) = delete;

  // The view: vtkCamera from the tree's camera, clipping range [near_plane, far_plane].
  void set_camera(const mrbsp::Camera& camera, double far_plane);

  // Replaces the triangle list with the frame's, in its order (and, with lod_colors, the
  // per-triangle colours: lod_color(level) times the mean shade of the three vertices).
  // The frame's own vertices (colour-box faces: Frame::transient_positions, from index
  // transient_base) go after the tree's, in a tail of vertices reserved for them (an eighth
  // more than the frame that grew it needed: a frame that needs more grows it again and
  // uploads every vertex again); otherwise
  // only they are written to the vertex buffers (OrderedPolyDataMapper::update_vertices), or,
  // for the other orders, everything is uploaded again. Throws std::invalid_argument when the
  // frame's transient_base is not vertex_count() (the renderer holds other vertices than the
  // tree that traversed). In the bsp order a frame with such faces is blended in float
  // (use_float_target).
  void set_frame(const mrbsp::Frame& frame);

  // Draws one frame and waits for the GPU to finish it; returns wall milliseconds.
  double render();

  // The sky gradient's colours (bottom, top), or the uniform background (bottom) when the
  // settings have no gradient.
  void set_background(const scene::Rgb& bottom, const scene::Rgb& top);

  // Display switches for the interactive viewer; they take effect at the next set_frame() and
  // render(). LOD colours replace the texture and turn the haze off while on.
  void set_lod_colors(bool on);
  void set_wireframe(bool on);

  // Sliding and re-merging (terravol view): every vertex gets a new position and attributes
  // (the tree's positions() after TerrainTree::slide() or merge(), the shading and texture of
  // the window). The vertex count may change (merged polygons come and go); the texture side
  // must be the constructor's, and the attribute counts must match the positions, else
  // std::invalid_argument. The triangle list is emptied until the next set_frame().
  // In the bsp order, when the new vertices fit the arrays held (the vertices held and the
  // room kept after them: a terrain-only window slid keeps its count; merged vertices fit the
  // room when they grew by less than it), the arrays are written in place: no allocation;
  // the positions and colours are uploaded in place (OrderedPolyDataMapper::update_vertices;
  // positions go unshifted, so the picture is the one a fresh upload gives), the texture
  // coordinates only when they differ. Otherwise (and after release_vertices()) every array
  // is made and uploaded again, with room for count / scene::kVertexRoom more. The shading is
  // moved from.
  void replace_vertices(const std::vector<glm::vec3>& positions, scene::TerrainShading shading,
                        const ColorTexture& texture = {});
  // Edits and lazily built pieces (TerrainTree::merged_version() unchanged): the tree only
  // appended merged vertices, so only they are added: `positions` are the new tail of the
  // tree's positions() and `colors` their merged colours (shade 1, no texture, as
  // vertex_shading gives merged vertices). The triangles drawn stay valid. Throws
  // std::invalid_argument when the counts differ.
  void append_merged_vertices(std::span<const glm::vec3> positions, std::span<const glm::u8vec4> colors);
  // After the tree renumbered its merged vertices but kept its terrain (a compaction after
  // edits, a merge of everything): `positions` are all of the tree's positions(), the first
  // `merged_base` of them the terrain's, `colors` the merged ones' colours. When the terrain's
  // are the ones held (compared byte for byte) and all fit in the room reserved, the merged
  // ones are written in place and only they uploaded, and true is returned; else false, and
  // nothing changed (use replace_vertices). The triangle list is emptied until the next
  // set_frame().
  bool replace_merged_vertices(std::span<const glm::vec3> positions, std::size_t merged_base,
                               std::span<const glm::u8vec4> colors);
  std::size_t vertex_count() const { return point_rgba_.size(); }  // the tree's, not the frame's own
  std::size_t transient_capacity() const { return tail_; }
  // Which TerrainTree::merged_version() the vertices are of (the caller's bookkeeping:
  // SceneRenderer::sync_vertices sets it).
  std::uint64_t vertex_version() const { return vertex_version_; }
  void set_vertex_version(std::uint64_t v) { vertex_version_ = v; }
  // Frees every vertex array, the triangle lists and their buffers on the GPU (host memory
  // under Mesa's llvmpipe), keeping the texture. Call it before a slide or merge that will
  // replace every vertex with a merge's scratch (merged polygons), so that the old vertices
  // and that scratch never hold memory at the same time. Until replace_vertices() and
  // set_frame(), render() draws only the background.
  void release_vertices();

  // The transmitter markers' names, drawn over the scene as billboard text (white, with a
  // shadow, centred above each anchor; VTK projects the anchors with the camera), replacing the
  // last ones. Labels are not part of the tree's order: like the legend they lie over the image,
  // on a second layer, the same in every draw order.
  void set_labels(const std::vector<scene::MarkerLabel>& labels);

  // The colour legend, drawn as a card (legend_image: the slice's map, each isosurface level
  // marked on it and given a swatch), or none when `legend` is empty.
  void set_legend(const scene::Legend& legend);
  // Where render() puts the card, in window pixels from the top left: its right edge at x =
  // right, its top at y = top, at most max_height tall (legend_image shrinks it); max_height
  // <= 0: not drawn. Until this is called: the upper right, 10 px in, at most the window's
  // height less 20 px.
  void place_legend(int right, int top, int max_height);
  // Width and height in pixels of the card at that max_height ({0, 0} without a legend).
  std::array<int, 2> legend_size(int max_height);
  // The card as the last render() drew it: x, y (from the top left), width, height in window
  // pixels; none when no legend was drawn.
  const std::optional<std::array<int, 4>>& legend_box() const { return legend_box_; }

  // The last rendered image (the back buffer, not re-rendered): window_rgb(window()).
  std::vector<std::uint8_t> rgb() const;

  // The scene: every point (the lattice's first, sample (i, j) at j * (n + 1) + i), the array
  // "rgba" (point data), the current triangles in draw order, and with lod_colors the cell array
  // "lod_rgba" and always "level" (cell data).
  vtkPolyData* scene() { return poly_; }
  vtkCamera* camera();
  vtkRenderer* renderer() { return renderer_; }
  vtkRenderWindow* window() { return window_; }
  const RenderSettings& settings() const { return settings_; }

 private:
  void apply_color_mode();
  void update_legend();  // before each render: the card at its place and size
  const RgbaImage* legend_image_for(int max_height);
  void install_shaders(vtkActor& actor, bool textured);
  // Makes the arrays hold vertex_count() + capacity vertices: the tree's, then placeholders
  // for a frame's own (at the origin, clear, texture coordinates (-1, -1) so that the shader
  // takes their colour) and marks them modified. Sets tail_.
  void reserve_tail(std::size_t capacity);
  // Positions and RGBA bytes (4 per vertex) of vertices first .. first + positions.size() into
  // the arrays, which must hold them; nothing is marked modified.
  void write_vertices(std::size_t first, std::span<const glm::vec3> positions, const void* rgba);
  // replace_vertices() over the arrays held, when it can (see there); false when it cannot,
  // with nothing changed.
  bool replace_in_place(const std::vector<glm::vec3>& positions, scene::TerrainShading& shading,
                        const ColorTexture& texture);
  // Translucent newcomers turn the ordered mapper's blending on (it stays on: what was
  // translucent still is).
  void blend_if_translucent(std::span<const glm::u8vec4> colors);
  // In the bsp order, a frame with colour-box faces (densities) is blended into a 32-bit float
  // colour target (vtkFramebufferPass, copied to the window once per frame), and any other
  // frame into the window's 8 bits. A density is thousands of faint faces over a pixel, and
  // each blend into 8 bits rounds: the default density's mean error against the ray marcher
  // was 4.7/255 in 8 bits, 0.5/255 in float (bench density suite).
  void use_float_target(bool on);
  bool split_orders() const {
    return settings_.order != scene::DrawOrder::kBsp && settings_.order != scene::DrawOrder::kZBuffer;
  }

  RenderSettings settings_;
  std::vector<float> shade_;      // per vertex, for --lod-colors
  std::vector<scene::Rgba> point_rgba_;  // per vertex, for merged polygons under --lod-colors
  std::size_t tail_ = 0;          // vertices reserved after the tree's for a frame's own
  int texture_side_ = 0;          // 0: no texture
  std::uint64_t vertex_version_ = ~std::uint64_t{0};
  vtkNew<vtkPolyData> poly_;
  vtkNew<vtkImageData> texture_image_;
  vtkNew<vtkTexture> texture_;
  vtkSmartPointer<vtkPolyDataMapper> mapper_;
  vtkNew<vtkActor> actor_;
  // kPeel, kVtk, kSort: the merged triangles, translucent, sharing poly_'s points.
  vtkNew<vtkPolyData> merged_poly_;
  vtkSmartPointer<vtkPolyDataMapper> merged_mapper_;
  vtkNew<vtkActor> merged_actor_;
  // The legend: the card, its image at the last max height, the actor that shows it.
  std::optional<LegendCard> legend_card_;
  RgbaImage legend_cache_;
  int legend_cache_height_ = 0;
  bool legend_uploaded_ = false;
  std::optional<std::array<int, 3>> legend_place_;  // right, top, max height
  std::optional<std::array<int, 4>> legend_box_;
  vtkNew<vtkImageData> legend_data_;
  vtkNew<vtkActor2D> legend_actor_;
  std::vector<vtkSmartPointer<vtkBillboardTextActor3D>> labels_;
  vtkNew<vtkRenderer> labels_renderer_;  // layer 1: the labels over the scene
  std::vector<std::uint32_t> split_terrain_, split_merged_;  // set_frame's buffers (split orders)
  std::vector<std::int8_t> split_levels_;
  std::vector<OrderedPolyDataMapper::Run> untextured_runs_;  // set_frame's buffer (bsp order)
  vtkSmartPointer<vtkFramebufferPass> float_pass_;  // made at the first frame with boxes
  vtkNew<vtkRenderer> renderer_;
  vtkNew<vtkRenderWindow> window_;
};

}  // namespace terravol::app::render
