#include "reference/draw.h"

#include <X11/Xlib.h>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDepthPeelingPass.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLRenderer.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTexture.h>
#include <vtkTranslucentPass.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace terravol::reference {

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw std::runtime_error(path.string() + ": " + what);
}

template <std::size_t N>
std::array<double, N> field(vtkFieldData* fd, const char* name, const std::filesystem::path& path) {
  vtkDataArray* a = fd->GetArray(name);
  if (a == nullptr || a->GetNumberOfValues() != static_cast<vtkIdType>(N)) fail(path, std::string("no field data ") + name);
  std::array<double, N> v{};
  for (std::size_t k = 0; k < N; ++k) v[k] = a->GetComponent(0, static_cast<int>(k));
  return v;
}

std::optional<std::array<std::uint8_t, 3>> rgb_field(vtkFieldData* fd, const char* name) {
  vtkDataArray* a = fd->GetArray(name);
  if (a == nullptr || a->GetNumberOfValues() != 3) return std::nullopt;
  std::array<std::uint8_t, 3> c{};
  for (int k = 0; k < 3; ++k) c[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(a->GetComponent(0, k));
  return c;
}

// A renderer that peels with vtkDepthPeelingPass (one layer a peel) where vtkOpenGLRenderer
// would choose vtkDualDepthPeelingPass. VTK 9.1's dual peeling is not exact over opaque
// geometry: where an opaque surface lies behind the translucent layers of a pixel, that pixel's
// back peel is the opaque depth and stays empty, so its layers come off the front one a peel;
// but peeling stops when no pixel's back peel writes anything (the occlusion query wraps the
// back blend only), and the layers left are then dropped, not even blended unsorted (the
// mop-up runs only when pixels were written). Over terrain that happens as soon as the
// translucent pixels seen against the sky run out of layers (tests/reference/draw_test.cpp
// shows it: twelve layers over an opaque square composite as one). The single-layer pass counts
// the fragments of every peel and stops only when a peel finds none. vtkOpenGLRenderer creates
// its peeling pass only when it has none, so setting one here is enough.
class SingleLayerPeelingRenderer : public vtkOpenGLRenderer {
 public:
  static SingleLayerPeelingRenderer* New();
  vtkTypeMacro(SingleLayerPeelingRenderer, vtkOpenGLRenderer);

 protected:
  SingleLayerPeelingRenderer() {
    vtkDepthPeelingPass* peeling = vtkDepthPeelingPass::New();  // owned by vtkOpenGLRenderer
    vtkNew<vtkTranslucentPass> translucent;
    peeling->SetTranslucentPass(translucent);
    this->DepthPeelingPass = peeling;
  }
  ~SingleLayerPeelingRenderer() override = default;

 private:
  SingleLayerPeelingRenderer(const SingleLayerPeelingRenderer&) = delete;
  void operator=(const SingleLayerPeelingRenderer&) = delete;
};
vtkStandardNewMacro(SingleLayerPeelingRenderer);

// Colours as given: direct RGBA scalars, no lighting, both faces.
void unlit(vtkPolyDataMapper& mapper, vtkActor& actor) {
  mapper.SetColorModeToDirectScalars();
  mapper.SetScalarModeToUsePointData();
  mapper.ScalarVisibilityOn();
  mapper.InterpolateScalarsBeforeMappingOff();
  actor.SetMapper(&mapper);
  vtkProperty* p = actor.GetProperty();
  p->LightingOff();
  p->SetAmbient(1.0);
  p->SetDiffuse(0.0);
  p->SetSpecular(0.0);
  p->SetColor(1.0, 1.0, 1.0);
  p->BackfaceCullingOff();
}

}  // namespace

void require_display() {
  // Kept open for the life of the process: Xvfb resets when its last client leaves and refuses
  // connections while it does, which a render run as a child process between two of ours
  // would otherwise trigger ("bad X server connection", and VTK aborts).
  static Display* const kept = XOpenDisplay(nullptr);
  if (kept == nullptr) throw std::runtime_error("reference: cannot open an X display (set DISPLAY, or run under xvfb-run)");
}

Drawn read_drawn(const std::filesystem::path& vtp) {
  if (!std::filesystem::exists(vtp)) fail(vtp, "no such file");
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(vtp.c_str());
  reader->Update();
  vtkPolyData* in = reader->GetOutput();
  if (in == nullptr || in->GetNumberOfPoints() == 0) fail(vtp, "no points (not a VTK XML PolyData file?)");
  vtkDataArray* level = in->GetCellData()->GetArray("level");
  vtkDataArray* rgba = in->GetPointData()->GetArray("rgba");
  if (level == nullptr || level->GetNumberOfTuples() != in->GetNumberOfPolys()) fail(vtp, "no \"level\" per triangle");
  if (rgba == nullptr || rgba->GetNumberOfComponents() != 4) fail(vtp, "no \"rgba\" point data");

  Drawn d;
  vtkCellArray* polys = in->GetPolys();
  vtkNew<vtkCellArray> terrain;
  vtkNew<vtkIdList> cell;
  for (vtkIdType c = 0; c < polys->GetNumberOfCells(); ++c) {
    const double lv = level->GetTuple1(c);
    if (lv < -1.0) {
      ++d.merged_triangles;
      continue;
    }
    polys->GetCellAtId(c, cell);
    terrain->InsertNextCell(cell);
    ++(lv < 0 ? d.skirt_triangles : d.terrain_triangles);
  }
  d.terrain = vtkSmartPointer<vtkPolyData>::New();
  d.terrain->SetPoints(in->GetPoints());
  d.terrain->SetPolys(terrain);
  d.terrain->GetPointData()->SetScalars(rgba);

  vtkFieldData* fd = in->GetFieldData();
  d.position = field<3>(fd, "camera_position", vtp);
  d.focal_point = field<3>(fd, "camera_focal_point", vtp);
  d.view_up = field<3>(fd, "camera_view_up", vtp);
  d.view_angle = field<1>(fd, "camera_view_angle", vtp)[0];
  d.clipping_range = field<2>(fd, "camera_clipping_range", vtp);
  const auto bg = rgb_field(fd, "background");
  if (!bg) fail(vtp, "no field data background");
  d.background = *bg;
  d.background_top = rgb_field(fd, "background_top");
  return d;
}

void texture_terrain(Drawn& drawn, const Frame& frame, const WindowLattice& w) {
  if (w.cells < 1) throw std::runtime_error("reference: a window of " + std::to_string(w.cells) + " cells");
  const int side = w.cells + 1;
  const double dlat = (w.north - w.south) / w.cells, dlon = (w.east - w.west) / w.cells;
  vtkPoints* points = drawn.terrain->GetPoints();
  vtkDataArray* rgba = drawn.terrain->GetPointData()->GetScalars();
  const vtkIdType n = points->GetNumberOfPoints();
  std::vector<int> lattice(static_cast<std::size_t>(n), -1);  // row * side + column
  auto place = [&](vtkIdType p) {
    int& at = lattice[static_cast<std::size_t>(p)];
    if (at >= 0) return at;
    double xyz[3];
    points->GetPoint(p, xyz);
    const double fc = (frame.lon_of(xyz[0]) - w.west) / dlon, fr = (frame.lat_of(xyz[1]) - w.south) / dlat;
    const double c = std::round(fc), r = std::round(fr);
    if (std::abs(fc - c) > 0.01 || std::abs(fr - r) > 0.01 || c < 0 || r < 0 || c >= side || r >= side) {
      throw std::runtime_error("reference: an exported terrain point lies off the window's lattice lines "
                               "(column " + std::to_string(fc) + ", row " + std::to_string(fr) + ")");
    }
    at = static_cast<int>(r) * side + static_cast<int>(c);
    return at;
  };
  vtkNew<vtkUnsignedCharArray> texels;
  texels->SetNumberOfComponents(4);
  texels->SetNumberOfTuples(static_cast<vtkIdType>(side) * side);
  texels->Fill(0);
  vtkCellArray* polys = drawn.terrain->GetPolys();
  vtkNew<vtkIdList> cell;
  for (vtkIdType t = 0; t < polys->GetNumberOfCells(); ++t) {
    polys->GetCellAtId(t, cell);
    int lo_c = side, hi_c = -1, lo_r = side, hi_r = -1;
    for (vtkIdType k = 0; k < cell->GetNumberOfIds(); ++k) {
      const int at = place(cell->GetId(k));
      lo_c = std::min(lo_c, at % side), hi_c = std::max(hi_c, at % side);
      lo_r = std::min(lo_r, at / side), hi_r = std::max(hi_r, at / side);
    }
    if (hi_c - lo_c > 1 || hi_r - lo_r > 1) {
      throw std::runtime_error("reference: an exported terrain triangle spans more than one lattice cell "
                               "(render with --full-res)");
    }
  }
  // A sample's colour from its own point, the highest of those on its lattice line (crack-fill
  // bottoms hang below it).
  std::vector<double> top(static_cast<std::size_t>(side) * side, -std::numeric_limits<double>::infinity());
  vtkNew<vtkFloatArray> tcoords;
  tcoords->SetName("tcoords");
  tcoords->SetNumberOfComponents(2);
  tcoords->SetNumberOfTuples(n);
  for (vtkIdType p = 0; p < n; ++p) {
    const int at = lattice[static_cast<std::size_t>(p)];
    if (at < 0) {  // a point no terrain triangle uses
      tcoords->SetTuple2(p, 0.0, 0.0);
      continue;
    }
    const int c = at % side, r = at / side;
    tcoords->SetTuple2(p, (c + 0.5f) / static_cast<float>(side), (r + 0.5f) / static_cast<float>(side));
    double xyz[3];
    points->GetPoint(p, xyz);
    if (xyz[2] > top[static_cast<std::size_t>(at)]) {
      top[static_cast<std::size_t>(at)] = xyz[2];
      double v[4];
      rgba->GetTuple(p, v);
      for (int k = 0; k < 4; ++k) texels->SetComponent(at, k, v[k]);
    }
  }
  drawn.terrain->GetPointData()->SetTCoords(tcoords);
  drawn.texture = vtkSmartPointer<vtkImageData>::New();
  drawn.texture->SetDimensions(side, side, 1);
  drawn.texture->GetPointData()->SetScalars(texels);
}

Image draw(const Drawn& drawn, const Mesh& volumes, int width, int height) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("reference: empty image size");
  require_display();
  vtkNew<SingleLayerPeelingRenderer> renderer;
  vtkNew<vtkRenderWindow> window;

  vtkNew<vtkPolyDataMapper> terrain_mapper;
  vtkNew<vtkActor> terrain_actor;
  terrain_mapper->SetInputData(drawn.terrain);
  unlit(*terrain_mapper, *terrain_actor);
  terrain_actor->ForceOpaqueOn();
  vtkNew<vtkTexture> texture;
  if (drawn.texture) {
    texture->SetInputData(drawn.texture);
    texture->InterpolateOn();
    texture->MipmapOff();
    texture->EdgeClampOn();
    texture->RepeatOff();
    texture->SetColorModeToDirectScalars();
    terrain_actor->SetTexture(texture);
    terrain_mapper->ScalarVisibilityOff();  // the texture alone, not texture times vertex colour
  }
  renderer->AddActor(terrain_actor);

  vtkNew<vtkPolyData> overlay;
  vtkNew<vtkPolyDataMapper> overlay_mapper;
  vtkNew<vtkActor> overlay_actor;
  if (!volumes.triangles.empty()) {
    vtkNew<vtkDoubleArray> xyz;
    xyz->SetNumberOfComponents(3);
    xyz->SetNumberOfTuples(static_cast<vtkIdType>(volumes.vertices.size()));
    std::memcpy(xyz->GetPointer(0), volumes.vertices.data(), volumes.vertices.size() * sizeof(glm::dvec3));
    vtkNew<vtkPoints> points;
    points->SetData(xyz);
    vtkNew<vtkUnsignedCharArray> rgba;
    rgba->SetName("rgba");
    rgba->SetNumberOfComponents(4);
    rgba->SetNumberOfTuples(static_cast<vtkIdType>(volumes.colors.size()));
    std::memcpy(rgba->GetPointer(0), volumes.colors.data(), 4 * volumes.colors.size());
    vtkNew<vtkIdTypeArray> ids;
    ids->SetNumberOfValues(static_cast<vtkIdType>(volumes.triangles.size()));
    for (std::size_t k = 0; k < volumes.triangles.size(); ++k) ids->SetValue(static_cast<vtkIdType>(k), volumes.triangles[k]);
    vtkNew<vtkCellArray> cells;
    cells->SetData(3, ids);
    overlay->SetPoints(points);
    overlay->SetPolys(cells);
    overlay->GetPointData()->SetScalars(rgba);
    overlay_mapper->SetInputData(overlay);
    unlit(*overlay_mapper, *overlay_actor);
    overlay_actor->ForceTranslucentOn();
    renderer->AddActor(overlay_actor);
  }

  renderer->SetUseDepthPeeling(1);
  renderer->SetMaximumNumberOfPeels(std::numeric_limits<int>::max());
  renderer->SetOcclusionRatio(0.0);
  renderer->UseFXAAOff();
  renderer->AutomaticLightCreationOff();
  const auto& bg = drawn.background;
  renderer->SetBackground(bg[0] / 255.0, bg[1] / 255.0, bg[2] / 255.0);
  if (drawn.background_top) {
    const auto& top = *drawn.background_top;
    renderer->GradientBackgroundOn();
    renderer->SetBackground2(top[0] / 255.0, top[1] / 255.0, top[2] / 255.0);
  }
  vtkNew<vtkCamera> camera;
  camera->SetPosition(drawn.position.data());
  camera->SetFocalPoint(drawn.focal_point.data());
  camera->SetViewUp(drawn.view_up.data());
  camera->SetViewAngle(drawn.view_angle);
  camera->SetClippingRange(drawn.clipping_range[0], drawn.clipping_range[1]);
  renderer->SetActiveCamera(camera);

  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetAlphaBitPlanes(1);
  window->SetSize(width, height);
  window->AddRenderer(renderer);
  window->Render();
  window->WaitForCompletion();

  vtkNew<vtkUnsignedCharArray> pixels;
  window->GetPixelData(0, 0, width - 1, height - 1, 0, pixels, 0);
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.resize(static_cast<std::size_t>(width) * height * 3);
  const int comps = pixels->GetNumberOfComponents();
  for (int y = 0; y < height; ++y) {  // VTK's rows run from the bottom
    for (int x = 0; x < width; ++x) {
      const std::size_t from = static_cast<std::size_t>(y) * width + x;
      const std::size_t to = static_cast<std::size_t>(height - 1 - y) * width + x;
      for (int c = 0; c < 3; ++c) image.rgb[3 * to + c] = pixels->GetValue(static_cast<vtkIdType>(from * comps + c));
    }
  }
  window->Finalize();
  return image;
}

}  // namespace terravol::reference
