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
  const bool textured = texture.side > 0 && !settings.lod_colors;
  if (textured) {
    if (shading.tcoords.size() != n || texture.rgba.size() != static_cast<std::size_t>(texture.side) * texture.side) {
      throw std::invalid_argument("TerrainRenderer: texture coordinates or texture size do not match");
    }
    vtkNew<vtkFloatArray> tcoords;
    tcoords->SetName("tcoords");
    tcoords->SetNumberOfComponents(2);
    tcoords->SetNumberOfTuples(count);
    std::memcpy(tcoords->GetPointer(0), shading.tcoords.data(), n * sizeof(glm::vec2));
    poly_->GetPointData()->SetTCoords(tcoords);
  }

  if (settings.order == DrawOrder::kBsp) {
    mapper_ = vtkSmartPointer<OrderedPolyDataMapper>::New();
  } else {
    mapper_ = vtkSmartPointer<vtkPolyDataMapper>::New();
  }
  mapper_->SetInputData(poly_);
  mapper_->ScalarVisibilityOn();
  mapper_->SetColorModeToDirectScalars();
  if (textured) {
    mapper_->ScalarVisibilityOff();  // the texture gives the colour
  } else if (settings.lod_colors) {
    mapper_->SetScalarModeToUseCellFieldData();
    mapper_->SelectColorArray("lod_rgba");
  } else {
    mapper_->SetScalarModeToUsePointData();
  }
  mapper_->InterpolateScalarsBeforeMappingOff();

  actor_->SetMapper(mapper_);
  actor_->ForceOpaqueOn();  // drawn in the opaque pass, in our order
  vtkProperty* property = actor_->GetProperty();
  property->LightingOff();  // the shading is baked into the colours (terrain_colors.h)
  if (settings.wireframe) property->SetRepresentationToWireframe();
  if (textured) {
    vtkNew<vtkUnsignedCharArray> texels;
    texels->SetNumberOfComponents(4);
    texels->SetNumberOfTuples(static_cast<vtkIdType>(texture.rgba.size()));
    std::memcpy(texels->GetPointer(0), texture.rgba.data(), texture.rgba.size() * sizeof(Rgba));
    vtkNew<vtkImageData> image;
    image->SetDimensions(texture.side, texture.side, 1);
    image->GetPointData()->SetScalars(texels);
    vtkNew<vtkTexture> colors;
    colors->SetInputData(image);
    // Bilinear only: on llvmpipe mipmaps cost about 20 ms per 1280x720 frame and 8x anisotropic
    // filtering about 70 ms, with no visible gain in oblique views (a texel is about a pixel
    // at the distances the LOD threshold keeps fine).
    colors->InterpolateOn();
    colors->MipmapOff();
    colors->EdgeClampOn();
    colors->RepeatOff();
    colors->SetColorModeToDirectScalars();
    actor_->SetTexture(colors);
    property->SetColor(1.0, 1.0, 1.0);
  }
  if (settings.haze_distance > 0.0) {
    // After VTK's own colour, lighting and texture code: fade by depth, linearised from the
    // clipping range.
    vtkShaderProperty* shader = actor_->GetShaderProperty();
    shader->AddFragmentShaderReplacement("//VTK::TCoord::Impl", true,
                                         "//VTK::TCoord::Impl\n"
                                         "  {\n"
                                         "    float zn = 2.0 * gl_FragCoord.z - 1.0;\n"
                                         "    float depth = 2.0 * hazeNear * hazeFar / (hazeFar + hazeNear - zn * (hazeFar - hazeNear));\n"
                                         "    float haze = 0.85 * (1.0 - exp(-depth / hazeDistance));\n"
                                         "    gl_FragData[0].rgb = mix(gl_FragData[0].rgb, hazeColor, haze);\n"
                                         "  }\n",
                                         false);
    vtkUniforms* uniforms = shader->GetFragmentCustomUniforms();
    uniforms->SetUniformf("hazeDistance", static_cast<float>(settings.haze_distance));
    const float color[3] = {settings.haze_color[0] / 255.0f, settings.haze_color[1] / 255.0f,
                            settings.haze_color[2] / 255.0f};
    uniforms->SetUniform3f("hazeColor", color);
    uniforms->SetUniformf("hazeNear", 1.0f);
    uniforms->SetUniformf("hazeFar", 2.0f);
  }

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
  window_->SetOffScreenRendering(1);
  window_->SetMultiSamples(0);
  window_->SetAlphaBitPlanes(0);
  window_->SetSize(settings.width, settings.height);
  window_->AddRenderer(renderer_);
}

TerrainRenderer::~TerrainRenderer() { window_->Finalize(); }

vtkCamera* TerrainRenderer::camera() { return renderer_->GetActiveCamera(); }

void TerrainRenderer::set_camera(const mrbsp::Camera& camera, double far_plane) {
  apply_camera(camera, far_plane, *renderer_->GetActiveCamera());
  if (settings_.haze_distance > 0.0) {
    vtkUniforms* uniforms = actor_->GetShaderProperty()->GetFragmentCustomUniforms();
    uniforms->SetUniformf("hazeNear", static_cast<float>(camera.near_plane));
    uniforms->SetUniformf("hazeFar", static_cast<float>(far_plane));
  }
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

double TerrainRenderer::render() {
  const auto t0 = std::chrono::steady_clock::now();
  window_->Render();
  window_->WaitForCompletion();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<std::uint8_t> TerrainRenderer::png() const { return window_png(window_); }

}  // namespace terravol::app
