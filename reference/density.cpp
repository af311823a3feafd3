#include "reference/density.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "volume/colormap.h"

namespace terravol::reference {

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

DensityField::DensityField(const volume::Volume& v, const Frame& frame, std::function<double(double, double)> ground)
    : volume_(&v), frame_(&frame), ground_(std::move(ground)) {
  if (v.frame.kind != volume::FrameKind::kGeographic) throw std::invalid_argument("the reference marches geographic volumes only");
  agl_ = v.frame.height == volume::HeightRef::kGround;
  if (agl_ && !ground_) throw std::invalid_argument("heights above the ground need the ground");
  const volume::Lattice& l = v.lattice;
  lo_ = glm::dvec3(std::numeric_limits<double>::max());
  hi_ = -lo_;
  for (int j = 0; j < l.dims[1]; ++j)
    for (int i = 0; i < l.dims[0]; ++i) {
      const double lat = l.world(1, j), lon = l.world(0, i);
      const double g = agl_ ? ground_(lat, lon) : 0.0;
      for (const int k : {0, l.dims[2] - 1}) {
        const glm::dvec3 p = frame.to_scene(lat, lon, g + l.world(2, k));
        lo_ = glm::min(lo_, p);
        hi_ = glm::max(hi_, p);
      }
    }
}

float DensityField::at(const glm::dvec3& p) const {
  const volume::Lattice& l = volume_->lattice;
  const double lat = frame_->lat_of(p.y), lon = frame_->lon_of(p.x);
  const double fi = (lon - l.origin[0]) / l.spacing[0], fj = (lat - l.origin[1]) / l.spacing[1];
  if (!(fi >= 0.0 && fj >= 0.0 && fi <= l.dims[0] - 1 && fj <= l.dims[1] - 1)) return std::numeric_limits<float>::quiet_NaN();
  // The height of p: its z plus the curvature drop the frame takes off (to_scene of height 0).
  double h = p.z - frame_->to_scene(lat, lon, 0.0).z;
  if (agl_) h -= ground_(lat, lon);
  const double fk = (h - l.origin[2]) / l.spacing[2];
  if (!(fk >= 0.0 && fk <= l.dims[2] - 1)) return std::numeric_limits<float>::quiet_NaN();
  const double f[3] = {fi, fj, fk};
  int i0[3];
  double w[3];
  for (int a = 0; a < 3; ++a) {
    i0[a] = std::min(static_cast<int>(std::floor(f[a])), l.dims[static_cast<std::size_t>(a)] - 2);
    w[a] = f[a] - i0[a];
  }
  double sum = 0.0;
  for (int c = 0; c < 8; ++c) {
    double weight = 1.0;
    int idx[3];
    for (int a = 0; a < 3; ++a) {
      const int bit = (c >> a) & 1;
      weight *= bit ? w[a] : 1.0 - w[a];
      idx[a] = i0[a] + bit;
    }
    if (weight == 0.0) continue;
    const float v = volume_->at(idx[0], idx[1], idx[2]);
    if (std::isnan(v)) return std::numeric_limits<float>::quiet_NaN();
    sum += weight * v;
  }
  return static_cast<float>(sum);
}

MarchedImage march_density(const DensityField& field, const DensityTransfer& transfer, const MarchCamera& camera, double step,
                           const std::function<double(double, double)>& terrain) {
  const volume::Colormap map = volume::colormap_by_name(transfer.colormap);
  const double sigma_max = transfer.sigma_per_km / 1000.0;
  const int ramp = transfer.ramp == "up" ? 1 : transfer.ramp == "down" ? 2 : 0;
  MarchedImage out;
  out.width = camera.width;
  out.height = camera.height;
  out.rgba.assign(static_cast<std::size_t>(camera.width) * camera.height, glm::vec4(0.0f));
  out.inside.assign(out.rgba.size(), 0);
  const glm::dvec3 f = glm::normalize(camera.forward), r = glm::normalize(glm::cross(f, camera.up)), u = glm::cross(r, f);
  const double ty = std::tan(camera.fov_y_deg * kPi / 360.0), tx = ty * camera.width / camera.height;
  const glm::dvec3 lo = field.lo(), hi = field.hi();
  tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
    for (int py = rows.begin(); py < rows.end(); ++py) {
      for (int px = 0; px < camera.width; ++px) {
        const double sx = (2.0 * (px + 0.5) / camera.width - 1.0) * tx, sy = (1.0 - 2.0 * (py + 0.5) / camera.height) * ty;
        const glm::dvec3 d = glm::normalize(f + sx * r + sy * u);
        // The ray's stretch inside the field's box (slabs).
        double t0 = 0.0, t1 = std::numeric_limits<double>::max();
        for (int a = 0; a < 3 && t0 <= t1; ++a) {
          if (std::abs(d[a]) < 1e-15) {
            if (camera.eye[a] < lo[a] || camera.eye[a] > hi[a]) t1 = -1.0;
            continue;
          }
          double ta = (lo[a] - camera.eye[a]) / d[a], tb = (hi[a] - camera.eye[a]) / d[a];
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
        }
        if (!(t0 <= t1)) continue;
        const std::size_t at = static_cast<std::size_t>(py) * camera.width + px;
        out.inside[at] = 1;
        // Hidden before the box: checked in coarse steps where the ray could be under the ground.
        bool hidden = false;
        for (double t = 0.0; t < t0 && !hidden; t += 4.0 * step) {
          const glm::dvec3 p = camera.eye + d * t;
          hidden = p.z <= terrain(p.x, p.y);
        }
        if (hidden) continue;
        glm::dvec4 c(0.0);  // premultiplied, front to back
        for (double t = t0; t < t1 && c.a < 0.9999; t += step) {
          const double len = std::min(step, t1 - t);
          const glm::dvec3 p = camera.eye + d * (t + 0.5 * len);
          if (p.z <= terrain(p.x, p.y)) break;
          const float v = field.at(p);
          const double tt = (static_cast<double>(v) - transfer.lo) / (static_cast<double>(transfer.hi) - transfer.lo);
          if (!(tt >= 0.0 && tt <= 1.0)) continue;
          const double sigma = sigma_max * (ramp == 1 ? tt : ramp == 2 ? 1.0 - tt : 1.0);
          const double alpha = -std::expm1(-sigma * len);
          const glm::dvec3 rgb = glm::dvec3(map.map(tt)) / 255.0;
          c += (1.0 - c.a) * alpha * glm::dvec4(rgb, 1.0);
        }
        out.rgba[at] = glm::vec4(c);
      }
    }
  });
  return out;
}

std::vector<unsigned char> composite_over(const MarchedImage& m, const std::vector<unsigned char>& background) {
  std::vector<unsigned char> out(background.size());
  for (std::size_t p = 0; p < m.rgba.size(); ++p) {
    const glm::vec4& c = m.rgba[p];
    for (int k = 0; k < 3; ++k) {
      const double v = c[k] * 255.0 + (1.0 - c.a) * background[3 * p + static_cast<std::size_t>(k)];
      out[3 * p + static_cast<std::size_t>(k)] = static_cast<unsigned char>(std::clamp(std::lround(v), 0L, 255L));
    }
  }
  return out;
}

FootprintError footprint_error(const MarchedImage& m, const std::function<double(std::size_t p)>& worst) {
  std::vector<double> e;
  for (std::size_t p = 0; p < m.inside.size(); ++p)
    if (m.inside[p]) e.push_back(worst(p));
  FootprintError out;
  out.pixels = e.size();
  if (e.empty()) return out;
  for (const double v : e) out.mean += v;
  out.mean /= static_cast<double>(e.size());
  std::sort(e.begin(), e.end());
  out.p99 = e[static_cast<std::size_t>(0.99 * static_cast<double>(e.size() - 1))];
  return out;
}

FootprintError footprint_error(const MarchedImage& m, const std::vector<unsigned char>& ours,
                               const std::vector<unsigned char>& expected) {
  return footprint_error(m, [&](std::size_t p) {
    int worst = 0;
    for (std::size_t k = 0; k < 3; ++k) worst = std::max(worst, std::abs(int(ours[3 * p + k]) - int(expected[3 * p + k])));
    return static_cast<double>(worst);
  });
}

}  // namespace terravol::reference
