#include "bench/plain_vtk.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkOpenGLRenderer.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTypeInt32Array.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "app/render/terrain_renderer.h"
#include "app/render/vtk_camera.h"
#include "app/scene/timing.h"

namespace terravol::bench {

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be three packed floats");
static_assert(sizeof(glm::dvec3) == 3 * sizeof(double), "glm::dvec3 must be three packed doubles");
static_assert(sizeof(glm::u8vec4) == 4 && sizeof(app::scene::Rgba) == 4,
              "colours must be four packed bytes");

namespace {

constexpr int kUnlimitedPeels = std::numeric_limits<int>::max();
constexpr auto kMaxIndex = static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max());

// Checks an index list against its vertex count; `what` names it in the message.
void check_triangles(std::span<const std::uint32_t> triangles, std::size_t vertices,
                     const char* what) {
  if (triangles.size() % 3 != 0) {
    throw std::invalid_argument(std::string("PlainVtkScene: ") + what + " index count " +
                                std::to_string(triangles.size()) + " is not a multiple of 3");
  }
  if (vertices > kMaxIndex + 1) {
    throw std::invalid_argument(std::string("PlainVtkScene: ") + what + " has " +
                                std::to_string(vertices) +
                                " vertices, more than 32-bit connectivity can index");
  }
  const auto worst = std::max_element(triangles.begin(), triangles.end());
  if (worst != triangles.end() && *worst >= vertices) {
    throw std::invalid_argument(std::string("PlainVtkScene: ") + what + " index " +
                                std::to_string(*worst) + " is out of range (" +
                                std::to_string(vertices) + " vertices)");
  }
}

vtkNew<vtkUnsignedCharArray> rgba_array(const void* data, std::size_t count) {
  vtkNew<vtkUnsignedCharArray> rgba;
  rgba->SetName("rgba");
  rgba->SetNumberOfComponents(4);
  rgba->SetNumberOfTuples(static_cast<vtkIdType>(count));
  if (count > 0) std::memcpy(rgba->GetPointer(0), data, 4 * count);
  return rgba;
}

// Colours as they are (no lookup table, no lighting): ambient 1, diffuse 0, specular 0 and
// lighting off, so the fragment colour is the interpolated vertex colour, as in
// app::render::TerrainRenderer.
void setup_unlit(vtkPolyDataMapper& mapper, vtkActor& actor) {
  mapper.SetColorModeToDirectScalars();
  mapper.SetScalarModeToUsePointData();
  mapper.ScalarVisibilityOn();
  mapper.InterpolateScalarsBeforeMappingOff();
  mapper.StaticOn();  // the input never changes after construction: no pipeline checks per frame
  actor.SetMapper(&mapper);
  vtkProperty* property = actor.GetProperty();
  property->LightingOff();
  property->SetAmbient(1.0);
  property->SetDiffuse(0.0);
  property->SetSpecular(0.0);
  property->SetColor(1.0, 1.0, 1.0);
  property->BackfaceCullingOff();
}

}  // namespace

std::vector<std::uint32_t> lattice_triangles(int cells) {
  if (cells < 1)
    throw std::invalid_argument("lattice_triangles: cells = " + std::to_string(cells) +
                                ", want >= 1");
  const auto side = static_cast<std::uint64_t>(cells) + 1;
  if (side * side - 1 > kMaxIndex) {
    throw std::invalid_argument("lattice_triangles: " + std::to_string(cells) +
                                " cells need indices beyond 32-bit connectivity");
  }
  const auto n1 = static_cast<std::uint32_t>(side);
  std::vector<std::uint32_t> out;
  out.reserve(6 * static_cast<std::size_t>(cells) * static_cast<std::size_t>(cells));
  for (std::uint32_t j = 0; j + 1 < n1; ++j) {
    for (std::uint32_t i = 0; i + 1 < n1; ++i) {
      const std::uint32_t sw = j * n1 + i, se = sw + 1, nw = sw + n1, ne = nw + 1;
      out.insert(out.end(), {sw, se, ne, sw, ne, nw});
    }
  }
  return out;
}

PlainVtkScene::PlainVtkScene(std::span<const glm::vec3> terrain_positions,
                             std::span<const app::scene::Rgba> terrain_rgba,
                             std::span<const std::uint32_t> terrain_triangles,
                             std::span<const glm::dvec3> overlay_positions,
                             std::span<const glm::u8vec4> overlay_rgba,
                             std::span<const std::uint32_t> overlay_triangles,
                             const PlainVtkOptions& options)
    : options_(options),
      terrain_triangles_(terrain_triangles.size() / 3),
      overlay_triangles_(overlay_triangles.size() / 3) {
  if (options.width <= 0 || options.height <= 0) {
    throw std::invalid_argument("PlainVtkScene: image size " + std::to_string(options.width) + "x" +
                                std::to_string(options.height) + " is empty");
  }
  if (terrain_rgba.size() != terrain_positions.size() ||
      overlay_rgba.size() != overlay_positions.size()) {
    throw std::invalid_argument("PlainVtkScene: " + std::to_string(terrain_positions.size()) +
                                " terrain positions, " + std::to_string(terrain_rgba.size()) +
                                " colours; " + std::to_string(overlay_positions.size()) +
                                " overlay positions, " + std::to_string(overlay_rgba.size()) +
                                " colours");
  }
  check_triangles(terrain_triangles, terrain_positions.size(), "terrain");
  check_triangles(overlay_triangles, overlay_positions.size(), "overlay");

  // The terrain: float positions, as app::render::TerrainRenderer uploads them.
  vtkNew<vtkFloatArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(static_cast<vtkIdType>(terrain_positions.size()));
  if (!terrain_positions.empty()) {
    std::memcpy(xyz->GetPointer(0), terrain_positions.data(),
                terrain_positions.size() * sizeof(glm::vec3));
  }
  vtkNew<vtkPoints> terrain_points;
  terrain_points->SetData(xyz);
  terrain_->SetPoints(terrain_points);
  terrain_->GetPointData()->SetScalars(rgba_array(terrain_rgba.data(), terrain_rgba.size()));
  terrain_->SetPolys(app::render::triangle_cells(terrain_triangles));
  terrain_mapper_->SetInputData(terrain_);
  setup_unlit(*terrain_mapper_, *terrain_actor_);
  terrain_actor_->ForceOpaqueOn();  // the opaque pass, depth-tested, whatever the alpha says
  if (!terrain_triangles.empty()) renderer_->AddActor(terrain_actor_);

  // The overlay: double positions (VTK converts them when it builds the vertex buffer).
  if (!overlay_triangles.empty()) {
    vtkNew<vtkDoubleArray> dxyz;
    dxyz->SetNumberOfComponents(3);
    dxyz->SetNumberOfTuples(static_cast<vtkIdType>(overlay_positions.size()));
    std::memcpy(dxyz->GetPointer(0), overlay_positions.data(),
                overlay_positions.size() * sizeof(glm::dvec3));
    vtkNew<vtkPoints> overlay_points;
    overlay_points->SetData(dxyz);
    overlay_->SetPoints(overlay_points);
    overlay_->GetPointData()->SetScalars(rgba_array(overlay_rgba.data(), overlay_rgba.size()));
    overlay_->SetPolys(app::render::triangle_cells(overlay_triangles));
    overlay_mapper_->SetInputData(overlay_);
    setup_unlit(*overlay_mapper_, *overlay_actor_);
    overlay_actor_->ForceTranslucentOn();
    renderer_->AddActor(overlay_actor_);
  }

  const bool peel = options.translucency != Translucency::kVtkDefault;
  renderer_->SetUseDepthPeeling(peel ? 1 : 0);
  // Exact: no practical limit, so peeling ends when a peel writes no pixel (occlusion ratio 0).
  // Not MaximumNumberOfPeels 0, which vtkRenderer documents as "no limit": VTK 9.1's
  // vtkDualDepthPeelingPass (used wherever supported) stops when CurrentPeel >= the maximum,
  // so 0 means no peel at all and every translucent fragment is alpha-blended in draw order.
  renderer_->SetMaximumNumberOfPeels(
      options.translucency == Translucency::kPeelExact ? kUnlimitedPeels : 4);
  renderer_->SetOcclusionRatio(0.0);
  renderer_->UseFXAAOff();
  renderer_->AutomaticLightCreationOff();
  renderer_->GradientBackgroundOff();
  const app::scene::Rgb& bg = options.background;
  renderer_->SetBackground(bg[0] / 255.0, bg[1] / 255.0, bg[2] / 255.0);

  app::render::require_x_display();
  window_->SetOffScreenRendering(1);
  window_->SetMultiSamples(0);
  window_->SetAlphaBitPlanes(peel ? 1 : 0);  // depth peeling needs destination alpha
  window_->SetSize(options.width, options.height);
  window_->AddRenderer(renderer_);
}

PlainVtkScene::~PlainVtkScene() {
  window_->Finalize();
}

void PlainVtkScene::set_camera(const mrbsp::Camera& camera, double far_plane) {
  app::render::apply_camera(camera, far_plane, *renderer_->GetActiveCamera());
}

double PlainVtkScene::render() {
  const auto t0 = app::scene::Clock::now();
  window_->Render();
  window_->WaitForCompletion();
  rendered_ = true;
  return app::scene::ms_since(t0);
}

bool PlainVtkScene::dual_depth_peeling() {
  auto* gl = vtkOpenGLRenderer::SafeDownCast(renderer_);
  return gl != nullptr && gl->IsDualDepthPeelingSupported();
}

std::vector<std::uint8_t> PlainVtkScene::rgb() const {
  if (!rendered_) return {};
  return app::render::window_rgb(window_.GetPointer());
}

}  // namespace terravol::bench
