#include "app/scene/volume_layer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "app/scene/ground_grid.h"
#include "app/scene/timing.h"
#include "volume/colormap.h"
#include "volume/geometry.h"
#include "volume/plan.h"
#include "volume/point_query.h"
#include "volume/readers.h"
#include "volume/reduction.h"

namespace terravol::app::scene {

namespace {

std::array<float, 2> finite_range(const volume::Volume& v) {
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (float x : v.values) {
    if (std::isfinite(x)) {
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
  }
  if (!(lo <= hi)) return {0.0f, 1.0f};
  return {lo, hi};
}

// The transmitters a volume records: a plan's "transmitters" attribute, else a single one's
// tx_lat, tx_lon and tx_height_agl_m (terravol rf); none when it has neither or they do not parse.
std::vector<volume::RecordedTransmitter> transmitters_of(const volume::Volume& v) {
  try {
    std::vector<volume::RecordedTransmitter> tx = volume::recorded_transmitters(v);
    if (!tx.empty()) return tx;
    const auto lat = v.attributes.find("tx_lat"), lon = v.attributes.find("tx_lon"), h = v.attributes.find("tx_height_agl_m");
    if (lat == v.attributes.end() || lon == v.attributes.end() || h == v.attributes.end()) return {};
    return {{"", std::stod(lat->second), std::stod(lon->second), std::stod(h->second)}};
  } catch (const std::exception&) {
    return {};
  }
}

// A mast per transmitter (scene frame): a square prism of half-width 20 m from 2 m below the
// ground to the antenna, and on it an octahedron of radius 100 m whose lowest vertex is the
// antenna, opaque red, so that it shows as some ten pixels from 10 km. Built by hand: eight vertices and twelve triangles each
// need no library.
// The markers' labels (MarkerLabel): the octahedron's top is 200 m above the antenna.
std::vector<MarkerLabel> marker_labels_of(const std::vector<volume::RecordedTransmitter>& tx, const io::SceneFrame& frame,
                                          const GroundGrid& ground) {
  std::vector<MarkerLabel> out;
  for (const auto& t : tx) {
    const io::ScenePoint p = frame.to_scene({t.lat, t.lon, ground(t.lat, t.lon) + std::max(t.height_agl, 1.0) + 220.0});
    out.push_back({glm::dvec3(p.x, p.y, p.z), t.name.empty() ? "tx" : t.name});
  }
  return out;
}

volume::Mesh marker_mesh(const std::vector<volume::RecordedTransmitter>& tx, const io::SceneFrame& frame,
                         const GroundGrid& ground) {
  volume::Mesh m;
  const glm::u8vec4 red(220, 30, 40, 255);
  const auto add = [&](const glm::dvec3& p) {
    m.vertices.push_back(p);
    m.colors.push_back(red);
    return static_cast<std::uint32_t>(m.vertices.size() - 1);
  };
  for (const auto& t : tx) {
    const double g = ground(t.lat, t.lon), top = g + std::max(t.height_agl, 1.0);
    const io::ScenePoint base = frame.to_scene({t.lat, t.lon, g - 2.0}), head = frame.to_scene({t.lat, t.lon, top});
    const glm::dvec3 b(base.x, base.y, base.z), h(head.x, head.y, head.z);
    constexpr double w = 20.0, r = 100.0;
    std::uint32_t lo[4], hi[4];
    for (int c = 0; c < 4; ++c) {
      const glm::dvec3 d((c == 0 || c == 3) ? -w : w, c < 2 ? -w : w, 0.0);
      lo[c] = add(b + d);
      hi[c] = add(glm::dvec3(b.x, b.y, h.z) + d);
    }
    for (int c = 0; c < 4; ++c) {
      const int n = (c + 1) % 4;
      for (const std::uint32_t i : {lo[c], lo[n], hi[n], lo[c], hi[n], hi[c]}) m.triangles.push_back(i);
    }
    const glm::dvec3 centre = h + glm::dvec3(0, 0, r);
    const std::uint32_t up = add(centre + glm::dvec3(0, 0, r)), down = add(h);
    std::uint32_t ring[4];
    for (int c = 0; c < 4; ++c) ring[c] = add(centre + glm::dvec3(c == 0 ? r : c == 2 ? -r : 0.0, c == 1 ? r : c == 3 ? -r : 0.0, 0.0));
    for (int c = 0; c < 4; ++c) {
      const int n = (c + 1) % 4;
      for (const std::uint32_t i : {ring[c], ring[n], up, ring[n], ring[c], down}) m.triangles.push_back(i);
    }
  }
  return m;
}

}  // namespace

// A volume as read, the ground under it, its mapper into the scene frame, and the geometry
// of each style.
struct VolumeLayer::Loaded {
  VolumeSpec spec;
  volume::Volume data;
  GroundGrid ground;
  std::unique_ptr<volume::LatticeMapper> mapper;
  std::vector<volume::Mesh> isosurfaces, slices;
  volume::Mesh markers;  // its transmitters' masts (shown with markers_shown_)
  std::unique_ptr<density::ColorCubeOctree> density;  // with a density style
  std::vector<MarkerLabel> labels;  // and their names
  // Changed since the last merge_into(), each surface (isosurfaces, slices, then the markers);
  // a change of the volume's visibility changes all of them.
  std::vector<bool> changed;
  std::array<float, 2> range{0, 1};

  volume::GroundFunction ground_function() const {
    return [this](double lat, double lon) { return ground(lat, lon); };
  }
  std::size_t max_triangles = 0;

  volume::Mesh iso_mesh(const volume::IsoSpec& s) const {
    return volume::reduced_isosurface(data, *mapper, s.value, s.rgba(), max_triangles);
  }
  volume::Mesh slice_mesh(const volume::SliceSpec& s) const {
    try {
      return volume::slice(data, *mapper, s, ground_function());
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(spec.file.string() + ": " + e.what());
    }
  }
};

VolumeLayer::VolumeLayer() = default;
VolumeLayer::~VolumeLayer() = default;
VolumeLayer::VolumeLayer(VolumeLayer&&) noexcept = default;
VolumeLayer& VolumeLayer::operator=(VolumeLayer&&) noexcept = default;

VolumeLayer::VolumeLayer(const std::vector<VolumeSpec>& specs, const io::Mosaic& mosaic, const io::SceneFrame& frame,
                         std::size_t max_triangles, bool markers)
    : max_triangles_(max_triangles), markers_shown_(markers) {
  const auto t0 = Clock::now();
  for (const VolumeSpec& spec : specs) {
    auto v = std::make_unique<Loaded>();
    v->spec = spec;
    v->max_triangles = max_triangles_;
    volume::ReadOptions read;
    read.field = spec.field;
    if (!spec.frame.empty()) read.frame = volume::parse_frame(spec.frame);
    v->data = volume::read_volume(spec.file, read);
    if (v->data.frame.kind == volume::FrameKind::kNone) {
      throw std::invalid_argument(spec.file.string() +
                                  ": the volume does not say where it lies; give its frame (geographic, "
                                  "geographic-agl or enu:LAT,LON,H)");
    }
    // Its footprint, for the ground under it: the lattice's corners, geodetic (heights do not
    // move them).
    const volume::LatticeMapper flat(v->data, frame, [](double, double) { return 0.0; });
    const volume::Lattice& l = v->data.lattice;
    double south = 90, north = -90, west = 1e9, east = -1e9;
    for (int c = 0; c < 4; ++c) {
      const io::Geodetic p = flat.geodetic((c & 1) ? l.dims[0] - 1 : 0, (c & 2) ? l.dims[1] - 1 : 0, 0);
      south = std::min(south, p.lat);
      north = std::max(north, p.lat);
      west = std::min(west, p.lon);
      east = std::max(east, p.lon);
    }
    v->ground = GroundGrid(mosaic, south, north, west, east);
    v->mapper = std::make_unique<volume::LatticeMapper>(v->data, frame, v->ground_function());
    v->range = finite_range(v->data);
    for (const auto& s : spec.isosurfaces) v->isosurfaces.push_back(v->iso_mesh(s));
    for (const auto& s : spec.slices) v->slices.push_back(v->slice_mesh(s));
    if (spec.density) {
      try {
        v->density = std::make_unique<density::ColorCubeOctree>(v->data, frame, v->ground_function(), *spec.density);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(spec.file.string() + ": " + e.what());
      }
    }
    v->markers = marker_mesh(transmitters_of(v->data), frame, v->ground);
    v->labels = marker_labels_of(transmitters_of(v->data), frame, v->ground);
    v->changed.assign(v->isosurfaces.size() + v->slices.size() + 1, true);
    volumes_.push_back(std::move(v));
  }
  figures_.geometry_ms = ms_since(t0);
}

const VolumeSpec& VolumeLayer::spec(std::size_t volume) const {
  if (volume >= volumes_.size()) throw std::invalid_argument("there is no volume " + std::to_string(volume + 1));
  return volumes_[volume]->spec;
}

volume::Mesh VolumeLayer::visible_mesh() const {
  volume::Mesh all;
  for (const auto& v : volumes_) {
    if (!v->spec.visible) continue;
    for (const auto& m : v->isosurfaces) volume::append(all, m);
    for (const auto& m : v->slices) volume::append(all, m);
  }
  return all;
}

void VolumeLayer::merge_into(TerrainScene& scene) {
  const bool fresh = merged_tree_ != &scene.tree();
  std::vector<std::uint32_t> ids;
  std::vector<mrbsp::SurfaceInput> inputs;
  figures_.input_triangles = 0;
  for (std::size_t v = 0; v < volumes_.size(); ++v) {
    Loaded& l = *volumes_[v];
    const std::size_t isos = l.isosurfaces.size(), surfaces = isos + l.slices.size();
    for (std::size_t k = 0; k < l.changed.size(); ++k) {
      const volume::Mesh& m = k < isos ? l.isosurfaces[k] : k < surfaces ? l.slices[k - isos] : l.markers;
      const bool shown = l.spec.visible && (k < surfaces || markers_shown_);
      if (l.spec.visible && k < surfaces) figures_.input_triangles += m.triangle_count();
      if (!fresh && !l.changed[k]) continue;
      l.changed[k] = false;
      if (fresh && (!shown || m.empty())) continue;
      const std::uint32_t kind = k < isos ? 0 : k < surfaces ? 1 : 2;
      const std::size_t index = k < isos ? k : k < surfaces ? k - isos : 0;
      ids.push_back(static_cast<std::uint32_t>(v << 16 | kind << 14 | index));
      inputs.push_back(shown ? mrbsp::SurfaceInput{m.vertices, m.colors, m.triangles} : mrbsp::SurfaceInput{});
    }
  }
  const auto t0 = Clock::now();
  if (fresh || !ids.empty()) figures_.tree_triangles = scene.set_surfaces(ids, inputs).stored_polygons;
  figures_.merge_ms = ms_since(t0);
  figures_.merged_surfaces = ids.size();
  merged_tree_ = &scene.tree();
}

void VolumeLayer::set_visible(std::size_t volume, bool visible) {
  spec(volume);
  Loaded& v = *volumes_[volume];
  if (v.spec.visible != visible) v.changed.assign(v.changed.size(), true);
  v.spec.visible = visible;
}

std::vector<MarkerLabel> VolumeLayer::marker_labels() const {
  std::vector<MarkerLabel> out;
  if (!markers_shown_) return out;
  for (const auto& v : volumes_)
    if (v->spec.visible) out.insert(out.end(), v->labels.begin(), v->labels.end());
  return out;
}

void VolumeLayer::set_markers(bool shown) {
  if (shown == markers_shown_) return;
  markers_shown_ = shown;
  for (const auto& v : volumes_) {
    if (!v->markers.empty()) v->changed.back() = true;  // the last surface: the markers
  }
}

void VolumeLayer::set_slice(std::size_t volume, std::size_t slice, const volume::SliceSpec& s) {
  spec(volume);
  Loaded& v = *volumes_[volume];
  if (slice >= v.slices.size()) {
    throw std::invalid_argument("volume " + std::to_string(volume + 1) + " has no slice " + std::to_string(slice + 1));
  }
  const auto t0 = Clock::now();
  v.slices[slice] = v.slice_mesh(s);
  v.spec.slices[slice] = s;
  v.changed[v.isosurfaces.size() + slice] = true;
  figures_.geometry_ms = ms_since(t0);
}

void VolumeLayer::set_isosurface(std::size_t volume, std::size_t iso, const volume::IsoSpec& s) {
  spec(volume);
  Loaded& v = *volumes_[volume];
  if (iso >= v.isosurfaces.size()) {
    throw std::invalid_argument("volume " + std::to_string(volume + 1) + " has no isosurface " + std::to_string(iso + 1));
  }
  const auto t0 = Clock::now();
  v.isosurfaces[iso] = v.iso_mesh(s);
  v.spec.isosurfaces[iso] = s;
  v.changed[iso] = true;
  figures_.geometry_ms = ms_since(t0);
}

namespace {

std::string slice_text(const volume::SliceSpec& s) {
  char b[96];
  switch (s.kind) {
    case volume::SliceKind::kAgl:
      std::snprintf(b, sizeof b, "slice %g m above ground", s.value);
      break;
    case volume::SliceKind::kAlt:
      std::snprintf(b, sizeof b, "slice at %g m altitude", s.value);
      break;
    case volume::SliceKind::kLat:
      std::snprintf(b, sizeof b, "slice at latitude %g", s.value);
      break;
    case volume::SliceKind::kLon:
      std::snprintf(b, sizeof b, "slice at longitude %g", s.value);
      break;
  }
  return b;
}

}  // namespace

bool VolumeLayer::density_boxes(const mrbsp::Camera& camera, const density::RefineOptions& options,
                                std::vector<mrbsp::ColorBox>& out, density::RefineStats& stats) const {
  for (const auto& v : volumes_) {
    if (!v->spec.visible || !v->density) continue;
    v->density->refine(camera, options, out, stats);
    return true;
  }
  stats = {};
  return false;
}

void VolumeLayer::set_density(std::size_t volume, const density::DensitySpec& d) {
  spec(volume);
  Loaded& v = *volumes_[volume];
  if (!v.density) throw std::invalid_argument("volume " + std::to_string(volume + 1) + " has no density");
  volume::colormap_by_name(d.colormap);  // throws for an unknown map, before anything changes
  v.density->set_transfer(d);
  v.spec.density = d;
}

DensityFigures VolumeLayer::density_figures() const {
  DensityFigures f;
  for (std::size_t k = 0; k < volumes_.size(); ++k) {
    const Loaded& v = *volumes_[k];
    if (!v.spec.visible || !v.density) continue;
    f.drawn = true;
    f.volume = k;
    f.grid = v.density->grid();
    f.levels = v.density->levels();
    f.bytes = v.density->bytes();
    f.resample_ms = v.density->resample_ms();
    f.build_ms = v.density->build_ms();
    break;
  }
  return f;
}

Legend VolumeLayer::legend() const {
  Legend legend;
  for (const auto& v : volumes_) {
    if (!v->spec.visible || (v->spec.slices.empty() && v->spec.isosurfaces.empty() && !v->spec.density)) continue;
    const std::string units = v->data.units.empty() ? "" : " (" + v->data.units + ")";
    legend.title = v->data.name + units;
    if (!v->spec.slices.empty() && volume::is_categorical(v->spec.slices.front().colormap)) {
      // One swatch per category: the transmitters' names where the volume records them
      // (best_server), else the whole numbers within the values' range (at most 64).
      const std::vector<volume::RecordedTransmitter> tx = volume::recorded_transmitters(v->data);
      const double first = tx.empty() ? std::ceil(static_cast<double>(v->range[0])) : 1.0;
      const double last = tx.empty() ? std::min(std::floor(static_cast<double>(v->range[1])), first + 63.0) : static_cast<double>(tx.size());
      for (double k = first; k <= last; k += 1.0) {
        const glm::u8vec3 c = volume::category_color(static_cast<std::int64_t>(k));
        legend.categories.push_back({tx.empty() ? std::to_string(static_cast<long long>(k))
                                                : tx[static_cast<std::size_t>(k) - 1].name,
                                     {c.r, c.g, c.b},
                                     k});
      }
      legend.categories_title = tx.empty() ? "categories" : "transmitters";
      legend.subtitle = slice_text(v->spec.slices.front()) + ": categorical";
    } else if (!v->spec.slices.empty()) {
      const volume::SliceSpec& s = v->spec.slices.front();
      legend.lo = s.lo.value_or(v->range[0]);
      legend.hi = s.hi.value_or(v->range[1]);
      legend.colormap = std::string(volume::colormap_by_name(s.colormap).name());
      legend.subtitle = slice_text(s) + ": " + legend.colormap;
    } else if (v->spec.density) {
      const density::DensitySpec& d = *v->spec.density;
      legend.lo = d.lo;
      legend.hi = d.hi;
      legend.colormap = d.colormap;
      char b[96];
      std::snprintf(b, sizeof b, "density, %g per km (%s): %s", d.sigma_per_km, std::string(density::ramp_name(d.ramp)).c_str(),
                    d.colormap.c_str());
      legend.subtitle = b;
    }
    break;
  }
  // The isosurfaces of every visible volume of the same field: named by their file when more
  // than one volume has any.
  const auto same_field = [&](const Loaded& v) {
    return v.spec.visible && v.data.name + (v.data.units.empty() ? "" : " (" + v.data.units + ")") == legend.title;
  };
  const auto with_levels = std::count_if(volumes_.begin(), volumes_.end(), [&](const auto& v) {
    return same_field(*v) && !v->spec.isosurfaces.empty();
  });
  for (const auto& v : volumes_) {
    if (!same_field(*v)) continue;
    for (const auto& iso : v->spec.isosurfaces) {
      char b[48];
      std::snprintf(b, sizeof b, "%g%s%s", static_cast<double>(iso.value), v->data.units.empty() ? "" : " ",
                    v->data.units.c_str());
      const std::string label = with_levels > 1 ? v->spec.file.stem().string() + ": " + b : std::string(b);
      legend.levels.push_back({label, {iso.color.r, iso.color.g, iso.color.b}, iso.value});
    }
  }
  return legend;
}

std::vector<PointValue> VolumeLayer::values_at(double lat, double lon, double height_agl, double ground_m) const {
  std::vector<PointValue> out;
  for (const auto& v : volumes_) {
    if (!v->spec.visible) continue;
    const volume::PointQuery q(v->data);
    out.push_back({v->spec.file.filename().string() + " " + v->data.name, v->data.units,
                   q.value(lat, lon, height_agl, ground_m)});
  }
  return out;
}

}  // namespace terravol::app::scene
