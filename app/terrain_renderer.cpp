#include "app/terrain_renderer.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkShaderProperty.h>
#include <vtkSignedCharArray.h>
#include <vtkTexture.h>
#include <vtkTypeInt32Array.h>
#include <vtkUniforms.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <stdexcept>

#include "app/camera.h"
#include "app/ordered_mapper.h"
#include "app/png_output.h"

#include <X11/Xlib.h>

namespace terravol::app {

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be three packed floats");

namespace {

void set_rgb(const Rgb& c, double out[3]) {
  for (int k = 0; k < 3; ++k) out[k] = c[k] / 255.0;
}

// One X connection for the whole process, handed to every VTK window. Xvfb (as xvfb-run
// starts it) resets when its last client disconnects and refuses connections meanwhile, so a
// check that opened and closed its own connection, or a window that closed its own, could
// make the next XOpenDisplay fail, and VTK aborts when it does. Opening is retried for a
// second for the same reason (another process may just have left the server).
Display* shared_display() {
  static Display* display = [] {
    Display* d = nullptr;
    for (int attempt = 0; attempt < 20 && d == nullptr; ++attempt) {
      if (attempt > 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      d = XOpenDisplay(nullptr);
    }
    return d;
  }();
  return display;
}

}  // namespace

void require_x_display() {
  const char* name = std::getenv("DISPLAY");
  const bool named = name != nullptr && *name != '\0';
  if (!named || shared_display() == nullptr) {
    throw std::runtime_error("render needs an X display and none can be opened (DISPLAY=" +
                             std::string(named ? name : "(unset)") +
                             "); run it under xvfb-run -a -s \"-screen 0 1920x1080x24\"");
  }
}

TerrainRenderer::TerrainRenderer(const std::vector<glm::vec3>& positions, const TerrainShading& shading,
                                 const RenderSettings& settings, const ColorTexture& texture)
    : settings_(settings), shade_(shading.shade), point_rgba_(shading.rgba) {
  const std::size_t n = positions.size();
  if (shading.rgba.size() != n || shading.normals.size() != n || shading.shade.size() != n) {
    throw std::invalid_argument("TerrainRenderer: " + std::to_string(n) + " positions but " +
                                std::to_string(shading.rgba.size()) + " colours");
  }
  if (settings.width <= 0 || settings.height <= 0) throw std::invalid_argument("TerrainRenderer: empty image size");
  const auto count = static_cast<vtkIdType>(n);

  vtkNew<vtkFloatArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(count);
  std::memcpy(xyz->GetPointer(0), positions.data(), n * sizeof(glm::vec3));
  vtkNew<vtkPoints> points;
  points->SetData(xyz);
  poly_->SetPoints(points);

  vtkNew<vtkFloatArray> normals;
  normals->SetName("normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(count);
  std::memcpy(normals->GetPointer(0), shading.normals.data(), n * sizeof(glm::vec3));
  poly_->GetPointData()->SetNormals(normals);

  vtkNew<vtkUnsignedCharArray> rgba;
  rgba->SetName("rgba");
  rgba->SetNumberOfComponents(4);
  rgba->SetNumberOfTuples(count);
  std::memcpy(rgba->GetPointer(0), shading.rgba.data(), n * sizeof(Rgba));
  poly_->GetPointData()->SetScalars(rgba);
  poly_->SetPolys(vtkNew<vtkCellArray>());
  if (texture.side > 0) {
    if (shading.tcoords.size() != n || texture.rgba.size() != static_cast<std::size_t>(texture.side) * texture.side) {
      throw std::invalid_argument("TerrainRenderer: texture coordinates or texture size do not match");
    }
    texture_side_ = texture.side;
    vtkNew<vtkFloatArray> tcoords;
    tcoords->SetName("tcoords");
    tcoords->SetNumberOfComponents(2);
    tcoords->SetNumberOfTuples(count);
    std::memcpy(tcoords->GetPointer(0), shading.tcoords.data(), n * sizeof(glm::vec2));
    poly_->GetPointData()->SetTCoords(tcoords);

    vtkNew<vtkUnsignedCharArray> texels;
    texels->SetNumberOfComponents(4);
    texels->SetNumberOfTuples(static_cast<vtkIdType>(texture.rgba.size()));
    std::memcpy(texels->GetPointer(0), texture.rgba.data(), texture.rgba.size() * sizeof(Rgba));
    texture_image_->SetDimensions(texture.side, texture.side, 1);
    texture_image_->GetPointData()->SetScalars(texels);
    texture_->SetInputData(texture_image_);
    // Bilinear only: on llvmpipe mipmaps cost about 20 ms per 1280x720 frame and 8x anisotropic
    // filtering about 70 ms, with no visible gain in oblique views (a texel is about a pixel
    // at the distances the LOD threshold keeps fine).
    texture_->InterpolateOn();
    texture_->MipmapOff();
    texture_->EdgeClampOn();
    texture_->RepeatOff();
    texture_->SetColorModeToDirectScalars();
  }

  if (settings.order == DrawOrder::kBsp) {
    mapper_ = vtkSmartPointer<OrderedPolyDataMapper>::New();
  } else {
    mapper_ = vtkSmartPointer<vtkPolyDataMapper>::New();
  }
  mapper_->SetInputData(poly_);
  mapper_->SetColorModeToDirectScalars();
  mapper_->InterpolateScalarsBeforeMappingOff();

  actor_->SetMapper(mapper_);
  actor_->ForceOpaqueOn();  // drawn in the opaque pass, in our order
  vtkProperty* property = actor_->GetProperty();
  property->LightingOff();  // the shading is baked into the colours (terrain_colors.h)
  property->SetColor(1.0, 1.0, 1.0);
  if (settings.wireframe) property->SetRepresentationToWireframe();
  if (settings.haze_distance > 0.0) {
    // The haze of each vertex from its depth along the view axis (clip-space w), interpolated,
    // and mixed in after VTK's own colour and texture code. Per fragment (depth linearised
    // from gl_FragCoord.z) it cost about 18 ms more per 1280x720 frame on llvmpipe, where
    // back-to-front drawing shades every layer of the terrain; per vertex the difference is
    // invisible (the fade is smooth and coarse triangles are far).
    vtkShaderProperty* shader = actor_->GetShaderProperty();
    shader->AddVertexShaderReplacement("//VTK::PositionVC::Dec", true,
                                       "//VTK::PositionVC::Dec\nout float hazeAmount;\n", false);
    shader->AddVertexShaderReplacement(
        "//VTK::PositionVC::Impl", true,
        "//VTK::PositionVC::Impl\n  hazeAmount = 0.85 * (1.0 - exp(-gl_Position.w / hazeDistance));\n", false);
    shader->AddFragmentShaderReplacement("//VTK::PositionVC::Dec", true,
                                         "//VTK::PositionVC::Dec\nin float hazeAmount;\n", false);
    shader->AddFragmentShaderReplacement(
        "//VTK::TCoord::Impl", true,
        "//VTK::TCoord::Impl\n  gl_FragData[0].rgb = mix(gl_FragData[0].rgb, hazeColor, hazeAmount);\n", false);
    shader->GetVertexCustomUniforms()->SetUniformf("hazeDistance", static_cast<float>(settings.haze_distance));
    const float color[3] = {settings.haze_color[0] / 255.0f, settings.haze_color[1] / 255.0f,
                            settings.haze_color[2] / 255.0f};
    shader->GetFragmentCustomUniforms()->SetUniform3f("hazeColor", color);
  }
  apply_color_mode();

  renderer_->AddActor(actor_);
  renderer_->UseDepthPeelingOff();
  renderer_->UseFXAAOff();
  renderer_->AutomaticLightCreationOff();
  double c[3];
  set_rgb(settings.background, c);
  renderer_->SetBackground(c);
  if (settings.gradient) {
    set_rgb(settings.background_top, c);
    renderer_->SetBackground2(c);
    renderer_->GradientBackgroundOn();
  }

  require_x_display();
  window_->SetDisplayId(shared_display());  // not owned: VTK leaves it open
  window_->SetOffScreenRendering(settings.offscreen ? 1 : 0);
  window_->SetMultiSamples(0);
  window_->SetAlphaBitPlanes(0);
  window_->SetSize(settings.width, settings.height);
  window_->AddRenderer(renderer_);
}

TerrainRenderer::~TerrainRenderer() { window_->Finalize(); }

vtkCamera* TerrainRenderer::camera() { return renderer_->GetActiveCamera(); }

void TerrainRenderer::set_camera(const mrbsp::Camera& camera, double far_plane) {
  apply_camera(camera, far_plane, *renderer_->GetActiveCamera());
}

void TerrainRenderer::set_frame(const mrbsp::Frame& frame) {
  const auto triangles = static_cast<vtkIdType>(frame.indices.size() / 3);
  vtkNew<vtkTypeInt32Array> connectivity;
  connectivity->SetNumberOfValues(3 * triangles);
  std::int32_t* out = connectivity->GetPointer(0);
  for (std::size_t k = 0; k < frame.indices.size(); ++k) out[k] = static_cast<std::int32_t>(frame.indices[k]);
  vtkNew<vtkCellArray> polys;
  polys->SetData(3, connectivity);
  poly_->SetPolys(polys);

  vtkNew<vtkSignedCharArray> level;
  level->SetName("level");
  level->SetNumberOfValues(triangles);
  std::copy(frame.level.begin(), frame.level.begin() + std::min<std::size_t>(frame.level.size(), triangles),
            level->GetPointer(0));
  poly_->GetCellData()->AddArray(level);

  if (settings_.lod_colors) {
    vtkNew<vtkUnsignedCharArray> colors;
    colors->SetName("lod_rgba");
    colors->SetNumberOfComponents(4);
    colors->SetNumberOfTuples(triangles);
    auto* rgba = reinterpret_cast<Rgba*>(colors->GetPointer(0));
    for (vtkIdType t = 0; t < triangles; ++t) {
      const int lv = t < static_cast<vtkIdType>(frame.level.size()) ? frame.level[t] : mrbsp::kSkirtLevel;
      const std::uint32_t* v = &frame.indices[3 * t];
      if (lv == mrbsp::kSkirtLevel) {
        rgba[t] = kSkirtColor;
        continue;
      }
      if (lv < 0) {  // merged polygons keep their own colour
        rgba[t] = point_rgba_[v[0]];
        continue;
      }
      const float s = (shade_[v[0]] + shade_[v[1]] + shade_[v[2]]) / 3.0f;
      rgba[t] = shaded(lod_color(lv), s);
    }
    poly_->GetCellData()->AddArray(colors);
  }
  poly_->Modified();
}

void TerrainRenderer::apply_color_mode() {
  const bool textured = texture_side_ > 0 && !settings_.lod_colors;
  actor_->SetTexture(textured ? texture_.GetPointer() : nullptr);
  if (textured) {
    mapper_->ScalarVisibilityOff();  // the texture gives the colour
  } else if (settings_.lod_colors) {
    mapper_->ScalarVisibilityOn();
    mapper_->SetScalarModeToUseCellFieldData();
    mapper_->SelectColorArray("lod_rgba");
  } else {
    mapper_->ScalarVisibilityOn();
    mapper_->SetScalarModeToUsePointData();
  }
  if (settings_.haze_distance > 0.0) {  // the shader replacement exists: fade, or not at all
    const double distance = settings_.lod_colors ? 1e30 : settings_.haze_distance;
    actor_->GetShaderProperty()->GetVertexCustomUniforms()->SetUniformf("hazeDistance", static_cast<float>(distance));
  }
}

void TerrainRenderer::set_lod_colors(bool on) {
  if (on == settings_.lod_colors) return;
  settings_.lod_colors = on;
  apply_color_mode();
}

void TerrainRenderer::set_wireframe(bool on) {
  settings_.wireframe = on;
  if (on) {
    actor_->GetProperty()->SetRepresentationToWireframe();
  } else {
    actor_->GetProperty()->SetRepresentationToSurface();
  }
}

void TerrainRenderer::replace_vertices(const std::vector<glm::vec3>& positions, const TerrainShading& shading,
                                       const ColorTexture& texture) {
  const std::size_t n = positions.size();
  if (n != static_cast<std::size_t>(poly_->GetNumberOfPoints()) || shading.rgba.size() != n ||
      shading.normals.size() != n || shading.shade.size() != n || texture.side != texture_side_ ||
      texture.rgba.size() != static_cast<std::size_t>(texture.side) * texture.side) {
    throw std::invalid_argument("TerrainRenderer::replace_vertices: " + std::to_string(n) + " positions for " +
                                std::to_string(poly_->GetNumberOfPoints()) + " vertices, or attributes that differ");
  }
  auto copy = [](vtkDataArray* to, const void* from, std::size_t bytes) {
    std::memcpy(to->GetVoidPointer(0), from, bytes);
    to->Modified();
  };
  copy(poly_->GetPoints()->GetData(), positions.data(), n * sizeof(glm::vec3));
  poly_->GetPoints()->Modified();
  copy(poly_->GetPointData()->GetNormals(), shading.normals.data(), n * sizeof(glm::vec3));
  copy(poly_->GetPointData()->GetScalars(), shading.rgba.data(), n * sizeof(Rgba));
  shade_ = shading.shade;
  point_rgba_ = shading.rgba;
  if (texture_side_ > 0) {
    copy(texture_image_->GetPointData()->GetScalars(), texture.rgba.data(), texture.rgba.size() * sizeof(Rgba));
    texture_image_->Modified();
  }
  poly_->Modified();
}

double TerrainRenderer::render() {
  const auto t0 = std::chrono::steady_clock::now();
  window_->Render();
  window_->WaitForCompletion();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<std::uint8_t> TerrainRenderer::png() const { return window_png(window_); }

}  // namespace terravol::app
