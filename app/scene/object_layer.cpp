#include "app/scene/object_layer.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>

#include "app/scene/timing.h"
#include "objects/model.h"
#include "objects/placement.h"

namespace terravol::app::scene {

namespace {

std::string format_scale(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", s);
  return b;
}

}  // namespace

std::uint32_t object_surface_id(std::size_t instance) {
  return static_cast<std::uint32_t>((instance >> 14) << 16 | 3u << 14 | (instance & 0x3fff));
}

// A model as read, its levels and its colour cube.
struct ObjectLayer::Model {
  objects::Model model;
  std::vector<objects::Lod> lods;
  volume::Mesh cube;
};

struct ObjectLayer::Instance {
  ObjectSpec spec;
  std::size_t model = 0;
  objects::Pose pose;  // height above the datum
  glm::dvec3 anchor{0.0};
  std::array<glm::dvec3, 8> corners{};  // the model's box in body axes, placed (scene frame)
  glm::dvec3 lo{0.0}, hi{0.0};          // the scene-frame box of those corners
  std::vector<volume::Mesh> placed;     // per level, then the cube; empty until first needed
  int merged = -1;
};

ObjectLayer::ObjectLayer() = default;
ObjectLayer::~ObjectLayer() = default;
ObjectLayer::ObjectLayer(ObjectLayer&&) noexcept = default;
ObjectLayer& ObjectLayer::operator=(ObjectLayer&&) noexcept = default;

ObjectLayer::ObjectLayer(const std::vector<ObjectSpec>& specs, const GroundFunction& ground,
                         const io::SceneFrame& frame, const objects::LodOptions& lod, const objects::Sunlight& sun)
    : frame_(std::make_unique<io::SceneFrame>(frame)), sun_(sun) {
  std::map<std::filesystem::path, std::size_t> by_file;
  for (const ObjectSpec& spec : specs) {
    auto [it, fresh] = by_file.try_emplace(spec.file, models_.size());
    if (fresh) {
      auto m = std::make_unique<Model>();
      const auto t0 = Clock::now();
      m->model = objects::read_model(spec.file);
      // Not an error: the meshes keep their material's colour, as most viewers draw them.
      for (const std::string& name : m->model.missing_textures) {
        std::fprintf(stderr, "terravol: %s: texture '%s' not read; its meshes keep their material's colour\n",
                     spec.file.string().c_str(), name.c_str());
      }
      const auto t1 = Clock::now();
      m->lods = objects::make_lods(m->model.mesh, lod);
      m->cube = objects::color_cube(m->model.mesh);
      for (const objects::Lod& l : m->lods) figures_.lod_triangles += l.mesh.triangle_count();
      figures_.lod_triangles += m->cube.triangle_count();
      figures_.read_ms += ms_between(t0, t1);
      figures_.lod_ms += ms_since(t1);
      models_.push_back(std::move(m));
    }
    const Model& m = *models_[it->second];
    auto in = std::make_unique<Instance>();
    in->spec = spec;
    in->model = it->second;
    in->pose = spec.pose;
    if (spec.agl) in->pose.height += ground(spec.pose.lat, spec.pose.lon);
    in->anchor = objects::anchor_of(m.model.mesh, in->pose.up);
    // The box's corners: the body-axes box taken back to the model's frame (body_of is its own
    // inverse) and placed like the model.
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const glm::dvec3& v : m.model.mesh.vertices) {
      lo = glm::min(lo, objects::body_of(v, in->pose.up));
      hi = glm::max(hi, objects::body_of(v, in->pose.up));
    }
    const double across = glm::length(hi - lo) * in->pose.scale;
    if (across > kMaxObjectMetres) {
      throw std::invalid_argument(spec.file.string() + ": " + std::to_string(static_cast<long long>(across / 1000.0)) +
                                  " km across at scale " + format_scale(in->pose.scale) + ", larger than " +
                                  std::to_string(static_cast<int>(kMaxObjectMetres / 1000.0)) + " km");
    }
    volume::Mesh box;
    for (int c = 0; c < 8; ++c) {
      box.vertices.push_back(objects::body_of(glm::dvec3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z), in->pose.up));
    }
    box.colors.assign(8, glm::u8vec4(0));
    try {
      box = objects::place(box, in->anchor, in->pose, frame, spec.opacity);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(spec.file.string() + ": " + e.what());
    }
    in->lo = glm::dvec3(INFINITY);
    in->hi = glm::dvec3(-INFINITY);
    for (int c = 0; c < 8; ++c) {
      in->corners[static_cast<std::size_t>(c)] = box.vertices[static_cast<std::size_t>(c)];
      in->lo = glm::min(in->lo, box.vertices[static_cast<std::size_t>(c)]);
      in->hi = glm::max(in->hi, box.vertices[static_cast<std::size_t>(c)]);
    }
    in->placed.resize(m.lods.size() + 1);
    figures_.full_triangles += m.model.mesh.triangle_count();
    instances_.push_back(std::move(in));
  }
  figures_.models = models_.size();
  figures_.instances = instances_.size();
}

int ObjectLayer::level_of(std::size_t instance) const {
  if (instance >= instances_.size()) throw std::invalid_argument("there is no object " + std::to_string(instance + 1));
  return instances_[instance]->merged;
}

std::size_t ObjectLayer::model_of(std::size_t instance) const {
  level_of(instance);
  return instances_[instance]->model;
}

const std::vector<objects::Lod>& ObjectLayer::levels(std::size_t model) const {
  if (model >= models_.size()) throw std::invalid_argument("there is no model " + std::to_string(model + 1));
  return models_[model]->lods;
}

const volume::Mesh& ObjectLayer::placed(std::size_t instance, int level) {
  level_of(instance);
  Instance& in = *instances_[instance];
  const Model& m = *models_[in.model];
  const auto k = static_cast<std::size_t>(std::clamp(level, 0, static_cast<int>(m.lods.size())));
  if (in.placed[k].empty()) {
    const volume::Mesh& local = k < m.lods.size() ? m.lods[k].mesh : m.cube;
    in.placed[k] = objects::place(local, in.anchor, in.pose, *frame_, in.spec.opacity);
    if (k < m.lods.size()) in.placed[k] = objects::sunlit(in.placed[k], sun_);
  }
  return in.placed[k];
}

int ObjectLayer::choose(const Instance& in, const mrbsp::Camera& camera, const mrbsp::TraversalOptions& options) const {
  const Model& m = *models_[in.model];
  const int last = static_cast<int>(m.lods.size()) - 1;
  if (fixed_level_ >= 0) return std::min(fixed_level_, last);
  if (options.full_res) return 0;
  const glm::dvec3 eye = camera.eye;
  const glm::dvec3 gap = glm::max(glm::max(in.lo - eye, eye - in.hi), glm::dvec3(0.0));
  const double distance = glm::length(gap);
  if (distance <= camera.near_plane) return 0;
  const double focal = camera.height / (2.0 * std::tan(camera.fov_y_deg * (3.14159265358979323846 / 360.0)));
  // The box on the screen: the bounding rectangle of its projected corners (pixels), unbounded
  // when a corner lies behind the near plane.
  const glm::dvec3 right = glm::normalize(glm::cross(camera.forward, camera.up));
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  bool behind = false;
  for (const glm::dvec3& c : in.corners) {
    const glm::dvec3 d = c - eye;
    const double z = glm::dot(d, camera.forward);
    if (z < camera.near_plane) {
      behind = true;
      break;
    }
    const double x = focal * glm::dot(d, right) / z, y = focal * glm::dot(d, camera.up) / z;
    x0 = std::min(x0, x);
    x1 = std::max(x1, x);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  }
  if (!behind && std::hypot(x1 - x0, y1 - y0) < kColorCubePixels) return last + 1;
  int level = 0;
  for (int k = last; k > 0; --k) {
    bool fine = false;
    if (options.metric == mrbsp::LodMetric::kError) {
      fine = m.lods[static_cast<std::size_t>(k)].error * in.pose.scale * focal / distance <= options.threshold_px;
    } else {
      const double area = behind ? INFINITY : (x1 - x0) * (y1 - y0);
      fine = area * 2.0 / static_cast<double>(m.lods[static_cast<std::size_t>(k)].mesh.triangle_count()) <=
             options.threshold_px;
    }
    if (fine) {
      level = k;
      break;
    }
  }
  return level;
}

bool ObjectLayer::update(TerrainScene& scene, const mrbsp::Camera& camera, const mrbsp::TraversalOptions& options) {
  const bool fresh = merged_tree_ != &scene.tree();
  std::vector<std::uint32_t> ids;
  std::vector<mrbsp::SurfaceInput> inputs;
  figures_.chosen_triangles = 0;
  figures_.cubes = 0;
  const auto t0 = Clock::now();
  for (std::size_t i = 0; i < instances_.size(); ++i) {
    Instance& in = *instances_[i];
    if (!visible_) {
      const bool in_tree = !fresh && in.merged >= 0;
      in.merged = kHidden;
      if (in_tree) {
        ids.push_back(object_surface_id(i));
        inputs.push_back({});  // an empty surface: taken out
      }
      continue;
    }
    const int k = choose(in, camera, options);
    const volume::Mesh& mesh = placed(i, k);
    figures_.chosen_triangles += mesh.triangle_count();
    figures_.cubes += k == static_cast<int>(models_[in.model]->lods.size()) ? 1 : 0;
    if (!fresh && k == in.merged) continue;
    in.merged = k;
    ids.push_back(object_surface_id(i));
    inputs.push_back({mesh.vertices, mesh.colors, mesh.triangles});
  }
  const auto t1 = Clock::now();
  figures_.place_ms = ms_between(t0, t1);
  if (!ids.empty()) scene.set_surfaces(ids, inputs);
  figures_.merge_ms = ms_since(t1);
  figures_.remerged = ids.size();
  merged_tree_ = &scene.tree();
  return !ids.empty();
}

volume::Mesh ObjectLayer::visible_mesh() const {
  volume::Mesh all;
  for (const auto& in : instances_) {
    if (in->merged >= 0) volume::append(all, in->placed[static_cast<std::size_t>(in->merged)]);
  }
  return all;
}

}  // namespace terravol::app::scene
