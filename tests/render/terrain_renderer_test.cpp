// app/render/terrain_renderer.h and app/render/ordered_mapper.h on a tiny scene of their own: the draw order
// of the triangle list decides visibility under --order bsp, the depth buffer under zbuffer.
#include <gtest/gtest.h>
#include <vtkPolyData.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "app/render/ordered_mapper.h"
#include "app/render/terrain_renderer.h"
#include "app/scene/terrain_colors.h"
#include "mrbsp/color_boxes.h"
#include "mrbsp/terrain_tree.h"
#include "image_compare.h"
#include "require_display.h"

namespace terravol::app::render {
namespace {

// Two unit-ish squares seen from above: a red one at z = 5 (near) and a blue one at z = 0 (far).
struct TwoSquares {
  std::vector<glm::vec3> positions;
  scene::TerrainShading shading;
  mrbsp::Camera camera;
};

TwoSquares two_squares(std::uint8_t near_alpha) {
  TwoSquares s;
  for (float z : {5.0f, 0.0f})
    for (auto [x, y] : {std::pair{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}})
      s.positions.emplace_back(x, y, z);
  for (int v = 0; v < 8; ++v) {
    s.shading.shade.push_back(1.0f);
    s.shading.rgba.push_back(v < 4 ? scene::Rgba{255, 0, 0, near_alpha} : scene::Rgba{0, 0, 255, 255});
  }
  s.camera.eye = {0.0, 0.0, 20.0};
  s.camera.forward = {0.0, 0.0, -1.0};
  s.camera.up = {0.0, 1.0, 0.0};
  s.camera.fov_y_deg = 30.0;
  s.camera.width = 64;
  s.camera.height = 64;
  s.camera.near_plane = 1.0;
  return s;
}

mrbsp::Frame frame_of(std::vector<std::uint32_t> indices) {
  mrbsp::Frame f;
  f.indices = std::move(indices);
  f.level.assign(f.indices.size() / 3, 0);
  return f;
}

const std::vector<std::uint32_t> kNearThenFar{0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
const std::vector<std::uint32_t> kFarThenNear{4, 5, 6, 4, 6, 7, 0, 1, 2, 0, 2, 3};

// 64 x 64 pixels on a uniform green background.
RenderSettings two_squares_settings(scene::DrawOrder order) {
  RenderSettings settings;
  settings.width = 64;
  settings.height = 64;
  settings.order = order;
  settings.gradient = false;
  settings.background = {0, 255, 0};
  return settings;
}

test::Rgb8 centre_pixel(const TwoSquares& s, scene::DrawOrder order, const std::vector<std::uint32_t>& indices) {
  TerrainRenderer renderer(s.positions, s.shading, two_squares_settings(order));
  renderer.set_camera(s.camera, 100.0);
  renderer.set_frame(frame_of(indices));
  renderer.render();
  const test::Image img = test::image_of_rgb(renderer.rgb(), 64, 64);
  EXPECT_EQ(img.width, 64);
  return img.width == 64 ? img.at(32, 32) : test::Rgb8{};
}

TEST(TerrainRenderer, BspOrderDrawsLaterTrianglesOnTopWithoutDepthTest) {
  TERRAVOL_REQUIRE_DISPLAY();
  const TwoSquares s = two_squares(255);
  EXPECT_EQ(centre_pixel(s, scene::DrawOrder::kBsp, kNearThenFar), (test::Rgb8{0, 0, 255}))
      << "the far square, drawn last";
  EXPECT_EQ(centre_pixel(s, scene::DrawOrder::kBsp, kFarThenNear), (test::Rgb8{255, 0, 0}));
}

TEST(TerrainRenderer, ZBufferOrderShowsTheNearestWhateverTheOrder) {
  TERRAVOL_REQUIRE_DISPLAY();
  const TwoSquares s = two_squares(255);
  EXPECT_EQ(centre_pixel(s, scene::DrawOrder::kZBuffer, kNearThenFar), (test::Rgb8{255, 0, 0}));
  EXPECT_EQ(centre_pixel(s, scene::DrawOrder::kZBuffer, kFarThenNear), (test::Rgb8{255, 0, 0}));
}

TEST(TerrainRenderer, BspOrderBlendsTranslucentTrianglesOverWhatIsBehind) {
  TERRAVOL_REQUIRE_DISPLAY();
  const TwoSquares s = two_squares(128);  // the near red square half transparent
  const test::Rgb8 c = centre_pixel(s, scene::DrawOrder::kBsp, kFarThenNear);
  EXPECT_NEAR(c[0], 128, 2);
  EXPECT_EQ(c[1], 0);
  EXPECT_NEAR(c[2], 127, 2);
}

TEST(TerrainRenderer, EmptyFrameShowsTheBackground) {
  TERRAVOL_REQUIRE_DISPLAY();
  const TwoSquares s = two_squares(255);
  EXPECT_EQ(centre_pixel(s, scene::DrawOrder::kBsp, {}), (test::Rgb8{0, 255, 0}));
}

// A slide frees the renderer's vertices (and their GPU buffers) before the tree merges again,
// then gives it the new ones, which may be more.
TEST(TerrainRenderer, ReleasedVerticesDrawOnlyTheBackgroundUntilNewOnesAreGiven) {
  TERRAVOL_REQUIRE_DISPLAY();
  for (scene::DrawOrder order : {scene::DrawOrder::kBsp, scene::DrawOrder::kSort}) {
    TwoSquares s = two_squares(255);
    TerrainRenderer renderer(s.positions, s.shading, two_squares_settings(order));
    renderer.set_camera(s.camera, 100.0);
    renderer.set_frame(frame_of(kFarThenNear));
    renderer.render();
    EXPECT_EQ(test::image_of_rgb(renderer.rgb(), 64, 64).at(32, 32), (test::Rgb8{255, 0, 0}));

    renderer.release_vertices();
    EXPECT_EQ(renderer.scene()->GetNumberOfPoints(), 0);
    EXPECT_EQ(renderer.scene()->GetNumberOfCells(), 0);
    renderer.render();
    EXPECT_EQ(test::image_of_rgb(renderer.rgb(), 64, 64).at(32, 32), (test::Rgb8{0, 255, 0}));

    // Four more vertices: a white square at z = 8, drawn last.
    for (auto [x, y] : {std::pair{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}}) {
      s.positions.emplace_back(x, y, 8.0f);
      s.shading.shade.push_back(1.0f);
      s.shading.rgba.push_back(scene::Rgba{255, 255, 255, 255});
    }
    renderer.replace_vertices(s.positions, s.shading);
    // The twelve, and the room kept after them for vertices appended later.
    EXPECT_EQ(renderer.scene()->GetNumberOfPoints(), 12 + 12 / static_cast<vtkIdType>(scene::kVertexRoom));
    std::vector<std::uint32_t> three = kFarThenNear;
    three.insert(three.end(), {8, 9, 10, 8, 10, 11});
    renderer.set_frame(frame_of(three));
    renderer.render();
    EXPECT_EQ(test::image_of_rgb(renderer.rgb(), 64, 64).at(32, 32), (test::Rgb8{255, 255, 255}));
  }
}

// The picture a renderer made with these vertices draws of `indices` from `camera` (bsp order).
test::Image fresh_picture(const std::vector<glm::vec3>& positions,
                          const scene::TerrainShading& shading, const mrbsp::Camera& camera,
                          const std::vector<std::uint32_t>& indices,
                          const ColorTexture& texture = {}) {
  TerrainRenderer fresh(positions, shading, two_squares_settings(scene::DrawOrder::kBsp), texture);
  fresh.set_camera(camera, 100.0);
  fresh.set_frame(frame_of(indices));
  fresh.render();
  return test::image_of_rgb(fresh.rgb(), 64, 64);
}

// A terrain-only slide keeps the vertex count: the renderer writes the new vertices over the
// old ones, in the same arrays. The picture is the one a renderer made with the new vertices
// draws.
TEST(TerrainRenderer, VerticesReplacedInPlaceDrawWhatARendererMadeWithThemDraws) {
  TERRAVOL_REQUIRE_DISPLAY();
  const TwoSquares s = two_squares(255);
  const std::vector<scene::Rgba> yellow{{255, 255, 0, 255}};
  scene::TerrainShading shading = s.shading;
  shading.tcoords.assign(8, glm::vec2(-1.0f));  // vertex colours
  TerrainRenderer renderer(s.positions, shading, two_squares_settings(scene::DrawOrder::kBsp), {1, yellow});
  renderer.set_camera(s.camera, 100.0);
  renderer.set_frame(frame_of(kFarThenNear));
  renderer.render();
  const test::Image before = test::image_of_rgb(renderer.rgb(), 64, 64);
  ASSERT_EQ(before.at(32, 32), (test::Rgb8{255, 0, 0}));

  // The near square moved right by half its side and textured, the far one recoloured.
  std::vector<glm::vec3> moved = s.positions;
  for (int v = 0; v < 4; ++v) moved[static_cast<std::size_t>(v)].x += 1.0f;
  scene::TerrainShading recoloured = shading;
  for (int v = 0; v < 4; ++v) recoloured.tcoords[static_cast<std::size_t>(v)] = glm::vec2(0.5f);
  for (int v = 4; v < 8; ++v) recoloured.rgba[static_cast<std::size_t>(v)] = scene::Rgba{255, 255, 255, 255};
  const std::vector<scene::Rgba> magenta{{255, 0, 255, 255}};
  const void* storage = renderer.scene()->GetPoints()->GetData()->GetVoidPointer(0);
  renderer.replace_vertices(moved, recoloured, {1, magenta});
  EXPECT_EQ(renderer.scene()->GetPoints()->GetData()->GetVoidPointer(0), storage) << "written in place";
  renderer.set_frame(frame_of(kFarThenNear));
  renderer.render();
  const test::Image after = test::image_of_rgb(renderer.rgb(), 64, 64);

  const test::Image expected =
      fresh_picture(moved, recoloured, s.camera, kFarThenNear, {1, magenta});
  ASSERT_EQ(after.width, 64);
  EXPECT_EQ(after.pixels, expected.pixels);
  // Row 0 is the top of the picture; the near square now covers x from 0 to 2.
  EXPECT_EQ(after.at(40, 32), (test::Rgb8{255, 0, 255})) << "the moved near square, with the new texel";
  EXPECT_EQ(after.at(28, 32), (test::Rgb8{255, 255, 255})) << "the far square's new colour, uncovered";
}

// A slide with merged pieces changes the vertex count. When the new vertices fit the room
// kept after the old ones (here the room the appended pieces left), they are written in place
// too, and the picture is a fresh renderer's, far from the scene frame's origin as well.
TEST(TerrainRenderer, MoreVerticesThatFitTheRoomAreWrittenInPlaceAndDrawAsAFreshRenderer) {
  TERRAVOL_REQUIRE_DISPLAY();
  for (const float offset : {0.0f, 60000.0f}) {
    SCOPED_TRACE(offset);
    TwoSquares s = two_squares(255);
    for (glm::vec3& p : s.positions) p.x += offset;
    s.camera.eye.x += offset;
    TerrainRenderer renderer(s.positions, s.shading, two_squares_settings(scene::DrawOrder::kBsp));
    renderer.set_camera(s.camera, 100.0);
    // Four merged vertices appended: room for three times as many kept after them.
    const std::vector<glm::vec3> piece{{offset - 0.5f, -0.5f, 6.0f},
                                       {offset + 0.5f, -0.5f, 6.0f},
                                       {offset + 0.5f, 0.5f, 6.0f},
                                       {offset - 0.5f, 0.5f, 6.0f}};
    const std::vector<glm::u8vec4> white(4, glm::u8vec4(255));
    renderer.append_merged_vertices(piece, white);
    renderer.set_frame(frame_of({4, 5, 6, 4, 6, 7, 0, 1, 2, 0, 2, 3, 8, 9, 10, 8, 10, 11}));
    renderer.render();

    // Slid: the squares moved, and two translucent merged squares where one was.
    std::vector<glm::vec3> moved = s.positions;
    for (glm::vec3& p : moved) p.y += 0.5f;
    scene::TerrainShading shading = s.shading;
    for (int q = 0; q < 2; ++q)
      for (const glm::vec3& p : piece) {
        moved.push_back(p + glm::vec3(q == 0 ? -0.75f : 0.75f, 0.0f, 1.0f + q));
        shading.shade.push_back(1.0f);
        shading.rgba.push_back(q == 0 ? scene::Rgba{255, 255, 0, 128}
                                      : scene::Rgba{0, 255, 255, 160});
      }
    const std::vector<std::uint32_t> order{4, 5, 6,  4, 6,  7,  0,  1,  2,  0,  2,  3,
                                           8, 9, 10, 8, 10, 11, 12, 13, 14, 12, 14, 15};
    const void* storage = renderer.scene()->GetPoints()->GetData()->GetVoidPointer(0);
    renderer.replace_vertices(moved, shading);
    EXPECT_EQ(renderer.scene()->GetPoints()->GetData()->GetVoidPointer(0), storage)
        << "written in place";
    renderer.set_frame(frame_of(order));
    renderer.render();
    const test::Image after = test::image_of_rgb(renderer.rgb(), 64, 64);

    const test::Image expected = fresh_picture(moved, shading, s.camera, order);
    ASSERT_EQ(after.width, 64);
    EXPECT_EQ(after.pixels, expected.pixels);
    // The near red square under the cyan piece (x > 0), the yellow one (x < 0): both blended.
    const test::Rgb8 left = after.at(32 - 6, 32), right = after.at(32 + 6, 32);
    EXPECT_GT(left[0], 200);
    EXPECT_GT(left[1], 100) << "yellow over red";
    EXPECT_GT(right[2], 100) << "cyan over red";
  }
}

// A textured floor (8 x 8 at z = 0, one yellow texel) and, over its left half, a run of 128
// thin half-transparent blue triangles (merged pieces: vertex colours, texture coordinates -1)
// at z = 1; then a textured square at z = 2 over the bottom-left quadrant. Drawn in that order,
// seen from 20 above (the floor spans about 48 of the 64 pixels).
struct TexturedRun {
  std::vector<glm::vec3> positions;
  scene::TerrainShading shading;
  std::vector<std::uint32_t> indices;
  std::vector<std::int8_t> level;
};

TexturedRun textured_run(std::int8_t run_level) {
  TexturedRun s;
  auto vertex = [&](float x, float y, float z, scene::Rgba c, glm::vec2 t) {
    s.positions.emplace_back(x, y, z);
    s.shading.shade.push_back(1.0f);
    s.shading.rgba.push_back(c);
    s.shading.tcoords.push_back(t);
    return static_cast<std::uint32_t>(s.positions.size() - 1);
  };
  auto quad = [&](float x0, float y0, float x1, float y1, float z, scene::Rgba c, bool textured, std::int8_t lv) {
    const glm::vec2 t0 = textured ? glm::vec2(0.5f) : glm::vec2(-1.0f);
    const std::uint32_t a = vertex(x0, y0, z, c, t0), b = vertex(x1, y0, z, c, t0), d = vertex(x1, y1, z, c, t0),
                        e = vertex(x0, y1, z, c, t0);
    s.indices.insert(s.indices.end(), {a, b, d, a, d, e});
    s.level.insert(s.level.end(), {lv, lv});
  };
  const scene::Rgba grey{90, 90, 90, 255};  // the vertex colour the texture replaces
  quad(-4.0f, -4.0f, 4.0f, 4.0f, 0.0f, grey, true, 0);
  for (int k = 0; k < 64; ++k) {  // 128 triangles: the ordered mapper's shortest untextured run
    const float y0 = -4.0f + 8.0f * k / 64.0f;
    quad(-4.0f, y0, 0.0f, y0 + 8.0f / 64.0f, 1.0f, scene::Rgba{0, 0, 255, 128}, false, run_level);
  }
  quad(-4.0f, -4.0f, 0.0f, 0.0f, 2.0f, grey, true, 0);
  return s;
}

test::Image textured_run_image(std::int8_t run_level) {
  const TexturedRun s = textured_run(run_level);
  const std::vector<scene::Rgba> texel{{255, 255, 0, 255}};
  TerrainRenderer renderer(s.positions, s.shading, two_squares_settings(scene::DrawOrder::kBsp), {1, texel});
  renderer.set_camera(two_squares(255).camera, 100.0);
  mrbsp::Frame f;
  f.indices = s.indices;
  f.level = s.level;
  renderer.set_frame(f);
  renderer.render();
  return test::image_of_rgb(renderer.rgb(), 64, 64);
}

TEST(TerrainRenderer, LongRunsOfMergedPiecesDrawnWithoutTheTextureGiveTheSameImageInOrder) {
  TERRAVOL_REQUIRE_DISPLAY();
  static_assert(OrderedPolyDataMapper::kMinUntexturedRun <= 128);
  // Merged pieces: the run takes the untextured program. Terrain level 0: one draw, VTK's.
  const test::Image split = textured_run_image(mrbsp::kMergedLevel);
  const test::Image single = textured_run_image(0);
  ASSERT_EQ(split.width, 64);
  ASSERT_EQ(single.width, 64);
  EXPECT_EQ(split.pixels, single.pixels);
  // Row 0 is the top of the picture (north, +y).
  EXPECT_EQ(split.at(48, 32), (test::Rgb8{255, 255, 0})) << "the floor's texture, right";
  EXPECT_EQ(split.at(24, 48), (test::Rgb8{255, 255, 0})) << "the square drawn after the run, bottom left";
  const test::Rgb8 blended = split.at(24, 8);  // the run over the floor, top left
  EXPECT_NEAR(blended[0], 127, 2);
  EXPECT_NEAR(blended[1], 127, 2);
  EXPECT_NEAR(blended[2], 128, 2);
}

// Appends a colour-box face to `f` (after its transient_base): the square over the two
// squares' x and y at height z, in `colour`.
void add_face(mrbsp::Frame& f, float z, glm::u8vec4 colour) {
  const std::uint32_t b = f.transient_base + static_cast<std::uint32_t>(f.transient_positions.size());
  for (auto [x, y] : {std::pair{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}}) {
    f.transient_positions.emplace_back(x, y, z);
    f.transient_colors.push_back(colour);
  }
  f.indices.insert(f.indices.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
  f.level.insert(f.level.end(), {mrbsp::kBoxLevel, mrbsp::kBoxLevel});
}

// Colour-box faces (a density) are many faint layers over a pixel. 300 black faces of opacity
// 1/255 over the white far square leave 255 (254/255)^300 = 78.7 in exact arithmetic; blended
// into 8 bits, every step rounds, and the colour stops moving once a step is under half a unit
// (near 128) or falls to 0 when rounded down. A frame with such faces is blended in float
// (TerrainRenderer::use_float_target); the same triangles as merged pieces, in 8 bits, show
// the difference, and a frame without faces afterwards is drawn as before.
TEST(TerrainRenderer, ManyFaintColourBoxFacesBlendAsInExactArithmetic) {
  TERRAVOL_REQUIRE_DISPLAY();
  TwoSquares s = two_squares(255);
  s.shading.rgba.assign(8, scene::Rgba{255, 255, 255, 255});
  constexpr int kLayers = 300;
  const double exact = 255.0 * std::pow(254.0 / 255.0, kLayers);
  mrbsp::Frame boxes = frame_of({4, 5, 6, 4, 6, 7});  // the white square at z = 0
  boxes.transient_base = static_cast<std::uint32_t>(s.positions.size());
  for (int k = 0; k < kLayers; ++k) add_face(boxes, 0.5f + 4.0f * static_cast<float>(k) / kLayers, {0, 0, 0, 1});
  TerrainRenderer renderer(s.positions, s.shading, two_squares_settings(scene::DrawOrder::kBsp));
  renderer.set_camera(s.camera, 100.0);
  renderer.set_frame(boxes);
  renderer.render();
  const test::Rgb8 fog = test::image_of_rgb(renderer.rgb(), 64, 64).at(32, 32);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fog[c], exact, 1.5) << "channel " << c;

  // The same faces as the tree's own vertices (merged pieces): blended into 8 bits.
  TwoSquares merged = s;
  for (std::size_t v = 0; v < boxes.transient_positions.size(); ++v) {
    merged.positions.push_back(boxes.transient_positions[v]);
    merged.shading.shade.push_back(1.0f);
    merged.shading.rgba.push_back(scene::Rgba{0, 0, 0, 1});
  }
  TerrainRenderer eight(merged.positions, merged.shading, two_squares_settings(scene::DrawOrder::kBsp));
  eight.set_camera(s.camera, 100.0);
  mrbsp::Frame pieces = frame_of(boxes.indices);
  pieces.level = boxes.level;
  std::fill(pieces.level.begin() + 2, pieces.level.end(), mrbsp::kMergedLevel);
  eight.set_frame(pieces);
  eight.render();
  EXPECT_GT(std::abs(test::image_of_rgb(eight.rgb(), 64, 64).at(32, 32)[0] - exact), 20.0) << "8 bits round it away";

  // No faces: the white square as it is.
  renderer.set_frame(frame_of({4, 5, 6, 4, 6, 7}));
  renderer.render();
  EXPECT_EQ(test::image_of_rgb(renderer.rgb(), 64, 64).at(32, 32), (test::Rgb8{255, 255, 255}));
  EXPECT_EQ(test::image_of_rgb(renderer.rgb(), 64, 64).at(2, 2), (test::Rgb8{0, 255, 0})) << "the background";
}

// A frame's face vertices go in a tail reserved after the tree's. A frame with a few more
// of them than the one that sized the tail (a density after a small transfer-function change)
// fits it, so its faces are written in place instead of every vertex being uploaded again;
// many more grow it, and either way the picture shows the frame's own faces.
TEST(TerrainRenderer, AFewMoreFaceVerticesFitTheTailAndDrawTheirOwnColours) {
  TERRAVOL_REQUIRE_DISPLAY();
  TwoSquares s = two_squares(255);
  s.shading.rgba.assign(8, scene::Rgba{255, 255, 255, 255});
  // `quads` opaque squares at z = 1 over the white one, in `colour`.
  const auto faces = [&](int quads, glm::u8vec4 colour) {
    mrbsp::Frame f = frame_of({4, 5, 6, 4, 6, 7});
    f.transient_base = static_cast<std::uint32_t>(s.positions.size());
    for (int k = 0; k < quads; ++k) add_face(f, 1.0f, colour);
    return f;
  };
  TerrainRenderer renderer(s.positions, s.shading, two_squares_settings(scene::DrawOrder::kBsp));
  renderer.set_camera(s.camera, 100.0);
  const auto centre = [&](const mrbsp::Frame& f) {
    renderer.set_frame(f);
    renderer.render();
    return test::image_of_rgb(renderer.rgb(), 64, 64).at(32, 32);
  };

  EXPECT_EQ(centre(faces(2000, {255, 0, 0, 255})), (test::Rgb8{255, 0, 0}));
  const std::size_t sized = renderer.transient_capacity();
  EXPECT_GE(sized, 8000u + 8000u / 8);
  EXPECT_EQ(centre(faces(2100, {0, 0, 255, 255})), (test::Rgb8{0, 0, 255})) << "written in place";
  EXPECT_EQ(renderer.transient_capacity(), sized) << "5% more vertices fit";
  EXPECT_EQ(centre(faces(3000, {0, 255, 0, 255})), (test::Rgb8{0, 255, 0})) << "after growing";
  EXPECT_GE(renderer.transient_capacity(), 12000u);
}

}  // namespace
}  // namespace terravol::app::render

namespace terravol::app::render {
namespace {

// The legend on the picture: the card the renderer says it drew is where the slice's map and
// each isosurface's swatch are in the window's pixels, blended over the background at 85%.
TEST(TerrainRenderer, TheLegendCardShowsTheSliceMapAndASwatchPerIsosurfaceWhereItSays) {
  TERRAVOL_REQUIRE_DISPLAY();
  const TwoSquares s = two_squares(255);
  RenderSettings settings = two_squares_settings(scene::DrawOrder::kBsp);
  settings.width = 400;
  settings.height = 360;
  TerrainRenderer renderer(s.positions, s.shading, settings);
  renderer.set_camera(s.camera, 100.0);
  renderer.set_frame(frame_of({}));
  scene::Legend legend;
  legend.title = "path_loss_db (dB)";
  legend.subtitle = "slice 300 m above ground: viridis";
  legend.colormap = "viridis";
  legend.lo = 80;
  legend.hi = 160;
  legend.levels = {{"110 dB", {255, 0, 255}, 110.0}, {"130 dB", {255, 165, 225}, 130.0}};
  renderer.set_legend(legend);
  renderer.place_legend(390, 20, 300);
  renderer.render();
  ASSERT_TRUE(renderer.legend_box().has_value());
  const auto [x, y, w, h] = *renderer.legend_box();
  EXPECT_EQ(x + w, 390);
  EXPECT_EQ(y, 20);
  EXPECT_LE(h, 300);
  const test::Image img = test::image_of_rgb(renderer.rgb(), 400, 360);
  // Every pixel of each swatch colour, exactly, lies inside the box: the swatches (opaque),
  // 14 x 14, and the marks on the bar; outside it only the green background.
  for (const scene::LegendLevel& l : legend.levels) {
    int inside = 0, outside = 0;
    for (int py = 0; py < img.height; ++py)
      for (int px = 0; px < img.width; ++px) {
        if (img.at(px, py) != test::Rgb8{l.color[0], l.color[1], l.color[2]}) continue;
        (px >= x && px < x + w && py >= y && py < y + h ? inside : outside) += 1;
      }
    EXPECT_GE(inside, 14 * 14) << l.label;
    EXPECT_EQ(outside, 0) << l.label;
  }
  EXPECT_EQ(img.at(10, 10), (test::Rgb8{0, 255, 0})) << "outside the card, the background";
  // The card's white at alpha 217 over green: (217 * 255 + 38 * 0, 255, 217 * 255 / 255 ...).
  const test::Rgb8 card = img.at(x + 2, y + 2);
  EXPECT_NEAR(card[0], 217, 2);
  EXPECT_EQ(card[1], 255);
  EXPECT_NEAR(card[2], 217, 2);
  // The viridis bar: its top and bottom ends somewhere in the card.
  const volume::Colormap viridis = volume::colormap_by_name("viridis");
  for (const double t : {0.0, 1.0}) {
    const glm::u8vec3 c = viridis.map(t);
    bool found = false;
    for (int py = y; py < y + h && !found; ++py)
      for (int px = x; px < x + w && !found; ++px) found = test::same_color(img.at(px, py), {c.r, c.g, c.b}, 6);
    EXPECT_TRUE(found) << "viridis at " << t;
  }
  // Not placed (max height 0): not drawn.
  renderer.place_legend(390, 20, 0);
  renderer.render();
  EXPECT_FALSE(renderer.legend_box().has_value());
}

}  // namespace
}  // namespace terravol::app::render
