#include "reference/geometry.h"

#include <GeographicLib/LocalCartesian.hpp>

#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "volume/colormap.h"

namespace terravol::reference {

namespace {

std::uint8_t alpha_of(double opacity) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(opacity, 0.0, 1.0) * 255.0));
}

bool any_nan(const volume::Volume& v) {
  return std::any_of(v.values.begin(), v.values.end(), [](float x) { return std::isnan(x); });
}

}  // namespace

void append(Mesh& into, const Mesh& from) {
  const auto base = static_cast<std::uint32_t>(into.vertices.size());
  into.vertices.insert(into.vertices.end(), from.vertices.begin(), from.vertices.end());
  into.colors.insert(into.colors.end(), from.colors.begin(), from.colors.end());
  for (std::uint32_t t : from.triangles) into.triangles.push_back(base + t);
}

Placement::Placement(const volume::Volume& volume, const Frame& frame, const Dem* ground)
    : kind_(volume.frame), lattice_(volume.lattice), frame_(frame), ground_(ground) {
  if (kind_.kind == volume::FrameKind::kNone) {
    throw std::invalid_argument("reference: volume '" + volume.name + "' has no frame (give the scene's \"frame\")");
  }
  if (kind_.kind == volume::FrameKind::kGeographic && kind_.height == volume::HeightRef::kGround && ground == nullptr) {
    throw std::invalid_argument("reference: volume '" + volume.name + "' has heights above the ground and no DEM was given");
  }
  if (kind_.kind == volume::FrameKind::kEnu) {
    enu_ = std::make_unique<GeographicLib::LocalCartesian>(kind_.origin_lat, kind_.origin_lon, kind_.origin_h);
  }
}

Placement::~Placement() = default;

Geodetic Placement::geodetic(double i, double j, double k) const {
  const double w0 = lattice_.origin[0] + i * lattice_.spacing[0];
  const double w1 = lattice_.origin[1] + j * lattice_.spacing[1];
  const double w2 = lattice_.origin[2] + k * lattice_.spacing[2];
  Geodetic g;
  if (enu_) {
    enu_->Reverse(w0, w1, w2, g.lat, g.lon, g.h);
  } else {
    g.lon = w0;
    g.lat = w1;
    g.h = w2;
    if (kind_.height == volume::HeightRef::kGround) g.h += ground_->height(g.lat, g.lon);
  }
  return g;
}

glm::dvec3 Placement::scene(double i, double j, double k) const {
  const Geodetic g = geodetic(i, j, k);
  return frame_.to_scene(g.lat, g.lon, g.h);
}

double Placement::above_ground(const Geodetic& g) const {
  if (ground_ == nullptr) throw std::invalid_argument("reference: heights above the ground need a DEM");
  return g.h - ground_->height(g.lat, g.lon);
}

Mesh isosurface(const volume::Volume& volume, const Placement& placement, const IsoStyle& style) {
  const auto& dims = volume.lattice.dims;
  Mesh out;
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2) return out;
  // The lattice in index space: spacing 1, origin 0, so the filter's points are (i, j, k).
  vtkNew<vtkImageData> image;
  image->SetDimensions(dims[0], dims[1], dims[2]);
  vtkNew<vtkFloatArray> values;
  values->SetName("v");
  values->SetNumberOfValues(static_cast<vtkIdType>(volume.values.size()));
  const bool nan = any_nan(volume);
  for (std::size_t n = 0; n < volume.values.size(); ++n) {
    const float v = volume.values[n];
    values->SetValue(static_cast<vtkIdType>(n), std::isnan(v) ? style.value + 1.0f : v);
  }
  image->GetPointData()->SetScalars(values);
  vtkNew<vtkFlyingEdges3D> fe;
  fe->SetInputData(image);
  fe->SetValue(0, style.value);
  fe->ComputeNormalsOff();
  fe->ComputeGradientsOff();
  fe->ComputeScalarsOff();
  fe->InterpolateAttributesOff();
  fe->Update();
  vtkPolyData* mesh = fe->GetOutput();
  vtkPoints* points = mesh->GetPoints();
  if (points == nullptr || mesh->GetNumberOfPolys() == 0) return out;

  const vtkIdType n_points = points->GetNumberOfPoints();
  std::vector<std::array<double, 3>> index(static_cast<std::size_t>(n_points));
  out.vertices.resize(static_cast<std::size_t>(n_points));
  for (vtkIdType p = 0; p < n_points; ++p) {
    auto& ijk = index[static_cast<std::size_t>(p)];
    points->GetPoint(p, ijk.data());
    out.vertices[static_cast<std::size_t>(p)] = placement.scene(ijk[0], ijk[1], ijk[2]);
  }
  const glm::u8vec4 rgba(style.color[0], style.color[1], style.color[2], alpha_of(style.opacity));
  out.colors.assign(out.vertices.size(), rgba);

  // A triangle lies in one lattice cell; it is dropped when a lattice point of the box around
  // its vertices is NaN (conservative for triangles lying in a cell face).
  auto touches_nan = [&](const vtkIdType* ids) {
    std::array<int, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      double mn = std::numeric_limits<double>::max(), mx = -mn;
      for (int v = 0; v < 3; ++v) {
        mn = std::min(mn, index[static_cast<std::size_t>(ids[v])][static_cast<std::size_t>(a)]);
        mx = std::max(mx, index[static_cast<std::size_t>(ids[v])][static_cast<std::size_t>(a)]);
      }
      lo[static_cast<std::size_t>(a)] = std::max(0, static_cast<int>(std::floor(mn)));
      hi[static_cast<std::size_t>(a)] = std::min(dims[static_cast<std::size_t>(a)] - 1, static_cast<int>(std::ceil(mx)));
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i)
          if (std::isnan(volume.at(i, j, k))) return true;
    return false;
  };
  vtkCellArray* polys = mesh->GetPolys();
  vtkNew<vtkIdList> cell;
  out.triangles.reserve(static_cast<std::size_t>(3 * polys->GetNumberOfCells()));
  for (vtkIdType c = 0; c < polys->GetNumberOfCells(); ++c) {
    polys->GetCellAtId(c, cell);
    if (cell->GetNumberOfIds() != 3) continue;
    const vtkIdType* ids = cell->GetPointer(0);
    if (nan && touches_nan(ids)) continue;
    for (int v = 0; v < 3; ++v) out.triangles.push_back(static_cast<std::uint32_t>(ids[v]));
  }
  return out;
}

Mesh slice(const volume::Volume& volume, const Placement& placement, const SliceStyle& style) {
  const volume::Colormap map = volume::colormap_by_name(style.colormap);
  const auto& dims = volume.lattice.dims;
  // The line's axis and the sheet's two axes.
  int axis = 2, sa = 0, sb = 1;
  if (style.kind == SliceKind::kLat) {
    axis = 1, sa = 0, sb = 2;
  } else if (style.kind == SliceKind::kLon) {
    axis = 0, sa = 1, sb = 2;
  }
  auto quantity = [&](const std::array<double, 3>& ijk) {
    const Geodetic g = placement.geodetic(ijk[0], ijk[1], ijk[2]);
    switch (style.kind) {
      case SliceKind::kLat: return g.lat;
      case SliceKind::kLon: return g.lon;
      case SliceKind::kAlt: return g.h;
      case SliceKind::kAgl: return placement.above_ground(g);
    }
    return g.h;
  };

  float lo = std::numeric_limits<float>::max(), hi = -lo;
  for (float v : volume.values)
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  lo = style.lo.value_or(lo);
  hi = style.hi.value_or(hi);
  const std::uint8_t alpha = alpha_of(style.opacity);

  const int na = dims[static_cast<std::size_t>(sa)], nb = dims[static_cast<std::size_t>(sb)];
  const int nl = dims[static_cast<std::size_t>(axis)];
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> vertex(static_cast<std::size_t>(na) * static_cast<std::size_t>(nb), kNone);
  Mesh out;
  std::vector<double> f(static_cast<std::size_t>(nl));
  for (int b = 0; b < nb; ++b) {
    for (int a = 0; a < na; ++a) {
      std::array<double, 3> ijk{};
      ijk[static_cast<std::size_t>(sa)] = a;
      ijk[static_cast<std::size_t>(sb)] = b;
      auto f_at = [&](double t) {
        std::array<double, 3> p = ijk;
        p[static_cast<std::size_t>(axis)] = t;
        return quantity(p) - style.value;
      };
      for (int n = 0; n < nl; ++n) f[static_cast<std::size_t>(n)] = f_at(n);
      int seg = -1;
      for (int n = 0; n + 1 < nl && seg < 0; ++n) {
        const double f0 = f[static_cast<std::size_t>(n)], f1 = f[static_cast<std::size_t>(n + 1)];
        if ((f0 <= 0 && f1 >= 0) || (f0 >= 0 && f1 <= 0)) seg = n;
      }
      if (seg < 0) continue;
      // Regula falsi (Illinois) on [seg, seg + 1]: one step when f is linear along the line.
      double x0 = seg, x1 = seg + 1, f0 = f[static_cast<std::size_t>(seg)], f1 = f[static_cast<std::size_t>(seg + 1)];
      double t = f0 == 0 ? x0 : f1 == 0 ? x1 : x0 - f0 * (x1 - x0) / (f1 - f0);
      const double tolerance = style.kind == SliceKind::kLat || style.kind == SliceKind::kLon ? 1e-11 : 1e-7;
      for (int it = 0, side = 0; it < 100 && f0 != 0 && f1 != 0; ++it) {
        const double ft = f_at(t);
        if (std::abs(ft) <= tolerance || x1 - x0 < 1e-13) break;
        if ((ft < 0) == (f0 < 0)) {
          x0 = t, f0 = ft;
          if (side == -1) f1 *= 0.5;
          side = -1;
        } else {
          x1 = t, f1 = ft;
          if (side == 1) f0 *= 0.5;
          side = 1;
        }
        t = x0 - f0 * (x1 - x0) / (f1 - f0);
      }
      // The value, linear along the line; NaN when a NaN end has weight.
      const double s = t - seg;
      std::array<int, 3> p0{static_cast<int>(ijk[0]), static_cast<int>(ijk[1]), static_cast<int>(ijk[2])}, p1 = p0;
      p0[static_cast<std::size_t>(axis)] = seg;
      p1[static_cast<std::size_t>(axis)] = seg + 1;
      const float v0 = volume.at(p0[0], p0[1], p0[2]), v1 = volume.at(p1[0], p1[1], p1[2]);
      if ((s < 1 && std::isnan(v0)) || (s > 0 && std::isnan(v1))) continue;
      const double v = s == 0 ? v0 : s == 1 ? v1 : (1 - s) * v0 + s * v1;
      const double u = lo == hi ? 0.5 : std::clamp((v - lo) / (static_cast<double>(hi) - lo), 0.0, 1.0);
      std::array<double, 3> at = ijk;
      at[static_cast<std::size_t>(axis)] = t;
      vertex[static_cast<std::size_t>(b) * na + a] = static_cast<std::uint32_t>(out.vertices.size());
      out.vertices.push_back(placement.scene(at[0], at[1], at[2]));
      const glm::u8vec3 c = map.map(u);
      out.colors.emplace_back(c.r, c.g, c.b, alpha);
    }
  }
  if (out.vertices.empty()) throw std::invalid_argument("reference: the slice misses the volume '" + volume.name + "'");
  for (int b = 0; b + 1 < nb; ++b) {
    for (int a = 0; a + 1 < na; ++a) {
      const std::uint32_t v00 = vertex[static_cast<std::size_t>(b) * na + a], v10 = vertex[static_cast<std::size_t>(b) * na + a + 1];
      const std::uint32_t v01 = vertex[static_cast<std::size_t>(b + 1) * na + a], v11 = vertex[static_cast<std::size_t>(b + 1) * na + a + 1];
      if (v00 == kNone || v10 == kNone || v01 == kNone || v11 == kNone) continue;
      const double d0 = glm::distance(out.vertices[v00], out.vertices[v11]);
      const double d1 = glm::distance(out.vertices[v10], out.vertices[v01]);
      if (d0 <= d1) {
        out.triangles.insert(out.triangles.end(), {v00, v10, v11, v00, v11, v01});
      } else {
        out.triangles.insert(out.triangles.end(), {v00, v10, v01, v10, v11, v01});
      }
    }
  }
  return out;
}

}  // namespace terravol::reference
