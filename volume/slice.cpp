// Colour-coded slices: one vertex where each lattice line crosses the slice surface, a quad
// per lattice cell of the sheet (geometry.h states the contract).
//
// The crossing of a line is found by regula falsi with the Illinois modification (Dowell and
// Jarratt 1971) on q(t) - value, q being the latitude, longitude, height or height above
// ground at lattice coordinate t along the line. In a geographic frame q is linear along
// every line the slice uses (latitude along j, longitude along i, height along k; the ground
// is constant along a vertical line), so the first step is exact; in an ENU frame a few steps
// converge.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "volume/colormap.h"
#include "volume/geometry.h"
#include "volume/slice_sheet.h"

namespace terravol::volume {

using detail::SliceSheet;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

int line_axis(SliceKind kind) {
  switch (kind) {
    case SliceKind::kLat:
      return 1;
    case SliceKind::kLon:
      return 0;
    case SliceKind::kAlt:
    case SliceKind::kAgl:
      break;
  }
  return 2;
}

// The volume's value at lattice coordinates p, trilinear; NaN when a point with a weight > 0
// is NaN. Precondition: 0 <= p[a] <= dims[a] - 1.
float trilinear(const Volume& v, const std::array<double, 3>& p) {
  std::array<int, 3> i0{};
  std::array<double, 3> f{};
  for (int a = 0; a < 3; ++a) {
    const int n = v.lattice.dims[a];
    i0[a] = n < 2 ? 0 : std::clamp(static_cast<int>(std::floor(p[a])), 0, n - 2);
    f[a] = n < 2 ? 0.0 : p[a] - i0[a];
  }
  double sum = 0.0;
  for (int dz = 0; dz < 2; ++dz) {
    const double wz = dz ? f[2] : 1.0 - f[2];
    if (wz == 0.0) continue;
    for (int dy = 0; dy < 2; ++dy) {
      const double wy = dy ? f[1] : 1.0 - f[1];
      if (wy == 0.0) continue;
      for (int dx = 0; dx < 2; ++dx) {
        const double wx = dx ? f[0] : 1.0 - f[0];
        if (wx == 0.0) continue;
        const float x = v.at(i0[0] + dx, i0[1] + dy, i0[2] + dz);
        if (std::isnan(x)) return kNaN;
        sum += wx * wy * wz * x;
      }
    }
  }
  return static_cast<float>(sum);
}

// The value of the lattice point nearest p (ties round away from zero): what a categorical
// slice shows, since an index interpolated between two categories is neither.
float nearest(const Volume& v, const std::array<double, 3>& p) {
  std::array<int, 3> i{};
  for (int a = 0; a < 3; ++a) i[a] = std::clamp(static_cast<int>(std::lround(p[a])), 0, v.lattice.dims[a] - 1);
  return v.at(i[0], i[1], i[2]);
}

// Finds where lattice lines cross the slice, and the extent of the sliced quantity met on
// their ends (for the error message).
class Crossing {
 public:
  Crossing(const Volume& volume, const LatticeMapper& mapper, const SliceSpec& spec, const GroundFunction& ground)
      : volume_(volume), mapper_(mapper), spec_(spec), ground_(ground), axis_(line_axis(spec.kind)) {
    tol_ = spec.kind == SliceKind::kLat || spec.kind == SliceKind::kLon ? 1e-11 : 1e-6;
  }

  // The lattice point where the line through p along the slice's axis crosses the slice, or
  // false when it does not (inside the volume).
  bool find(std::array<double, 3>& p) {
    const int n = volume_.lattice.dims[axis_];
    const double f0 = residual(p, 0.0);
    note(f0);
    if (n == 1) {
      p[axis_] = 0.0;
      return std::abs(f0) <= tol_;
    }
    const double last = n - 1.0;
    const double f1 = residual(p, last);
    note(f1);
    if (!std::isfinite(f0) || !std::isfinite(f1)) return false;
    if (std::abs(f0) <= tol_) return set(p, 0.0);
    if (std::abs(f1) <= tol_) return set(p, last);
    if ((f0 > 0.0) == (f1 > 0.0)) return false;
    double a = 0.0, fa = f0, b = last, fb = f1, t = 0.0;
    for (int iteration = 0; iteration < 60; ++iteration) {
      t = std::clamp((a * fb - b * fa) / (fb - fa), 0.0, last);
      const double ft = residual(p, t);
      if (!std::isfinite(ft)) return false;
      if (std::abs(ft) <= tol_) break;
      if ((ft > 0.0) != (fb > 0.0)) {
        a = b;
        fa = fb;
      } else {
        fa *= 0.5;
      }
      b = t;
      fb = ft;
    }
    return set(p, t);
  }

  double min_seen() const { return min_; }
  double max_seen() const { return max_; }

 private:
  // q - value at coordinate t along the line through p.
  double residual(const std::array<double, 3>& p, double t) const {
    std::array<double, 3> q = p;
    q[axis_] = t;
    const io::Geodetic g = mapper_.geodetic(q[0], q[1], q[2]);
    switch (spec_.kind) {
      case SliceKind::kLat:
        return g.lat - spec_.value;
      case SliceKind::kLon:
        return std::remainder(g.lon - spec_.value, 360.0);
      case SliceKind::kAlt:
        return g.h - spec_.value;
      case SliceKind::kAgl:
        return g.h - ground_(g.lat, g.lon) - spec_.value;
    }
    return 0.0;
  }
  void note(double f) {
    if (!std::isfinite(f)) return;
    min_ = std::min(min_, f + spec_.value);
    max_ = std::max(max_, f + spec_.value);
  }
  bool set(std::array<double, 3>& p, double t) const {
    p[axis_] = t;
    return true;
  }

  const Volume& volume_;
  const LatticeMapper& mapper_;
  const SliceSpec& spec_;
  const GroundFunction& ground_;
  int axis_;
  double tol_;
  double min_ = std::numeric_limits<double>::infinity();
  double max_ = -std::numeric_limits<double>::infinity();
};

std::string describe(const SliceSpec& spec) {
  char b[64];
  std::snprintf(b, sizeof b, "%s=%g", std::string(slice_kind_name(spec.kind)).c_str(), spec.value);
  return b;
}

[[noreturn]] void throw_outside(const Volume& volume, const SliceSpec& spec, const Crossing& c) {
  static constexpr const char* kQuantity[] = {"latitude", "longitude", "height above the datum",
                                              "height above ground"};
  std::string extent;
  if (c.min_seen() <= c.max_seen()) {
    char b[160];
    const bool degrees = spec.kind == SliceKind::kLat || spec.kind == SliceKind::kLon;
    std::snprintf(b, sizeof b, " (%s %.6g .. %.6g %s)", kQuantity[static_cast<int>(spec.kind)], c.min_seen(),
                  c.max_seen(), degrees ? "degrees" : "m");
    extent = b;
  }
  throw std::invalid_argument("slice " + describe(spec) + " lies outside the volume '" + volume.name + "'" + extent);
}

}  // namespace

namespace detail {

SliceSheet slice_sheet(const Volume& volume, const LatticeMapper& mapper, const SliceSpec& spec,
                       const GroundFunction& ground) {
  if (!std::isfinite(spec.value)) throw std::invalid_argument("slice " + describe(spec) + ": the position must be finite");
  if (!(spec.opacity >= 0.0 && spec.opacity <= 1.0)) {
    throw std::invalid_argument("slice " + describe(spec) + ": opacity must be within [0, 1]");
  }
  if (spec.kind == SliceKind::kAgl && !ground) {
    throw std::invalid_argument("slice " + describe(spec) + ": heights above ground need a ground (DEM)");
  }
  const bool categorical = is_categorical(spec.colormap);
  const Colormap colormap = colormap_by_name(categorical ? std::string_view("grey") : std::string_view(spec.colormap));

  // The colour range.
  double lo = 0.0, hi = 0.0;
  if (!spec.lo || !spec.hi) {
    float vmin = std::numeric_limits<float>::infinity(), vmax = -vmin;
    for (float x : volume.values) {
      if (!std::isfinite(x)) continue;
      vmin = std::min(vmin, x);
      vmax = std::max(vmax, x);
    }
    lo = vmin;
    hi = vmax;
  }
  if (spec.lo) lo = *spec.lo;
  if (spec.hi) hi = *spec.hi;
  const std::uint8_t alpha = static_cast<std::uint8_t>(std::lround(spec.opacity * 255.0));
  auto color_of = [&](float v) {
    if (categorical) return glm::u8vec4(category_color(std::llround(v)), alpha);
    const double t = hi == lo ? 0.5 : (v - lo) / (hi - lo);
    const glm::u8vec3 rgb = colormap.map(t);
    return glm::u8vec4(rgb, alpha);
  };

  // The sheet's sample grid: u and v run along the two lattice axes other than the line's.
  SliceSheet sheet;
  const int axis = line_axis(spec.kind);
  sheet.line_axis = axis;
  sheet.u_axis = axis == 0 ? 1 : 0;
  sheet.v_axis = axis == 2 ? 1 : 2;
  sheet.nu = volume.lattice.dims[sheet.u_axis];
  sheet.nv = volume.lattice.dims[sheet.v_axis];
  const std::size_t n = static_cast<std::size_t>(sheet.nu) * static_cast<std::size_t>(sheet.nv);
  sheet.position.assign(n, glm::dvec3(0.0));
  sheet.value.assign(n, kNaN);
  sheet.usable.assign(n, 0);
  sheet.color.assign(n, glm::u8vec4(0));
  Crossing crossing(volume, mapper, spec, ground);
  bool any = false;
  for (int v = 0; v < sheet.nv; ++v) {
    for (int u = 0; u < sheet.nu; ++u) {
      std::array<double, 3> p{};
      p[sheet.u_axis] = u;
      p[sheet.v_axis] = v;
      if (!crossing.find(p)) continue;
      const std::size_t id = sheet.index(u, v);
      any = true;
      const float value = categorical ? nearest(volume, p) : trilinear(volume, p);
      sheet.value[id] = value;
      const io::ScenePoint s = mapper.scene(p[0], p[1], p[2]);
      sheet.position[id] = {s.x, s.y, s.z};
      if (std::isnan(value)) continue;
      sheet.usable[id] = 1;
      sheet.color[id] = color_of(value);
    }
  }
  if (!any) throw_outside(volume, spec, crossing);
  return sheet;
}

}  // namespace detail

Mesh slice(const Volume& volume, const LatticeMapper& mapper, const SliceSpec& spec, const GroundFunction& ground) {
  const SliceSheet sheet = detail::slice_sheet(volume, mapper, spec, ground);
  const int nu = sheet.nu, nv = sheet.nv;
  const auto& position = sheet.position;
  Mesh mesh;
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> index(position.size(), kUnused);
  auto vertex = [&](std::size_t id) {
    if (index[id] == kUnused) {
      index[id] = static_cast<std::uint32_t>(mesh.vertices.size());
      mesh.vertices.push_back(position[id]);
      mesh.colors.push_back(sheet.color[id]);
    }
    return index[id];
  };
  auto triangle = [&](std::size_t a, std::size_t b, std::size_t c) {
    const glm::dvec3 e1 = position[b] - position[a], e2 = position[c] - position[a];
    const glm::dvec3 cr(e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x);
    if (cr.x == 0.0 && cr.y == 0.0 && cr.z == 0.0) return;
    mesh.triangles.insert(mesh.triangles.end(), {vertex(a), vertex(b), vertex(c)});
  };
  auto length2 = [](const glm::dvec3& d) { return d.x * d.x + d.y * d.y + d.z * d.z; };
  for (int v = 0; v + 1 < nv; ++v) {
    for (int u = 0; u + 1 < nu; ++u) {
      if (!sheet.cell_usable(u, v)) continue;
      const std::size_t a = sheet.index(u, v), b = a + 1, c = b + static_cast<std::size_t>(nu),
                        d = a + static_cast<std::size_t>(nu);
      if (length2(position[c] - position[a]) <= length2(position[d] - position[b])) {
        triangle(a, b, c);
        triangle(a, c, d);
      } else {
        triangle(a, b, d);
        triangle(b, c, d);
      }
    }
  }
  return mesh;
}

}  // namespace terravol::volume
