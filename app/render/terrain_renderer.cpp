#include "app/render/terrain_renderer.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDepthSortPolyData.h>
#include <vtkLookupTable.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkOpenGLPolyDataMapper.h>
#include <vtkOpenGLVertexBufferObject.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderStepsPass.h>
#include <vtkFramebufferPass.h>
#include <vtkTextureObject.h>
#include <vtkCullerCollection.h>
#include <vtkRenderer.h>
#include <vtkActor2D.h>
#include <vtkImageMapper.h>
#include <vtkTextProperty.h>
#include <vtkShaderProperty.h>
#include <vtkSignedCharArray.h>
#include <vtkTexture.h>
#include <vtkTypeInt32Array.h>
#include <vtkUniforms.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <limits>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <stdexcept>

#include "app/render/legend_image.h"
#include "app/render/ordered_mapper.h"
#include "app/render/vtk_camera.h"
#include "app/scene/timing.h"
#include "volume/colormap.h"

#include <X11/Xlib.h>

namespace terravol::app::render {

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be three packed floats");

namespace {

void set_rgb(const scene::Rgb& c, double out[3]) {
  for (int k = 0; k < 3; ++k) out[k] = c[k] / 255.0;
}

// The ordered mapper blends only when a colour it may draw is translucent: the vertices' RGBA
// (merged polygons), the texels, and under --lod-colors the level colours (opaque) and merged
// vertices' RGBA again. With alpha 1 everywhere blending gives the same image, and it costs
// about 10% of the terrain's fragment work on llvmpipe. O(vertices + texels): once per upload.
void choose_blending(vtkPolyDataMapper& mapper, std::span<const scene::Rgba> vertex_rgba,
                     std::span<const scene::Rgba> texels) {
  auto* ordered = OrderedPolyDataMapper::SafeDownCast(&mapper);
  if (ordered == nullptr) return;
  const auto opaque = [](const scene::Rgba& c) { return c[3] == 255; };
  ordered->set_blending(!std::all_of(vertex_rgba.begin(), vertex_rgba.end(), opaque) ||
                        !std::all_of(texels.begin(), texels.end(), opaque));
}

// The positions go to the GPU as they are: scene-frame floats, no coordinate shift or scale.
// VTK's default shifts them by the centre of their bounds and scales them by their range,
// values that change with every slide of the window, so that writing new positions in place
// (glBufferSubData, OrderedPolyDataMapper::update_vertices) with the last upload's shift gave
// pictures a few bytes off a fresh upload's; VTK then had to pack and upload every position
// again at each slide (about 15 ms of the frame that lands one, 1.06 M vertices over Utah).
// Unshifted, a fresh upload and one in place are the same floats. What it costs is precision:
// the tree's positions are floats in the scene frame already (half a unit in the last place
// is 4 mm 100 km from its origin), and the vertex transform in floats adds an error of the
// same order (float epsilon times the eye's distance from the origin), where VTK's shift
// made it about the eye's distance from the window's centre.
void unshifted(vtkPolyDataMapper& mapper) {
  if (auto* gl = vtkOpenGLPolyDataMapper::SafeDownCast(&mapper)) {
    gl->SetVBOShiftScaleMethod(vtkOpenGLVertexBufferObject::DISABLE_SHIFT_SCALE);
  }
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

void require_x_display(const std::string& who) {
  const char* name = std::getenv("DISPLAY");
  const bool named = name != nullptr && *name != '\0';
  if (!named || shared_display() == nullptr) {
    throw std::runtime_error(who + " needs an X display and none can be opened (DISPLAY=" +
                             std::string(named ? name : "(unset)") +
                             "); run it under xvfb-run -a -s \"-screen 0 1920x1080x24\"");
  }
}

void use_shared_display(vtkRenderWindow* window, const std::string& who) {
  require_x_display(who);
  window->SetDisplayId(shared_display());  // not owned: VTK leaves it open
}

TerrainRenderer::TerrainRenderer(const std::vector<glm::vec3>& positions, const scene::TerrainShading& shading,
                                 const RenderSettings& settings, const ColorTexture& texture)
    : settings_(settings), shade_(shading.shade), point_rgba_(shading.rgba) {
  const std::size_t n = positions.size();
  if (shading.rgba.size() != n || shading.shade.size() != n) {
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

  vtkNew<vtkUnsignedCharArray> rgba;
  rgba->SetName("rgba");
  rgba->SetNumberOfComponents(4);
  rgba->SetNumberOfTuples(count);
  std::memcpy(rgba->GetPointer(0), shading.rgba.data(), n * sizeof(scene::Rgba));
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
    std::memcpy(texels->GetPointer(0), texture.rgba.data(), texture.rgba.size() * sizeof(scene::Rgba));
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

  if (settings.order == scene::DrawOrder::kBsp) {
    mapper_ = vtkSmartPointer<OrderedPolyDataMapper>::New();
  } else {
    mapper_ = vtkSmartPointer<vtkPolyDataMapper>::New();
  }
  mapper_->SetInputData(poly_);
  unshifted(*mapper_);
  choose_blending(*mapper_, shading.rgba, texture.rgba);
  mapper_->SetColorModeToDirectScalars();
  mapper_->InterpolateScalarsBeforeMappingOff();

  actor_->SetMapper(mapper_);
  actor_->ForceOpaqueOn();  // drawn in the opaque pass, in our order
  vtkProperty* property = actor_->GetProperty();
  property->LightingOff();  // the shading is baked into the colours (terrain_colors.h)
  // Unlit, and the polydata has no normals (TerrainShading): flat, so that no shader asks for any.
  property->SetInterpolationToFlat();
  property->SetColor(1.0, 1.0, 1.0);
  if (settings.wireframe) property->SetRepresentationToWireframe();

  if (split_orders()) {
    merged_poly_->SetPoints(poly_->GetPoints());
    merged_poly_->GetPointData()->SetScalars(poly_->GetPointData()->GetScalars());
    merged_poly_->SetPolys(vtkNew<vtkCellArray>());
    if (settings.order == scene::DrawOrder::kSort) {
      vtkNew<vtkDepthSortPolyData> sort;
      sort->SetInputData(merged_poly_);
      sort->SetCamera(renderer_->GetActiveCamera());
      sort->SetDirectionToBackToFront();
      sort->SetDepthSortModeToParametricCenter();
      merged_mapper_ = vtkSmartPointer<vtkPolyDataMapper>::New();
      merged_mapper_->SetInputConnection(sort->GetOutputPort());
    } else {
      merged_mapper_ = vtkSmartPointer<vtkPolyDataMapper>::New();
      merged_mapper_->SetInputData(merged_poly_);
    }
    unshifted(*merged_mapper_);
    merged_mapper_->SetColorModeToDirectScalars();
    merged_mapper_->InterpolateScalarsBeforeMappingOff();
    merged_mapper_->ScalarVisibilityOn();
    merged_actor_->SetMapper(merged_mapper_);
    merged_actor_->ForceTranslucentOn();
    merged_actor_->GetProperty()->LightingOff();
    merged_actor_->GetProperty()->BackfaceCullingOff();
    if (settings.wireframe) merged_actor_->GetProperty()->SetRepresentationToWireframe();
    install_shaders(*merged_actor_, false);
    renderer_->AddActor(merged_actor_);
    renderer_->SetUseDepthPeeling(settings.order == scene::DrawOrder::kPeel);
    if (settings.order == scene::DrawOrder::kSort) {
      // VTK 9.1 draws translucent geometry with weighted blended order-independent
      // translucency when depth peeling is off, which ignores the order of the cells; the
      // plain render steps blend in the sorted order instead.
      renderer_->SetPass(vtkNew<vtkRenderStepsPass>());
    }
    // No limit is INT_MAX, not 0: VTK 9.1's dual depth peeling (what it uses on llvmpipe) takes
    // 0 literally, peels nothing and blends in draw order. With occlusion ratio 0 it stops when
    // a peel writes no pixel: exact.
    renderer_->SetMaximumNumberOfPeels(settings.peels > 0 ? settings.peels : std::numeric_limits<int>::max());
    renderer_->SetOcclusionRatio(0.0);
  }
  apply_color_mode();

  renderer_->AddActor(actor_);
  {
    // The legend card: RGBA, blended over the picture, bytes passed through unscaled.
    vtkNew<vtkImageMapper> legend_mapper;
    legend_mapper->SetInputData(legend_data_);
    legend_mapper->SetColorWindow(255.0);
    legend_mapper->SetColorLevel(127.5);
    legend_actor_->SetMapper(legend_mapper);
    legend_actor_->SetVisibility(false);
    renderer_->AddActor2D(legend_actor_);
  }
  if (!split_orders()) renderer_->UseDepthPeelingOff();
  renderer_->UseFXAAOff();
  renderer_->AutomaticLightCreationOff();
  // No frustum culler: VTK's asks every actor for its bounds at every render, and the bounds of
  // a vtkPolyData (of the points its cells use, vtkPolyData::GetCellsBounds) flag and scan all
  // of its points whenever the triangle list has changed: about 3 ms per frame over the 3
  // million vertices of a 1024-cell window, whatever the frame draws. Culling would only skip
  // an actor wholly outside the view, which draws nothing anyway.
  renderer_->GetCullers()->RemoveAllItems();
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
  window_->SetAlphaBitPlanes(settings.order == scene::DrawOrder::kPeel ? 1 : 0);  // depth peeling needs alpha
  window_->SetSize(settings.width, settings.height);
  window_->AddRenderer(renderer_);
  // The markers' labels on a layer of their own over the scene, sharing its camera: its depth
  // buffer starts clear, so they show over the terrain in every draw order alike.
  window_->SetNumberOfLayers(2);
  labels_renderer_->SetLayer(1);
  labels_renderer_->UseDepthPeelingOff();
  labels_renderer_->InteractiveOff();
  labels_renderer_->SetActiveCamera(renderer_->GetActiveCamera());
  labels_renderer_->DrawOff();  // until there are labels: no second pass over the window
  window_->AddRenderer(labels_renderer_);
}

TerrainRenderer::~TerrainRenderer() {
  if (float_pass_) {
    window_->MakeCurrent();
    float_pass_->ReleaseGraphicsResources(window_);
  }
  window_->Finalize();
}

void TerrainRenderer::use_float_target(bool on) {
  if (on == (float_pass_ != nullptr && renderer_->GetPass() == float_pass_)) return;
  if (on) {
    if (!float_pass_) {
      float_pass_ = vtkSmartPointer<vtkFramebufferPass>::New();
      float_pass_->SetColorFormat(vtkTextureObject::Float32);
      float_pass_->SetDelegatePass(vtkNew<vtkRenderStepsPass>());
    }
    renderer_->SetPass(float_pass_);
  } else {
    window_->MakeCurrent();
    float_pass_->ReleaseGraphicsResources(window_);  // its colour and depth textures
    renderer_->SetPass(nullptr);
  }
}

vtkCamera* TerrainRenderer::camera() { return renderer_->GetActiveCamera(); }

void TerrainRenderer::set_camera(const mrbsp::Camera& camera, double far_plane) {
  apply_camera(camera, far_plane, *renderer_->GetActiveCamera());
}

vtkSmartPointer<vtkCellArray> triangle_cells(std::span<const std::uint32_t> indices) {
  vtkNew<vtkTypeInt32Array> connectivity;
  connectivity->SetNumberOfValues(static_cast<vtkIdType>(indices.size()));
  std::int32_t* out = connectivity->GetPointer(0);
  for (std::size_t k = 0; k < indices.size(); ++k) out[k] = static_cast<std::int32_t>(indices[k]);
  auto polys = vtkSmartPointer<vtkCellArray>::New();
  polys->SetData(3, connectivity);
  return polys;
}

void TerrainRenderer::reserve_tail(std::size_t capacity) {
  const std::size_t n = point_rgba_.size();
  const auto count = static_cast<vtkIdType>(n + capacity);
  vtkPointData* pd = poly_->GetPointData();
  const auto resize = [&](vtkDataArray* a) {
    if (a == nullptr) return;
    if (a->GetSize() < count * a->GetNumberOfComponents()) a->Resize(count);
    a->SetNumberOfTuples(count);
    a->Modified();
  };
  vtkDataArray* xyz = poly_->GetPoints()->GetData();
  for (vtkDataArray* a : {xyz, pd->GetScalars(), pd->GetTCoords()}) resize(a);
  auto* p = static_cast<float*>(xyz->GetVoidPointer(0));
  std::fill(p + 3 * n, p + 3 * (n + capacity), 0.0f);
  auto* c = static_cast<unsigned char*>(pd->GetScalars()->GetVoidPointer(0));
  std::fill(c + 4 * n, c + 4 * (n + capacity), static_cast<unsigned char>(0));
  if (pd->GetTCoords() != nullptr) {
    auto* t = static_cast<float*>(pd->GetTCoords()->GetVoidPointer(0));
    std::fill(t + 2 * n, t + 2 * (n + capacity), -1.0f);
  }
  poly_->GetPoints()->Modified();
  poly_->Modified();
  if (split_orders()) merged_poly_->Modified();
  tail_ = capacity;
}

void TerrainRenderer::set_frame(const mrbsp::Frame& frame) {
  // The frame's own vertices (colour-box faces) into the tail after the tree's.
  const std::size_t own = frame.transient_positions.size();
  if (own > 0) {
    if (frame.transient_base != point_rgba_.size()) {
      throw std::invalid_argument("TerrainRenderer::set_frame: the frame's own vertices start at " +
                                  std::to_string(frame.transient_base) + ", after " + std::to_string(point_rgba_.size()) +
                                  " vertices of the tree here");
    }
    // Room for an eighth more than asked: a density's face count moves by a few hundred when
    // its transfer function or the view changes a little, and an exact fit made the next such
    // frame grow the tail, so upload every vertex again (1.0 s more upload and 2.5 s more draw
    // for the 21 million face vertices of the bench's default density, whose frames take 3 s).
    // The eighth costs 3 of a face vertex's 24 bytes; doubling cost all 24 again.
    const bool grown = own > tail_;
    if (grown) reserve_tail(std::max({own + own / 8, tail_ + tail_ / 8, std::size_t{4096}}));
    const std::size_t base = point_rgba_.size();
    write_vertices(base, frame.transient_positions, frame.transient_colors.data());
    auto* ordered = OrderedPolyDataMapper::SafeDownCast(mapper_);
    if (ordered != nullptr && !grown) {
      ordered->update_vertices(base, own);
    } else {
      poly_->GetPoints()->GetData()->Modified();
      poly_->GetPoints()->Modified();
      poly_->GetPointData()->GetScalars()->Modified();
      if (split_orders()) merged_poly_->Modified();
    }
    blend_if_translucent(frame.transient_colors);
  }
  use_float_target(settings_.order == scene::DrawOrder::kBsp && own > 0);
  // The split orders draw the merged triangles with a second actor: the terrain's list keeps
  // the rest, in the frame's order (buffers reused from frame to frame).
  const std::vector<std::uint32_t>* terrain = &frame.indices;
  const std::vector<std::int8_t>* levels = &frame.level;
  if (split_orders()) {
    split_terrain_.clear();
    split_merged_.clear();
    split_levels_.clear();
    for (std::size_t t = 0; 3 * t < frame.indices.size(); ++t) {
      const int lv = t < frame.level.size() ? frame.level[t] : mrbsp::kCrackLevel;
      const bool translucent = lv == mrbsp::kMergedLevel || lv == mrbsp::kBoxLevel;
      auto& to = translucent ? split_merged_ : split_terrain_;
      to.insert(to.end(), frame.indices.begin() + static_cast<std::ptrdiff_t>(3 * t),
                frame.indices.begin() + static_cast<std::ptrdiff_t>(3 * t + 3));
      if (!translucent) split_levels_.push_back(static_cast<std::int8_t>(lv));
    }
    terrain = &split_terrain_;
    levels = &split_levels_;
    merged_poly_->SetPolys(triangle_cells(split_merged_));
    merged_poly_->Modified();
  }
  const auto triangles = static_cast<vtkIdType>(terrain->size() / 3);
  poly_->SetPolys(triangle_cells(*terrain));
  if (auto* ordered = OrderedPolyDataMapper::SafeDownCast(mapper_)) {
    // Long runs of merged pieces and box faces: drawn without the texture's fetch.
    std::vector<OrderedPolyDataMapper::Run>& runs = untextured_runs_;
    runs.clear();
    if (actor_->GetTexture() != nullptr) {
      const std::size_t n = std::min(levels->size(), static_cast<std::size_t>(triangles));
      for (std::size_t t = 0; t < n;) {
        std::size_t e = t;
        while (e < n && ((*levels)[e] == mrbsp::kMergedLevel || (*levels)[e] == mrbsp::kBoxLevel)) ++e;
        if (e - t >= OrderedPolyDataMapper::kMinUntexturedRun) {
          runs.push_back({static_cast<std::uint32_t>(t), static_cast<std::uint32_t>(e - t)});
        }
        t = e == t ? t + 1 : e;
      }
    }
    ordered->set_untextured_runs(runs);
  }

  vtkNew<vtkSignedCharArray> level;
  level->SetName("level");
  level->SetNumberOfValues(triangles);
  std::fill_n(level->GetPointer(0), triangles, static_cast<signed char>(mrbsp::kCrackLevel));
  std::copy(levels->begin(), levels->begin() + std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(levels->size()), triangles),
            level->GetPointer(0));
  poly_->GetCellData()->AddArray(level);

  if (settings_.lod_colors) {
    vtkNew<vtkUnsignedCharArray> colors;
    colors->SetName("lod_rgba");
    colors->SetNumberOfComponents(4);
    colors->SetNumberOfTuples(triangles);
    auto* rgba = reinterpret_cast<scene::Rgba*>(colors->GetPointer(0));
    for (vtkIdType t = 0; t < triangles; ++t) {
      const int lv = level->GetValue(t);
      const std::uint32_t* v = &(*terrain)[static_cast<std::size_t>(3 * t)];
      if (lv == mrbsp::kCrackLevel) {
        rgba[t] = scene::kCrackColor;
        continue;
      }
      if (lv == mrbsp::kBoxLevel) {  // box faces keep their own colour
        const glm::u8vec4& c = frame.transient_colors[v[0] - frame.transient_base];
        rgba[t] = {c.r, c.g, c.b, c.a};
        continue;
      }
      if (lv < 0) {  // merged polygons keep their own colour
        rgba[t] = point_rgba_[v[0]];
        continue;
      }
      const float s = (shade_[v[0]] + shade_[v[1]] + shade_[v[2]]) / 3.0f;
      rgba[t] = scene::shaded(scene::lod_color(lv), s);
    }
    poly_->GetCellData()->AddArray(colors);
  }
  poly_->Modified();
}

// The fragment colour: with the texture, a terrain vertex's texture coordinates are >= 0 and
// the texture gives the colour; a merged vertex's are (-1, -1) (vertex_shading) and its own
// RGBA does (a triangle is all terrain or all merged, so the interpolated coordinate keeps
// the sign). VTK's own texture code would multiply the two. Then the haze, if any.
void TerrainRenderer::install_shaders(vtkActor& actor, bool textured) {
  vtkShaderProperty* shader = actor.GetShaderProperty();
  shader->ClearAllShaderReplacements();
  // The texture's block between the ordered mapper's markers: its untextured runs replace it.
  std::string colour = textured ? std::string(OrderedPolyDataMapper::kTextureBegin) +
                                      "\n  if (tcoordVCVSOutput.s < 0.0) { gl_FragData[0] = vertexColorVSOutput; }\n"
                                      "  else { gl_FragData[0] = texture(actortexture, tcoordVCVSOutput.st); }\n" +
                                      std::string(OrderedPolyDataMapper::kTextureEnd) + "\n"
                                : "//VTK::TCoord::Impl\n";
  if (settings_.haze_distance > 0.0) {
    // The haze of each vertex from its depth along the view axis (clip-space w), interpolated,
    // and mixed in after the colour. Per fragment (depth linearised from gl_FragCoord.z) it
    // cost about 18 ms more per 1280x720 frame on llvmpipe, where back-to-front drawing shades
    // every layer of the terrain; per vertex the difference is invisible (the fade is smooth
    // and coarse triangles are far).
    shader->AddVertexShaderReplacement("//VTK::PositionVC::Dec", true,
                                       "//VTK::PositionVC::Dec\nout float hazeAmount;\n", false);
    shader->AddVertexShaderReplacement(
        "//VTK::PositionVC::Impl", true,
        "//VTK::PositionVC::Impl\n  hazeAmount = 0.85 * (1.0 - exp(-gl_Position.w / hazeDistance));\n", false);
    shader->AddFragmentShaderReplacement("//VTK::PositionVC::Dec", true,
                                         "//VTK::PositionVC::Dec\nin float hazeAmount;\n", false);
    colour += "  gl_FragData[0].rgb = mix(gl_FragData[0].rgb, hazeColor, hazeAmount);\n";
    const double distance = settings_.lod_colors ? 1e30 : settings_.haze_distance;
    shader->GetVertexCustomUniforms()->SetUniformf("hazeDistance", static_cast<float>(distance));
    const float color[3] = {settings_.haze_color[0] / 255.0f, settings_.haze_color[1] / 255.0f,
                            settings_.haze_color[2] / 255.0f};
    shader->GetFragmentCustomUniforms()->SetUniform3f("hazeColor", color);
  }
  shader->AddFragmentShaderReplacement("//VTK::TCoord::Impl", true, colour, false);
}

void TerrainRenderer::apply_color_mode() {
  const bool textured = texture_side_ > 0 && !settings_.lod_colors;
  actor_->SetTexture(textured ? texture_.GetPointer() : nullptr);
  mapper_->ScalarVisibilityOn();  // the merged polygons' colours, also under the texture
  if (settings_.lod_colors) {
    mapper_->SetScalarModeToUseCellFieldData();
    mapper_->SelectColorArray("lod_rgba");
  } else {
    mapper_->SetScalarModeToUsePointData();
  }
  install_shaders(*actor_, textured);
  if (split_orders()) install_shaders(*merged_actor_, false);
}

void TerrainRenderer::set_background(const scene::Rgb& bottom, const scene::Rgb& top) {
  double c[3];
  set_rgb(bottom, c);
  renderer_->SetBackground(c);
  set_rgb(top, c);
  renderer_->SetBackground2(c);
}

void TerrainRenderer::set_lod_colors(bool on) {
  if (on == settings_.lod_colors) return;
  settings_.lod_colors = on;
  apply_color_mode();
}

void TerrainRenderer::set_wireframe(bool on) {
  settings_.wireframe = on;
  for (vtkActor* a : {actor_.GetPointer(), merged_actor_.GetPointer()}) {
    if (on) {
      a->GetProperty()->SetRepresentationToWireframe();
    } else {
      a->GetProperty()->SetRepresentationToSurface();
    }
  }
}

void TerrainRenderer::replace_vertices(const std::vector<glm::vec3>& positions,
                                       scene::TerrainShading shading, const ColorTexture& texture) {
  const std::size_t n = positions.size();
  if (shading.rgba.size() != n || shading.shade.size() != n ||
      texture.side != texture_side_ || (texture_side_ > 0 && shading.tcoords.size() != n) ||
      texture.rgba.size() != static_cast<std::size_t>(texture.side) * texture.side) {
    throw std::invalid_argument("TerrainRenderer::replace_vertices: " + std::to_string(n) +
                                " positions with attributes or a texture that differ");
  }
  // The triangles index the old vertices: none until the next set_frame().
  poly_->SetPolys(vtkNew<vtkCellArray>());
  poly_->GetCellData()->Initialize();
  if (split_orders()) merged_poly_->SetPolys(vtkNew<vtkCellArray>());
  if (replace_in_place(positions, shading, texture)) return;
  const auto count = static_cast<vtkIdType>(n);
  auto copy = [count](vtkDataArray* to, const void* from, std::size_t bytes) {
    // Keeps the allocation when the count is unchanged; otherwise frees it first, since
    // SetNumberOfTuples alone keeps a larger one (the vertex count changes at every slide).
    if (to->GetSize() != count * to->GetNumberOfComponents()) to->Initialize();
    to->SetNumberOfTuples(count);
    std::memcpy(to->GetVoidPointer(0), from, bytes);
    to->Modified();
  };
  copy(poly_->GetPoints()->GetData(), positions.data(), n * sizeof(glm::vec3));
  poly_->GetPoints()->Modified();
  copy(poly_->GetPointData()->GetScalars(), shading.rgba.data(), n * sizeof(scene::Rgba));
  if (texture_side_ > 0) {
    copy(poly_->GetPointData()->GetTCoords(), shading.tcoords.data(), n * sizeof(glm::vec2));
    copy(texture_image_->GetPointData()->GetScalars(), texture.rgba.data(), texture.rgba.size() * sizeof(scene::Rgba));
    texture_image_->Modified();
  }
  shade_ = std::move(shading.shade);
  point_rgba_ = std::move(shading.rgba);
  // Room after the new vertices: the frames' own (colour-box faces), the pieces later edits
  // and traversals append, and the next slide's vertices when they outnumber these (written
  // in place then, replace_in_place): n / scene::kVertexRoom, as append_merged_vertices()
  // keeps.
  reserve_tail(std::max(tail_, n / scene::kVertexRoom));
  choose_blending(*mapper_, point_rgba_, texture.rgba);
  poly_->Modified();
  if (split_orders()) merged_poly_->Modified();
}

// replace_vertices() without allocating: when the new vertices fit the arrays (the vertices
// held and the room after them), written over the old ones (what lies beyond them joins the
// room); the positions and colours uploaded by the ordered mapper in one range (in place:
// they go unshifted, see unshifted()), the texture coordinates (a function of the lattice
// index, the same after a slide) only when they differ. Measured on terrain-only slides of the
// Utah mosaic (1024 cells, 1.06 M vertices; `terravol bench --suites build`, the viewer's
// frames): the frame that lands a slide took 85-96 ms against 19-25 ms for the frames around it
// when the arrays were freed before the slide and made and uploaded again after it; 51-71 ms
// with the arrays written in place and VTK packing the positions again; and its draw
// 2-3 ms more than the quiet frames' with the positions uploaded in place too, against 11-18
// ms more (2026-12-07, two alternating runs of each).
bool TerrainRenderer::replace_in_place(const std::vector<glm::vec3>& positions,
                                       scene::TerrainShading& shading,
                                       const ColorTexture& texture) {
  auto* ordered = OrderedPolyDataMapper::SafeDownCast(mapper_);
  const std::size_t n = positions.size(), held = point_rgba_.size();
  if (ordered == nullptr || split_orders() || n == 0 || n > held + tail_) return false;
  write_vertices(0, positions, shading.rgba.data());
  if (texture_side_ > 0) {
    vtkDataArray* tcoords = poly_->GetPointData()->GetTCoords();
    if (std::memcmp(tcoords->GetVoidPointer(0), shading.tcoords.data(), n * sizeof(glm::vec2)) != 0) {
      std::memcpy(tcoords->GetVoidPointer(0), shading.tcoords.data(), n * sizeof(glm::vec2));
      tcoords->Modified();
    }
    vtkDataArray* texels = texture_image_->GetPointData()->GetScalars();
    std::memcpy(texels->GetVoidPointer(0), texture.rgba.data(), texture.rgba.size() * sizeof(scene::Rgba));
    texels->Modified();
    texture_image_->Modified();
  }
  shade_ = std::move(shading.shade);
  point_rgba_ = std::move(shading.rgba);
  tail_ = held + tail_ - n;  // what lies beyond n (earlier merged vertices) no triangle indexes
  ordered->update_vertices(0, n);
  choose_blending(*mapper_, point_rgba_, texture.rgba);
  poly_->Modified();
  return true;
}

void TerrainRenderer::append_merged_vertices(std::span<const glm::vec3> positions,
                                             std::span<const glm::u8vec4> colors) {
  if (positions.size() != colors.size()) {
    throw std::invalid_argument("TerrainRenderer::append_merged_vertices: " + std::to_string(positions.size()) +
                                " positions but " + std::to_string(colors.size()) + " colours");
  }
  if (positions.empty()) return;
  const auto old_count = static_cast<vtkIdType>(point_rgba_.size());
  const auto count = old_count + static_cast<vtkIdType>(positions.size());
  std::vector<scene::Rgba> rgba(colors.size());
  for (std::size_t k = 0; k < colors.size(); ++k) rgba[k] = {colors[k].r, colors[k].g, colors[k].b, colors[k].a};
  auto* ordered = OrderedPolyDataMapper::SafeDownCast(mapper_);
  blend_if_translucent(colors);
  shade_.resize(shade_.size() + positions.size(), 1.0f);
  point_rgba_.insert(point_rgba_.end(), rgba.begin(), rgba.end());
  if (ordered != nullptr && !split_orders() && positions.size() <= tail_) {
    // Into the reserved tail, whose placeholders already have a merged vertex's texture
    // coordinates: positions and colours written in place, and only they uploaded
    // (update_vertices). Marking the arrays modified would make VTK upload every vertex again,
    // about 30 ms of the first frame after an edit of the benchmark's volumes over N44W072.
    write_vertices(static_cast<std::size_t>(old_count), positions, rgba.data());
    tail_ -= positions.size();
    ordered->update_vertices(static_cast<std::size_t>(old_count), positions.size());
    return;
  }
  // Grows each array by the tail; Resize keeps the old values, and the capacity at least
  // doubles, so a run of small appends (lazily built pieces, frame after frame) stays linear.
  auto grow = [&](vtkDataArray* a, const void* from, std::size_t bytes_per_tuple) {
    const vtkIdType capacity = a->GetSize() / std::max(a->GetNumberOfComponents(), 1);
    if (capacity < count) a->Resize(std::max(count, 2 * capacity));
    a->SetNumberOfTuples(count);
    std::memcpy(static_cast<char*>(a->GetVoidPointer(0)) + old_count * bytes_per_tuple, from,
                positions.size() * bytes_per_tuple);
    a->Modified();
  };
  grow(poly_->GetPoints()->GetData(), positions.data(), sizeof(glm::vec3));
  poly_->GetPoints()->Modified();
  grow(poly_->GetPointData()->GetScalars(), rgba.data(), sizeof(scene::Rgba));
  if (texture_side_ > 0) {
    const std::vector<glm::vec2> none(positions.size(), glm::vec2(-1.0f));
    grow(poly_->GetPointData()->GetTCoords(), none.data(), sizeof(glm::vec2));
  }
  // The frames' own vertices after the new ones, and room for about three more appends as
  // large as this one (an edit's) or the vertices' count / scene::kVertexRoom (lazily built
  // pieces come in small appends between an edit's large ones), to be written in place
  // (above).
  if (ordered != nullptr && !split_orders()) {
    reserve_tail(std::max({tail_, 3 * positions.size(), point_rgba_.size() / scene::kVertexRoom}));
  } else if (tail_ > 0) {
    reserve_tail(tail_);
  }
  poly_->Modified();
  if (split_orders()) merged_poly_->Modified();
}

void TerrainRenderer::write_vertices(std::size_t first, std::span<const glm::vec3> positions, const void* rgba) {
  std::memcpy(static_cast<float*>(poly_->GetPoints()->GetData()->GetVoidPointer(0)) + 3 * first, positions.data(),
              positions.size() * sizeof(glm::vec3));
  std::memcpy(static_cast<unsigned char*>(poly_->GetPointData()->GetScalars()->GetVoidPointer(0)) + 4 * first, rgba,
              4 * positions.size());
}

void TerrainRenderer::blend_if_translucent(std::span<const glm::u8vec4> colors) {
  auto* ordered = OrderedPolyDataMapper::SafeDownCast(mapper_);
  if (ordered == nullptr || ordered->blending()) return;
  if (std::any_of(colors.begin(), colors.end(), [](const glm::u8vec4& c) { return c.a != 255; })) ordered->set_blending(true);
}

bool TerrainRenderer::replace_merged_vertices(std::span<const glm::vec3> positions, std::size_t merged_base,
                                              std::span<const glm::u8vec4> colors) {
  auto* ordered = OrderedPolyDataMapper::SafeDownCast(mapper_);
  const std::size_t n = positions.size(), held = point_rgba_.size();
  if (ordered == nullptr || split_orders() || merged_base > held || merged_base > n || colors.size() != n - merged_base ||
      n > held + tail_) {
    return false;
  }
  auto* xyz = static_cast<float*>(poly_->GetPoints()->GetData()->GetVoidPointer(0));
  if (std::memcmp(xyz, positions.data(), merged_base * sizeof(glm::vec3)) != 0) return false;
  // The room after the terrain's vertices holds merged vertices or placeholders, whose texture
  // coordinates (-1, -1) are what merged vertices have: positions and colours are all that
  // change.
  poly_->SetPolys(vtkNew<vtkCellArray>());
  poly_->GetCellData()->Initialize();
  point_rgba_.resize(n);
  for (std::size_t k = merged_base; k < n; ++k) {
    const glm::u8vec4& c = colors[k - merged_base];
    point_rgba_[k] = {c.r, c.g, c.b, c.a};
  }
  write_vertices(merged_base, positions.subspan(merged_base), point_rgba_.data() + merged_base);
  shade_.resize(n);
  std::fill(shade_.begin() + static_cast<std::ptrdiff_t>(merged_base), shade_.end(), 1.0f);
  tail_ = held + tail_ - n;
  blend_if_translucent(colors);
  ordered->update_vertices(merged_base, n - merged_base);
  poly_->Modified();
  return true;
}

void TerrainRenderer::release_vertices() {
  vertex_version_ = ~std::uint64_t{0};  // of no tree: the next sync replaces every vertex
  poly_->SetPolys(vtkNew<vtkCellArray>());
  poly_->GetCellData()->Initialize();
  if (split_orders()) merged_poly_->SetPolys(vtkNew<vtkCellArray>());
  vtkPointData* pd = poly_->GetPointData();
  for (vtkDataArray* a : {poly_->GetPoints()->GetData(), pd->GetScalars(), pd->GetTCoords()}) {
    if (a == nullptr) continue;
    a->Initialize();  // frees the storage (vtkDataArray::Squeeze would keep it at the count)
    a->Modified();
  }
  poly_->GetPoints()->Modified();
  std::vector<float>().swap(shade_);
  std::vector<scene::Rgba>().swap(point_rgba_);
  tail_ = 0;
  // The mappers' vertex and index buffers. The next render() builds them again, as it would
  // after replace_vertices() anyway; shader programs stay in the window's cache.
  window_->MakeCurrent();
  mapper_->ReleaseGraphicsResources(window_);
  if (merged_mapper_ != nullptr) merged_mapper_->ReleaseGraphicsResources(window_);
  poly_->Modified();
  if (split_orders()) merged_poly_->Modified();
}

void TerrainRenderer::set_labels(const std::vector<scene::MarkerLabel>& labels) {
  for (const auto& a : labels_) labels_renderer_->RemoveActor(a);
  labels_.clear();
  labels_renderer_->SetDraw(labels.empty() ? 0 : 1);
  for (const scene::MarkerLabel& l : labels) {
    auto a = vtkSmartPointer<vtkBillboardTextActor3D>::New();
    a->SetInput(l.text.c_str());
    a->SetPosition(l.at.x, l.at.y, l.at.z);
    vtkTextProperty* t = a->GetTextProperty();
    t->SetFontSize(18);
    t->BoldOn();
    t->ShadowOn();
    t->SetColor(1.0, 1.0, 1.0);
    t->SetJustificationToCentered();
    t->SetVerticalJustificationToBottom();
    // Drawn in the opaque pass, blended there: as translucent geometry VTK 9.1 would draw the
    // layer with order-independent translucency, whose full-window buffers and passes cost
    // about 15 ms per 1280x720 frame on llvmpipe for three labels. Labels lie over everything
    // and never overlap the scene's translucency, so plain blending gives the same image.
    a->ForceOpaqueOn();
    labels_renderer_->AddActor(a);
    labels_.push_back(a);
  }
}

std::optional<LegendCard> legend_card(const scene::Legend& legend) {
  if (legend.empty()) return std::nullopt;
  LegendCard card;
  card.title = legend.title;
  card.subtitle = legend.subtitle;
  if (!legend.colormap.empty()) card.colormap = volume::colormap_by_name(legend.colormap);
  card.lo = legend.lo;
  card.hi = legend.hi;
  // A categorical slice's swatches come first (it has no bar), then the isosurfaces'.
  card.entries_title = legend.categories.empty() ? "isosurfaces"
                       : legend.levels.empty()   ? legend.categories_title
                                                 : legend.categories_title + ", isosurfaces";
  for (const scene::LegendLevel& l : legend.categories) {
    card.entries.push_back({l.label, {l.color[0], l.color[1], l.color[2]}, l.value});
  }
  for (const scene::LegendLevel& l : legend.levels) {
    card.entries.push_back({l.label, {l.color[0], l.color[1], l.color[2]}, l.value});
  }
  return card;
}

void TerrainRenderer::set_legend(const scene::Legend& legend) {
  legend_cache_ = {};
  legend_card_ = legend_card(legend);
  legend_actor_->SetVisibility(false);
}

void TerrainRenderer::place_legend(int right, int top, int max_height) { legend_place_ = {right, top, max_height}; }

const RgbaImage* TerrainRenderer::legend_image_for(int max_height) {
  if (!legend_card_) return nullptr;
  if (legend_cache_.rgba.empty() || legend_cache_height_ != max_height) {
    legend_cache_ = legend_image(*legend_card_, max_height);
    legend_cache_height_ = max_height;
    legend_uploaded_ = false;
  }
  return &legend_cache_;
}

std::array<int, 2> TerrainRenderer::legend_size(int max_height) {
  const RgbaImage* img = legend_image_for(max_height);
  return img == nullptr ? std::array<int, 2>{0, 0} : std::array<int, 2>{img->width, img->height};
}

void TerrainRenderer::update_legend() {
  const int* size = window_->GetSize();
  const int w = size[0], h = size[1];
  // Unplaced: the upper right, 10 px in, at most the window's height less 20 px.
  const auto [right, top, max_height] =
      legend_place_.value_or(std::array<int, 3>{w - 10, 10, std::max(1, h - 20)});
  const RgbaImage* img = max_height > 0 ? legend_image_for(max_height) : nullptr;
  if (img == nullptr) {
    legend_actor_->SetVisibility(false);
    legend_box_.reset();
    return;
  }
  if (!legend_uploaded_) {
    // vtkImageMapper draws row 0 at the bottom: the card's rows reversed.
    legend_data_->SetDimensions(img->width, img->height, 1);
    legend_data_->AllocateScalars(VTK_UNSIGNED_CHAR, 4);
    auto* dst = static_cast<unsigned char*>(legend_data_->GetScalarPointer());
    const std::size_t row = static_cast<std::size_t>(img->width) * 4;
    for (int y = 0; y < img->height; ++y) {
      std::memcpy(dst + static_cast<std::size_t>(img->height - 1 - y) * row, img->rgba.data() + y * row, row);
    }
    legend_data_->Modified();
    legend_uploaded_ = true;
  }
  legend_actor_->SetPosition(right - img->width, h - top - img->height);
  legend_actor_->SetVisibility(true);
  legend_box_ = std::array<int, 4>{right - img->width, top, img->width, img->height};
}

double TerrainRenderer::render() {
  const auto t0 = scene::Clock::now();
  update_legend();
  window_->Render();
  window_->WaitForCompletion();
  return scene::ms_since(t0);
}

std::vector<std::uint8_t> TerrainRenderer::rgb() const { return window_rgb(window_); }

std::vector<std::uint8_t> window_rgb(vtkRenderWindow* window) {
  int* size = window->GetSize();
  const int w = size[0], h = size[1];
  std::vector<std::uint8_t> out(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  if (out.empty()) return out;
  // The back buffer, bottom row first (OpenGL's order), turned top row first.
  unsigned char* pixels = window->GetPixelData(0, 0, w - 1, h - 1, 0, 0);
  const std::size_t row = static_cast<std::size_t>(w) * 3;
  for (int y = 0; y < h; ++y) {
    std::copy_n(pixels + static_cast<std::size_t>(h - 1 - y) * row, row, out.data() + static_cast<std::size_t>(y) * row);
  }
  delete[] pixels;
  return out;
}

}  // namespace terravol::app::render
