// The reference's drawing: exact composites of known layers, whatever order they are given in,
// and the VTP it reads.
#include <gtest/gtest.h>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSignedCharArray.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataWriter.h>

#include <cmath>
#include <tuple>

#include "reference/draw.h"
#include "temp_dir.h"

namespace terravol::reference {
namespace {

#define REQUIRE_DISPLAY()                   \
  do {                                      \
    try {                                   \
      require_display();                    \
    } catch (const std::runtime_error& e) { \
      GTEST_SKIP() << e.what();             \
    }                                       \
  } while (0)

// A camera 100 m above the origin looking straight down (north up), 60 degrees wide.
Drawn looking_down(vtkPolyData* terrain) {
  Drawn d;
  d.terrain = terrain;
  d.position = {0, 0, 100};
  d.focal_point = {0, 0, 0};
  d.view_up = {0, 1, 0};
  d.view_angle = 60;
  d.clipping_range = {1, 1000};
  d.background = {10, 20, 30};
  return d;
}

// A square of half-side `r` at height z, one colour, as two triangles appended to `m`.
void square(Mesh& m, double r, double z, glm::u8vec4 rgba) {
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  for (auto [x, y] : {std::pair{-r, -r}, {r, -r}, {r, r}, {-r, r}}) {
    m.vertices.emplace_back(x, y, z);
    m.colors.push_back(rgba);
  }
  m.triangles.insert(m.triangles.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

vtkSmartPointer<vtkPolyData> polydata(const Mesh& m) {
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  for (const auto& v : m.vertices) points->InsertNextPoint(v.x, v.y, v.z);
  vtkNew<vtkUnsignedCharArray> rgba;
  rgba->SetName("rgba");
  rgba->SetNumberOfComponents(4);
  for (const auto& c : m.colors) rgba->InsertNextTypedTuple(&c[0]);
  vtkNew<vtkCellArray> cells;
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    const vtkIdType ids[3] = {m.triangles[t], m.triangles[t + 1], m.triangles[t + 2]};
    cells->InsertNextCell(3, ids);
  }
  pd->SetPoints(points);
  pd->SetPolys(cells);
  pd->GetPointData()->SetScalars(rgba);
  return pd;
}

const std::uint8_t* centre(const Image& im) { return &im.rgb[3 * (static_cast<std::size_t>(im.height / 2) * im.width + im.width / 2)]; }

TEST(Draw, TwelveTranslucentLayersCompositeBackToFrontWhateverTheirOrder) {
  REQUIRE_DISPLAY();
  Mesh ground;
  square(ground, 30, 0, {200, 200, 200, 255});
  Mesh layers;
  // Nearest first, the worst order for blending: twelve layers, more than 4 dual peels hold.
  const glm::u8vec3 colors[3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}};
  for (int k = 0; k < 12; ++k) square(layers, 10, 60.0 - 4.0 * k, glm::u8vec4(colors[k % 3], 77));
  const Image im = draw(looking_down(polydata(ground)), layers, 64, 48);
  // The "over" composite from the farthest layer (k = 11) to the nearest (k = 0).
  double c[3] = {200, 200, 200};
  for (int k = 11; k >= 0; --k)
    for (int ch = 0; ch < 3; ++ch) c[ch] = c[ch] * (1 - 77 / 255.0) + colors[k % 3][ch] * (77 / 255.0);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(centre(im)[ch], c[ch], 4.0) << ch;  // 8-bit rounding per layer
  EXPECT_EQ(im.rgb[0], 10);  // the corner: background
  EXPECT_EQ(im.rgb[1], 20);
  EXPECT_EQ(im.rgb[2], 30);
}

TEST(Draw, TheOpaqueTerrainHidesWhatLiesBelowIt) {
  REQUIRE_DISPLAY();
  Mesh ground;
  square(ground, 500, 0, {100, 150, 50, 255});
  Mesh below;
  square(below, 40, -10, {255, 0, 255, 200});
  const Image im = draw(looking_down(polydata(ground)), below, 64, 48);
  EXPECT_EQ(centre(im)[0], 100);
  EXPECT_EQ(centre(im)[1], 150);
  EXPECT_EQ(centre(im)[2], 50);
}

TEST(Draw, AGradientSkyRunsFromTheBottomColourToTheTop) {
  REQUIRE_DISPLAY();
  Mesh nothing;
  square(nothing, 1, -500, {0, 0, 0, 255});  // behind the camera's far plane... below it, out of view
  Drawn d = looking_down(polydata(nothing));
  d.position = {0, 0, 0};
  d.focal_point = {0, 1, 0};  // looking north, level
  d.view_up = {0, 0, 1};
  d.background_top = std::array<std::uint8_t, 3>{250, 250, 250};
  const Image im = draw(d, {}, 32, 64);
  const std::uint8_t* top = &im.rgb[3 * 16];
  const std::uint8_t* bottom = &im.rgb[3 * (63 * 32 + 16)];
  EXPECT_GT(top[0], 240);
  EXPECT_LT(bottom[0], 20);
}

TEST(TextureTerrain, SamplesTheLatticeColoursBilinearlyNotAlongTheTriangles) {
  REQUIRE_DISPLAY();
  // One cell of a 1-cell window, split along its south-west to north-east diagonal, the
  // north-west corner white and the others black: at the cell's centre bilinear filtering gives
  // a quarter of white, Gouraud shading black (the centre lies on the diagonal between two black
  // corners).
  const Frame frame(45.0, 6.0);
  const WindowLattice w{1, 44.999, 45.001, 5.999, 6.001};
  Mesh cell;
  const glm::u8vec4 black(0, 0, 0, 255), white(255, 255, 255, 255);
  for (auto [lat, lon, c] : {std::tuple{44.999, 5.999, black}, {44.999, 6.001, black}, {45.001, 6.001, black},
                             {45.001, 5.999, white}}) {
    cell.vertices.push_back(frame.to_scene(lat, lon, 0.0));
    cell.colors.push_back(c);
  }
  cell.triangles = {0, 1, 2, 0, 2, 3};
  Drawn d = looking_down(polydata(cell));
  d.position = {0, 0, 500};
  texture_terrain(d, frame, w);
  const Image textured = draw(d, {}, 33, 33);
  EXPECT_NEAR(centre(textured)[0], 64, 3);
  d.texture = nullptr;
  EXPECT_LE(centre(draw(d, {}, 33, 33))[0], 3);

  Drawn coarse = looking_down(polydata(cell));
  EXPECT_THROW(texture_terrain(coarse, frame, {1, 44.998, 45.001, 5.999, 6.001}), std::runtime_error);  // off the lines
  EXPECT_THROW(texture_terrain(coarse, frame, {2, 44.999, 45.001, 5.999, 6.001}), std::runtime_error);  // spans 2 cells
}

TEST(ReadDrawn, TakesTerrainAndCrackFillsAndLeavesMergedPolygons) {
  test::TempDir dir;
  Mesh m;
  square(m, 10, 0, {1, 2, 3, 255});   // level 0
  square(m, 10, 5, {4, 5, 6, 100});   // merged: level -2
  auto pd = polydata(m);
  vtkNew<vtkSignedCharArray> level;
  level->SetName("level");
  for (signed char v : {0, -1, -2, -2}) level->InsertNextValue(v);
  pd->GetCellData()->AddArray(level);
  auto field = [&](const char* name, std::initializer_list<double> v) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    for (double x : v) a->InsertNextValue(x);
    pd->GetFieldData()->AddArray(a);
  };
  field("camera_position", {1, 2, 3});
  field("camera_focal_point", {4, 5, 6});
  field("camera_view_up", {0, 0, 1});
  field("camera_view_angle", {50});
  field("camera_clipping_range", {2, 9000});
  const auto path = dir.path() / "drawn.vtp";
  auto write = [&] {
    vtkNew<vtkXMLPolyDataWriter> w;
    w->SetInputData(pd);
    w->SetFileName(path.c_str());
    ASSERT_EQ(w->Write(), 1);
  };
  write();
  EXPECT_THROW(read_drawn(path), std::runtime_error);  // no background yet
  vtkNew<vtkUnsignedCharArray> bg;
  bg->SetName("background");
  bg->SetNumberOfComponents(3);
  const std::uint8_t rgb[3] = {7, 8, 9};
  bg->InsertNextTypedTuple(rgb);
  pd->GetFieldData()->AddArray(bg);
  write();
  const Drawn d = read_drawn(path);
  EXPECT_EQ(d.terrain_triangles, 1u);
  EXPECT_EQ(d.skirt_triangles, 1u);
  EXPECT_EQ(d.merged_triangles, 2u);
  EXPECT_EQ(d.terrain->GetNumberOfPolys(), 2);
  EXPECT_EQ(d.position, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(d.view_angle, 50);
  EXPECT_EQ(d.clipping_range, (std::array<double, 2>{2, 9000}));
  EXPECT_EQ(d.background, (std::array<std::uint8_t, 3>{7, 8, 9}));
  EXPECT_FALSE(d.background_top.has_value());
  EXPECT_THROW(read_drawn(dir.path() / "missing.vtp"), std::runtime_error);
}

}  // namespace
}  // namespace terravol::reference
