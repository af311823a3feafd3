#include "bench/item_buffer.h"

#include <vtkCellData.h>
#include <vtkPolyData.h>
#include <vtkUnsignedCharArray.h>

#include <stdexcept>
#include <string>

namespace terravol::bench {

namespace {

app::render::RenderSettings item_settings(const app::render::SceneRenderer& scene) {
  app::render::RenderSettings s;
  s.width = scene.camera().width;
  s.height = scene.camera().height;
  s.order = app::scene::DrawOrder::kBsp;
  s.lod_colors = true;  // per-triangle colours (the "lod_rgba" cell array), no texture, no haze
  s.gradient = false;
  s.background = {0, 0, 0};  // id 0: no triangle
  s.haze_distance = 0.0;
  return s;
}

}  // namespace

ItemBuffer::ItemBuffer(const app::render::SceneRenderer& scene) : renderer_(scene.make_renderer(item_settings(scene))) {}

ItemBuffer::~ItemBuffer() = default;

std::vector<std::uint32_t> ItemBuffer::pixels_per_triangle(const app::render::SceneRenderer& scene,
                                                           const mrbsp::Frame& frame) {
  const std::size_t triangles = frame.indices.size() / 3;
  if (triangles + 1 >= (std::size_t{1} << 24)) {
    throw std::invalid_argument("ItemBuffer: " + std::to_string(triangles) + " triangles do not fit 24-bit ids");
  }
  scene.sync_vertices(*renderer_);
  renderer_->set_camera(scene.camera(), scene.terrain().far_plane(scene.camera().eye));
  renderer_->set_frame(frame);
  // Replace set_frame's LOD colours by the ids: triangle t in colour t + 1 (24 bits, alpha 1).
  auto* colors = vtkUnsignedCharArray::SafeDownCast(renderer_->scene()->GetCellData()->GetArray("lod_rgba"));
  if (!colors || static_cast<std::size_t>(colors->GetNumberOfTuples()) != triangles) {
    throw std::logic_error("ItemBuffer: the renderer's per-triangle colours are missing");
  }
  std::uint8_t* rgba = colors->GetPointer(0);
  for (std::size_t t = 0; t < triangles; ++t) {
    const std::size_t id = t + 1;
    rgba[4 * t] = static_cast<std::uint8_t>(id & 255u);
    rgba[4 * t + 1] = static_cast<std::uint8_t>((id >> 8) & 255u);
    rgba[4 * t + 2] = static_cast<std::uint8_t>((id >> 16) & 255u);
    rgba[4 * t + 3] = 255;
  }
  colors->Modified();
  renderer_->scene()->Modified();
  renderer_->render();
  const std::vector<std::uint8_t> image = renderer_->rgb();
  std::vector<std::uint32_t> pixels(triangles, 0);
  for (std::size_t p = 0; p + 2 < image.size(); p += 3) {
    const std::size_t id = image[p] | static_cast<std::size_t>(image[p + 1]) << 8 | static_cast<std::size_t>(image[p + 2]) << 16;
    if (id == 0) continue;
    if (id > triangles) throw std::logic_error("ItemBuffer: pixel of id " + std::to_string(id) + " beyond the frame's triangles");
    ++pixels[id - 1];
  }
  return pixels;
}

}  // namespace terravol::bench
