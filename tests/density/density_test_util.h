// Helpers of the density tests: small geographic volumes, a refinement of a lattice, and a
// software compositor of colour boxes (the renderer's blending, without GL).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include "mrbsp/color_boxes.h"
#include "volume/volume.h"

namespace terravol::density::test {

// A geographic volume: nx x ny x nz points from (lon0, lat0, h0), spacing (dlon, dlat) degrees
// and dh metres, heights above the ground when agl, value(i, j, k).
template <class F>
volume::Volume geographic_volume(int nx, int ny, int nz, double lon0, double lat0, double dlon, double dlat, double h0,
                                 double dh, bool agl, F value) {
  volume::Volume v;
  v.name = "test";
  v.units = "dB";
  v.frame.kind = volume::FrameKind::kGeographic;
  v.frame.height = agl ? volume::HeightRef::kGround : volume::HeightRef::kDatum;
  v.lattice.dims = {nx, ny, nz};
  v.lattice.origin = {lon0, lat0, h0};
  v.lattice.spacing = {dlon, dlat, dh};
  v.values.resize(v.lattice.size());
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) v.values[v.lattice.index(i, j, k)] = value(i, j, k);
  v.active_points = v.values.size();
  return v;
}

// A path-loss-like field about the frame origin (45 N, 6 E): 80 dB at 10 m from a point 100 m
// above the lattice's centre, plus 20 log10 of the distance; lattice 0.002 degrees, 60 m.
inline volume::Volume path_loss_volume(int nx, int ny, int nz, bool agl) {
  const double dlon = 0.002, dlat = 0.002, dh = 60.0;
  const double lon0 = 6.0 - 0.5 * (nx - 1) * dlon, lat0 = 45.0 - 0.5 * (ny - 1) * dlat;
  const double mx = 78846.8 * dlon, my = 111131.8 * dlat;  // metres per step near 45 N
  return geographic_volume(nx, ny, nz, lon0, lat0, dlon, dlat, 0.0, dh, agl, [&](int i, int j, int k) {
    const glm::dvec3 d((i - 0.5 * (nx - 1)) * mx, (j - 0.6 * (ny - 1)) * my, k * dh - 100.0);
    return static_cast<float>(80.0 + 20.0 * std::log10(std::max(glm::length(d), 10.0) / 10.0));
  });
}

// The lattice refined `factor` times per axis: (n - 1) factor + 1 points, trilinear.
inline volume::Volume refined(const volume::Volume& v, int factor) {
  volume::Volume r = v;
  const auto& d = v.lattice.dims;
  for (int a = 0; a < 3; ++a) {
    r.lattice.dims[static_cast<std::size_t>(a)] = (d[static_cast<std::size_t>(a)] - 1) * factor + 1;
    r.lattice.spacing[static_cast<std::size_t>(a)] = v.lattice.spacing[static_cast<std::size_t>(a)] / factor;
  }
  r.values.resize(r.lattice.size());
  for (int k = 0; k < r.lattice.dims[2]; ++k)
    for (int j = 0; j < r.lattice.dims[1]; ++j)
      for (int i = 0; i < r.lattice.dims[0]; ++i) {
        const double f[3] = {static_cast<double>(i) / factor, static_cast<double>(j) / factor, static_cast<double>(k) / factor};
        int i0[3];
        double w[3];
        for (int a = 0; a < 3; ++a) {
          i0[a] = std::min(static_cast<int>(f[a]), d[static_cast<std::size_t>(a)] - 2);
          w[a] = f[a] - i0[a];
        }
        double sum = 0.0;
        for (int c = 0; c < 8; ++c) {
          double weight = 1.0;
          for (int a = 0; a < 3; ++a) weight *= ((c >> a) & 1) ? w[a] : 1.0 - w[a];
          if (weight > 0.0) sum += weight * v.at(i0[0] + (c & 1), i0[1] + ((c >> 1) & 1), i0[2] + (c >> 2));
        }
        r.values[r.lattice.index(i, j, k)] = static_cast<float>(sum);
      }
  r.active_points = r.values.size();
  return r;
}

// The boxes' faces that face the eye, blended in the given order into a black image (premultiplied
// RGBA per pixel, row 0 at the top) as GL blends them: straight colour, src alpha, one minus src
// alpha; a pixel is covered when its centre lies inside the projected face. Pinhole camera:
// forward and up unit, fov_y degrees.
inline std::vector<glm::vec4> composite_boxes(const std::vector<mrbsp::ColorBox>& boxes, const glm::dvec3& eye,
                                              const glm::dvec3& forward, const glm::dvec3& up, double fov_y, int width,
                                              int height) {
  std::vector<glm::vec4> image(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), glm::vec4(0.0f));
  const glm::dvec3 r = glm::normalize(glm::cross(forward, up)), u = glm::cross(r, forward);
  const double focal = height * 0.5 / std::tan(fov_y * 3.14159265358979323846 / 360.0);
  for (const mrbsp::ColorBox& b : boxes) {
    for (int f = 0; f < 6; ++f) {
      const int a = f / 2, ua = (a + 1) % 3, va = (a + 2) % 3;
      if (!((f & 1) ? eye[a] > b.hi[a] : eye[a] < b.lo[a])) continue;
      const double us[4] = {b.lo[ua], b.hi[ua], b.hi[ua], b.lo[ua]}, vs[4] = {b.lo[va], b.lo[va], b.hi[va], b.hi[va]};
      std::array<glm::dvec2, 4> p;
      bool behind = false;
      for (int k = 0; k < 4; ++k) {
        glm::dvec3 q;
        q[a] = (f & 1) ? b.hi[a] : b.lo[a];
        q[ua] = us[k];
        q[va] = vs[k];
        const glm::dvec3 dq = q - eye;
        const double depth = glm::dot(dq, forward);
        behind |= depth <= 1e-3;
        p[static_cast<std::size_t>(k)] = glm::dvec2(0.5 * width + focal * glm::dot(dq, r) / depth, 0.5 * height - focal * glm::dot(dq, u) / depth);
      }
      if (behind) continue;
      double area = 0.0;
      for (int k = 0; k < 4; ++k) {
        const glm::dvec2 &s = p[static_cast<std::size_t>(k)], &t = p[static_cast<std::size_t>((k + 1) % 4)];
        area += s.x * t.y - t.x * s.y;
      }
      const double sign = area < 0 ? -1.0 : 1.0;
      double x0 = width, x1 = 0, y0 = height, y1 = 0;
      for (const auto& q : p) {
        x0 = std::min(x0, q.x);
        x1 = std::max(x1, q.x);
        y0 = std::min(y0, q.y);
        y1 = std::max(y1, q.y);
      }
      const glm::vec4 c(glm::vec3(b.rgba[static_cast<std::size_t>(f)]) / 255.0f, b.rgba[static_cast<std::size_t>(f)].a / 255.0f);
      for (int py = std::max(0, static_cast<int>(std::floor(y0))); py < std::min(height, static_cast<int>(std::ceil(y1)) + 1); ++py)
        for (int px = std::max(0, static_cast<int>(std::floor(x0))); px < std::min(width, static_cast<int>(std::ceil(x1)) + 1); ++px) {
          const glm::dvec2 centre(px + 0.5, py + 0.5);
          bool in = true;
          for (int k = 0; k < 4 && in; ++k) {
            const glm::dvec2 &s = p[static_cast<std::size_t>(k)], &t = p[static_cast<std::size_t>((k + 1) % 4)];
            in = sign * ((t.x - s.x) * (centre.y - s.y) - (t.y - s.y) * (centre.x - s.x)) >= 0.0;
          }
          if (!in) continue;
          glm::vec4& d = image[static_cast<std::size_t>(py) * static_cast<std::size_t>(width) + static_cast<std::size_t>(px)];
          d = glm::vec4(glm::vec3(c) * c.a, c.a) + (1.0f - c.a) * d;
        }
    }
  }
  return image;
}

}  // namespace terravol::density::test
