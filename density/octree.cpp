// The colour-cube octree (Chamberlain et al. 1996; their 1995 report), for a volume density.
//
// Leaves (1996, section 4, "at each leaf cell a color-cube is created"): the paper renders a
// leaf's geometry through each face to a 4x4 image and averages it; a leaf here is a box of an
// emission-absorption medium (density/transfer.h) whose value is known at its eight corners,
// so each face is computed, as the paper allows ("compute the RGBA value analytically"), from
// four rays along the face's normal through the box's edges: along each edge the first half
// has its near corner's colour and extinction, the second half its far corner's, composited
// front over back, and the four averaged (premultiplied). Half a box's extinction along each
// axis comes from the transfer table (one exp per table entry, not per ray).
//
// Cells above the leaves (1996, section 4 and figure 3): for each face, the four pairs of
// children along its normal composited front over back, the four averaged. Where a cell
// reaches beyond the volume (its box is cut to the volume's; the box grid need not be a power
// of two) only the pairs that exist are averaged, over the part of the face they cover, and a
// missing child of a pair is clear. The 1995 report's coverage-aware variant (section 4.1:
// coverages added, assuming "minimal overlap", and coverage-weighted averages) is
// Compositing::kCoverage; over a medium, "over" is what the light does (the back child is seen
// through the front one), and kCoverage makes coarse cells too opaque: the default is kOver
// (docs/architecture.md gives the measurement).
//
// Build: post-order, in parallel (TBB) over the subtrees of the first level from the top with
// at least 64 cells; each cell's faces are computed once in float and kept in 8 bits (straight
// colour, sqrt of alpha). Subtrees whose columns hold no data at their heights (below the
// ground, above the top layer) are skipped: their cells are clear.
//
// Refinement (1995 report, section 3.1, Render(cell)): from the root, a cell outside the view
// frustum is left out, a clear cell is left out, a cell whose largest side spans fewer than
// epsilon pixels at its distance is drawn as its faces, a leaf is drawn, and otherwise its
// children are visited far side first along every axis (a back-to-front order: any two cells of
// an octree are separated by a plane of their common ancestor, and the far side of it comes
// first). With RefineOptions::error_tolerance, a cell whose error (how far its faces are from
// the columns of children they average, plus its children's: kept per cell at the build) is
// within it is also drawn while it spans fewer than max_size_px pixels (Laur and Hanrahan's
// error-bounded levels). Below the level with at least 64 cells the subtrees are walked in
// parallel (TBB) and their boxes put in the one walk's order. Departures: the 1995
// implementation drew every face and did not cull; the faces that face the eye are chosen by
// mrbsp (mrbsp/color_boxes.h), which also orders them with the terrain and the merged surfaces.
#include "density/octree.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include <tbb/parallel_for.h>

namespace terravol::density {

namespace {

using Faces = ColorCubeOctree::Faces;
using Packed = ColorCubeOctree::Packed;

glm::vec4 over(const glm::vec4& front, const glm::vec4& back) { return front + (1.0f - front.a) * back; }

// The 1995 report's composite: the back covers what the front leaves, up to its own coverage.
glm::vec4 cover(const glm::vec4& front, const glm::vec4& back) {
  const float a = std::min(1.0f, front.a + back.a);
  if (!(back.a > 0.0f)) return front;
  const float share = (a - front.a) / back.a;
  return glm::vec4(glm::vec3(front) + share * glm::vec3(back), a);
}

// A cell's six faces from its eight children's (child c at offset (c & 1, c >> 1 & 1, c >> 2);
// children beyond the level below, `dc` cells per axis, are clear), 1996 section 4: per axis a,
// each column of two children composited front over back along a (low face: the low child in
// front; high face: the high one), and the columns that lie inside the level below averaged.
// `deviation` gets the largest difference of a channel between a face and one of the
// columns it averages.
Faces compose(const Faces (&child)[8], const std::array<int, 3>& dc, int i, int j, int k, Compositing compositing,
              float& deviation) {
  const auto composite = compositing == Compositing::kOver ? over : cover;
  const int idx[3] = {i, j, k};
  Faces f{};
  for (int a = 0; a < 3; ++a) {
    const int bit = 1 << a, u = (a + 1) % 3, v = (a + 2) % 3;
    glm::vec4 low_first(0.0f), high_first(0.0f);
    glm::vec4 low_columns[4], high_columns[4];
    int columns = 0;
    for (int c = 0; c < 8; ++c) {
      if (c & bit) continue;
      const int cu = 2 * idx[u] + ((c >> u) & 1), cv = 2 * idx[v] + ((c >> v) & 1);
      if (cu >= dc[static_cast<std::size_t>(u)] || cv >= dc[static_cast<std::size_t>(v)]) continue;
      const std::size_t lo = static_cast<std::size_t>(c), hi = static_cast<std::size_t>(c | bit);
      low_columns[columns] = composite(child[lo][static_cast<std::size_t>(2 * a)], child[hi][static_cast<std::size_t>(2 * a)]);
      high_columns[columns] = composite(child[hi][static_cast<std::size_t>(2 * a + 1)], child[lo][static_cast<std::size_t>(2 * a + 1)]);
      low_first += low_columns[columns];
      high_first += high_columns[columns];
      ++columns;
    }
    const float w = columns > 0 ? 1.0f / static_cast<float>(columns) : 0.0f;
    f[static_cast<std::size_t>(2 * a)] = w * low_first;
    f[static_cast<std::size_t>(2 * a + 1)] = w * high_first;
    for (int c = 0; c < columns; ++c) {
      const glm::vec4 dl = glm::abs(low_columns[c] - f[static_cast<std::size_t>(2 * a)]);
      const glm::vec4 dh = glm::abs(high_columns[c] - f[static_cast<std::size_t>(2 * a + 1)]);
      deviation = std::max({deviation, dl.r, dl.g, dl.b, dl.a, dh.r, dh.g, dh.b, dh.a});
    }
  }
  return f;
}

// An error in 1/255 units, rounded up and saturated.
std::uint8_t error_byte(float e) { return static_cast<std::uint8_t>(std::min(255.0f, std::ceil(e * 255.0f - 1e-4f))); }

Packed pack(const Faces& f) {
  Packed p{};
  for (std::size_t k = 0; k < 6; ++k) {
    const float a = std::clamp(f[k].a, 0.0f, 1.0f);
    if (!(a > 0.0f)) continue;
    const glm::vec3 c = glm::clamp(glm::vec3(f[k]) / a, 0.0f, 1.0f);
    p[k] = glm::u8vec4(static_cast<std::uint8_t>(c.r * 255.0f + 0.5f), static_cast<std::uint8_t>(c.g * 255.0f + 0.5f),
                       static_cast<std::uint8_t>(c.b * 255.0f + 0.5f), static_cast<std::uint8_t>(std::sqrt(a) * 255.0f + 0.5f));
  }
  return p;
}

Faces unpack(const Packed& p) {
  Faces f{};
  for (std::size_t k = 0; k < 6; ++k) {
    const float s = static_cast<float>(p[k].a) / 255.0f, a = s * s;
    f[k] = glm::vec4(glm::vec3(p[k]) / 255.0f * a, a);
  }
  return f;
}

bool clear(const Faces& f) {
  for (const glm::vec4& v : f)
    if (v.a > 0.0f) return false;
  return true;
}

// A hash of a cell's face, uniform in [0, 1): the stochastic rounding of its alpha.
float dither(int level, int i, int j, int k, int face) {
  std::uint64_t h = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32 | static_cast<std::uint32_t>(j)) *
                    0x9E3779B97F4A7C15ull;
  h ^= (static_cast<std::uint64_t>(static_cast<std::uint32_t>(k)) << 8 | static_cast<std::uint64_t>(level) << 3 |
        static_cast<std::uint64_t>(face)) * 0xC2B2AE3D27D4EB4Full;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  return static_cast<float>(h >> 40) * 0x1.0p-24f;
}

struct Plane {
  glm::dvec3 n;
  double d;
};

// The view frustum's four side planes and its near plane, normals pointing in.
std::array<Plane, 5> frustum(const mrbsp::Camera& c) {
  const glm::dvec3 f = glm::normalize(c.forward), r = glm::normalize(glm::cross(f, c.up)), u = glm::cross(r, f);
  const double ty = std::tan(glm::radians(c.fov_y_deg) * 0.5), tx = ty * c.width / c.height;
  const glm::dvec3 corner[4] = {f + r * tx + u * ty, f - r * tx + u * ty, f - r * tx - u * ty, f + r * tx - u * ty};
  std::array<Plane, 5> planes{};
  for (int k = 0; k < 4; ++k) {
    glm::dvec3 n = glm::normalize(glm::cross(corner[k], corner[(k + 1) % 4]));
    if (glm::dot(n, f) < 0.0) n = -n;
    planes[static_cast<std::size_t>(k)] = {n, -glm::dot(n, c.eye)};
  }
  planes[4] = {f, -glm::dot(f, c.eye) - c.near_plane};
  return planes;
}

}  // namespace

ColorCubeOctree::ColorCubeOctree(const volume::Volume& v, const io::SceneFrame& frame, const volume::GroundFunction& ground,
                                 const DensitySpec& spec, const BuildOptions& options)
    : spec_(spec), options_(options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (v.frame.kind != volume::FrameKind::kGeographic) {
    throw std::invalid_argument("a density needs a volume in a geographic frame (geographic or geographic-agl); this one is " +
                                volume::format_frame(v.frame));
  }
  const bool agl = v.frame.height == volume::HeightRef::kGround;
  if (agl && !ground) throw std::invalid_argument("a density of heights above the ground needs the ground");
  const volume::Lattice& l = v.lattice;
  for (int a = 0; a < 3; ++a) {
    if (l.dims[static_cast<std::size_t>(a)] < 2) {
      throw std::invalid_argument("a density needs at least two lattice points on every axis; this volume has " +
                                  std::to_string(l.dims[0]) + " x " + std::to_string(l.dims[1]) + " x " + std::to_string(l.dims[2]));
    }
  }
  lattice_ = l.dims;
  values_ = v.values;
  const int nx = l.dims[0], ny = l.dims[1], nz = l.dims[2];
  const double dz = l.spacing[2];
  grid_.size = glm::dvec3(l.spacing[0] * frame.metres_per_degree_lon(), l.spacing[1] * frame.metres_per_degree_lat(), dz);
  grid_.origin.x = frame.x_of_lon(l.origin[0]);
  grid_.origin.y = frame.y_of_lat(l.origin[1]);
  // The height of layer 0 in each column (scene z: height less the curvature drop).
  std::vector<double> bottom(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny));
  double zlo = std::numeric_limits<double>::max(), zhi = -zlo;
  for (int j = 0; j < ny; ++j) {
    const double lat = l.world(1, j), y = grid_.origin.y + j * grid_.size.y;
    for (int i = 0; i < nx; ++i) {
      const double lon = l.world(0, i), x = grid_.origin.x + i * grid_.size.x;
      const double z = l.origin[2] + (agl ? ground(lat, lon) : 0.0) - frame.curvature_drop(x, y);
      bottom[static_cast<std::size_t>(j * nx + i)] = z;
      zlo = std::min(zlo, z);
      zhi = std::max(zhi, z + (nz - 1) * dz);
    }
  }
  grid_.origin.z = zlo;
  grid_.boxes = {nx - 1, ny - 1, std::max(1, static_cast<int>(std::ceil((zhi - zlo) / dz - 1e-9)))};
  // Box corner k of column (i, j) lies at lattice height (zlo + k dz - bottom) / dz = k - off.
  base_.resize(bottom.size());
  weight_.resize(bottom.size());
  for (std::size_t c = 0; c < bottom.size(); ++c) {
    double kf = (zlo - bottom[c]) / dz;  // <= 0
    // Box corners within a millionth of a layer of one lie on it (columns whose layer 0 is the
    // lowest, or lies a whole number of layers above it, up to rounding).
    if (std::abs(kf - std::round(kf)) < 1e-6) kf = std::round(kf);
    const double b = std::floor(kf);
    base_[c] = static_cast<std::int32_t>(b);
    weight_[c] = static_cast<float>(kf - b);
  }
  // The heights a cell may hold data in, per column block and level.
  const auto column_range = [&](int i, int j) {
    const std::size_t c = static_cast<std::size_t>(j * nx + i);
    const std::int32_t lo = -base_[c], hi = nz - 1 - base_[c] - (weight_[c] > 0.0f ? 1 : 0);
    return std::array<std::int32_t, 2>{lo, hi};
  };
  dims_.push_back(grid_.boxes);
  while (dims_.back()[0] > 1 || dims_.back()[1] > 1 || dims_.back()[2] > 1) {
    const auto& d = dims_.back();
    dims_.push_back({(d[0] + 1) / 2, (d[1] + 1) / 2, (d[2] + 1) / 2});
  }
  filled_.resize(dims_.size());
  {
    auto& f0 = filled_[0];
    f0.resize(static_cast<std::size_t>(grid_.boxes[0]) * static_cast<std::size_t>(grid_.boxes[1]));
    for (int j = 0; j < grid_.boxes[1]; ++j)
      for (int i = 0; i < grid_.boxes[0]; ++i) {
        std::array<std::int32_t, 2> r{std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::min()};
        for (int c = 0; c < 4; ++c) {
          const auto q = column_range(i + (c & 1), j + (c >> 1));
          if (q[0] > q[1]) continue;
          r[0] = std::min(r[0], q[0] - 1);  // a leaf at k - 1 has its top corners at k
          r[1] = std::max(r[1], q[1]);
        }
        f0[static_cast<std::size_t>(j * grid_.boxes[0] + i)] = r;
      }
  }
  for (std::size_t lv = 1; lv < dims_.size(); ++lv) {
    const auto& below = filled_[lv - 1];
    const auto& db = dims_[lv - 1];
    const auto& d = dims_[lv];
    auto& f = filled_[lv];
    f.assign(static_cast<std::size_t>(d[0]) * static_cast<std::size_t>(d[1]),
             {std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::min()});
    for (int j = 0; j < db[1]; ++j)
      for (int i = 0; i < db[0]; ++i) {
        const auto& q = below[static_cast<std::size_t>(j * db[0] + i)];
        auto& r = f[static_cast<std::size_t>((j / 2) * d[0] + i / 2)];
        r[0] = std::min(r[0], q[0]);
        r[1] = std::max(r[1], q[1]);
      }
  }
  resample_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  build_all();
}

void ColorCubeOctree::set_transfer(const DensitySpec& spec) {
  spec_ = spec;
  build_all();
}

std::size_t ColorCubeOctree::bytes() const {
  std::size_t b = values_.capacity() * sizeof(float) + base_.capacity() * sizeof(std::int32_t) + weight_.capacity() * sizeof(float) +
                  entries_.capacity() * sizeof(std::int16_t);
  for (const auto& l : packed_) b += l.capacity() * sizeof(Packed);
  for (const auto& l : errors_) b += l.capacity();
  for (const auto& l : filled_) b += l.capacity() * sizeof(std::array<std::int32_t, 2>);
  return b;
}

std::size_t ColorCubeOctree::cell_index(int level, int i, int j, int k) const {
  const auto& d = dims_[static_cast<std::size_t>(level)];
  return (static_cast<std::size_t>(k) * static_cast<std::size_t>(d[1]) + static_cast<std::size_t>(j)) * static_cast<std::size_t>(d[0]) +
         static_cast<std::size_t>(i);
}

int ColorCubeOctree::parallel_level() const {
  int level = levels() - 1;
  while (level > 1) {
    const auto& d = dims_[static_cast<std::size_t>(level)];
    if (static_cast<std::size_t>(d[0]) * static_cast<std::size_t>(d[1]) *
            static_cast<std::size_t>(d[2]) >=
        64)
      break;
    --level;
  }
  return level;
}

bool ColorCubeOctree::maybe_filled(int level, int i, int j, int k) const {
  const auto& d = dims_[static_cast<std::size_t>(level)];
  const auto& r = filled_[static_cast<std::size_t>(level)][static_cast<std::size_t>(j * d[0] + i)];
  const std::int32_t k0 = k << level, k1 = ((k + 1) << level) - 1;
  return r[0] <= k1 && r[1] >= k0;
}

float ColorCubeOctree::corner_value(int i, int j, int k) const {
  const std::size_t c = static_cast<std::size_t>(j * lattice_[0] + i);
  const std::int32_t k0 = base_[c] + k;
  const float w = weight_[c];
  const int nz = lattice_[2];
  if (k0 < 0 || k0 > nz - 1 || (w > 0.0f && k0 + 1 > nz - 1)) return std::numeric_limits<float>::quiet_NaN();
  const std::size_t layer = static_cast<std::size_t>(lattice_[0]) * static_cast<std::size_t>(lattice_[1]);
  const float a = values_[static_cast<std::size_t>(k0) * layer + c];
  if (w == 0.0f) return a;
  return (1.0f - w) * a + w * values_[static_cast<std::size_t>(k0 + 1) * layer + c];
}

void ColorCubeOctree::cell_box(int level, int i, int j, int k, glm::dvec3& lo, glm::dvec3& hi) const {
  const int idx[3] = {i, j, k};
  for (int a = 0; a < 3; ++a) {
    const int first = idx[a] << level, last = std::min((idx[a] + 1) << level, grid_.boxes[static_cast<std::size_t>(a)]);
    lo[a] = grid_.origin[a] + first * grid_.size[a];
    hi[a] = grid_.origin[a] + last * grid_.size[a];
  }
}

Faces ColorCubeOctree::leaf_faces(int i, int j, int k) const {
  const TransferTable& t = *table_;
  const std::size_t nx = static_cast<std::size_t>(grid_.boxes[0]) + 1, ny = static_cast<std::size_t>(grid_.boxes[1]) + 1;
  const std::size_t base = (static_cast<std::size_t>(k) * ny + static_cast<std::size_t>(j)) * nx + static_cast<std::size_t>(i);
  int entry[8];
  bool any = false;
  for (int c = 0; c < 8; ++c) {
    entry[c] = entries_[base + static_cast<std::size_t>(c & 1) + static_cast<std::size_t>((c >> 1) & 1) * nx +
                        static_cast<std::size_t>(c >> 2) * nx * ny];
    any |= entry[c] >= 0;
  }
  Faces f{};
  if (!any) return f;
  for (int a = 0; a < 3; ++a) {
    const int bit = 1 << a;
    glm::vec4 low_first(0.0f), high_first(0.0f);  // seen from the low side, and from the high side
    for (int c = 0; c < 8; ++c) {
      if (c & bit) continue;  // c: the edge's low corner; c | bit its high one
      const int lo = entry[c], hi = entry[c | bit];
      const glm::vec4 l = lo < 0 ? glm::vec4(0.0f) : glm::vec4(t.color(lo) * t.half_alpha(lo, a), t.half_alpha(lo, a));
      const glm::vec4 h = hi < 0 ? glm::vec4(0.0f) : glm::vec4(t.color(hi) * t.half_alpha(hi, a), t.half_alpha(hi, a));
      low_first += over(l, h);
      high_first += over(h, l);
    }
    f[static_cast<std::size_t>(2 * a)] = 0.25f * low_first;
    f[static_cast<std::size_t>(2 * a + 1)] = 0.25f * high_first;
  }
  return f;
}

Faces ColorCubeOctree::build_cell(int level, int i, int j, int k) {
  if (!maybe_filled(level, i, j, k)) return Faces{};
  if (level == 0) return leaf_faces(i, j, k);
  const auto& dc = dims_[static_cast<std::size_t>(level - 1)];
  Faces child[8];
  for (int c = 0; c < 8; ++c) {
    const int ci = 2 * i + (c & 1), cj = 2 * j + ((c >> 1) & 1), ck = 2 * k + (c >> 2);
    child[c] = ci < dc[0] && cj < dc[1] && ck < dc[2] ? build_cell(level - 1, ci, cj, ck) : Faces{};
  }
  float deviation = 0.0f;
  const Faces f = compose(child, dc, i, j, k, options_.compositing, deviation);
  keep(level, i, j, k, f, deviation);
  return f;
}

void ColorCubeOctree::keep(int level, int i, int j, int k, const Faces& f, float deviation) {
  const std::size_t at = cell_index(level, i, j, k);
  packed_[static_cast<std::size_t>(level)][at] = pack(f);
  errors_[static_cast<std::size_t>(level)][at] = error_byte(deviation + children_error(level, i, j, k));
}

float ColorCubeOctree::children_error(int level, int i, int j, int k) const {
  if (level <= 1) return 0.0f;
  const auto& dc = dims_[static_cast<std::size_t>(level - 1)];
  std::uint8_t most = 0;
  for (int c = 0; c < 8; ++c) {
    const int ci = 2 * i + (c & 1), cj = 2 * j + ((c >> 1) & 1), ck = 2 * k + (c >> 2);
    if (ci < dc[0] && cj < dc[1] && ck < dc[2]) most = std::max(most, errors_[static_cast<std::size_t>(level - 1)][cell_index(level - 1, ci, cj, ck)]);
  }
  return static_cast<float>(most) / 255.0f;
}

double ColorCubeOctree::cell_error(int level, int i, int j, int k) const {
  if (level == 0) return 0.0;
  return static_cast<double>(errors_[static_cast<std::size_t>(level)][cell_index(level, i, j, k)]) / 255.0;
}

void ColorCubeOctree::build_all() {
  const auto t0 = std::chrono::steady_clock::now();
  table_.emplace(spec_, grid_.size * 0.5);
  {
    // Every box corner's entry, in parallel over the corner layers.
    const std::size_t nx = static_cast<std::size_t>(grid_.boxes[0]) + 1, ny = static_cast<std::size_t>(grid_.boxes[1]) + 1;
    const std::size_t nz = static_cast<std::size_t>(grid_.boxes[2]) + 1;
    entries_.assign(nx * ny * nz, -1);
    tbb::parallel_for(std::size_t{0}, nz, [&](std::size_t k) {
      for (std::size_t j = 0; j < ny; ++j)
        for (std::size_t i = 0; i < nx; ++i) {
          const int e = table_->entry(corner_value(static_cast<int>(i), static_cast<int>(j), static_cast<int>(k)));
          entries_[(k * ny + j) * nx + i] = static_cast<std::int16_t>(e);
        }
    });
  }
  packed_.assign(dims_.size(), {});
  errors_.assign(dims_.size(), {});
  for (std::size_t lv = 1; lv < dims_.size(); ++lv) {
    const auto& d = dims_[lv];
    const std::size_t cells = static_cast<std::size_t>(d[0]) * static_cast<std::size_t>(d[1]) * static_cast<std::size_t>(d[2]);
    packed_[lv].assign(cells, Packed{});
    errors_[lv].assign(cells, 0);
  }
  const int top = levels() - 1;
  // The level whose subtrees are built in parallel.
  const int split = parallel_level();
  std::vector<std::vector<Faces>> above(dims_.size());  // float faces of the levels split and up
  {
    const auto& d = dims_[static_cast<std::size_t>(split)];
    auto& out = above[static_cast<std::size_t>(split)];
    out.assign(static_cast<std::size_t>(d[0]) * static_cast<std::size_t>(d[1]) * static_cast<std::size_t>(d[2]), Faces{});
    tbb::parallel_for(std::size_t{0}, out.size(), [&](std::size_t n) {
      const int i = static_cast<int>(n % static_cast<std::size_t>(d[0]));
      const int j = static_cast<int>((n / static_cast<std::size_t>(d[0])) % static_cast<std::size_t>(d[1]));
      const int k = static_cast<int>(n / (static_cast<std::size_t>(d[0]) * static_cast<std::size_t>(d[1])));
      out[n] = build_cell(split, i, j, k);
    });
  }
  // Above the split level: the same composition, from the float faces kept.
  for (int lv = split + 1; lv <= top; ++lv) {
    const auto& d = dims_[static_cast<std::size_t>(lv)];
    const auto& dc = dims_[static_cast<std::size_t>(lv - 1)];
    auto& out = above[static_cast<std::size_t>(lv)];
    out.assign(static_cast<std::size_t>(d[0]) * static_cast<std::size_t>(d[1]) * static_cast<std::size_t>(d[2]), Faces{});
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          Faces child[8];
          for (int c = 0; c < 8; ++c) {
            const int ci = 2 * i + (c & 1), cj = 2 * j + ((c >> 1) & 1), ck = 2 * k + (c >> 2);
            child[c] = ci < dc[0] && cj < dc[1] && ck < dc[2] ? above[static_cast<std::size_t>(lv - 1)][cell_index(lv - 1, ci, cj, ck)]
                                                              : Faces{};
          }
          float deviation = 0.0f;
          const Faces f = compose(child, dc, i, j, k, options_.compositing, deviation);
          out[cell_index(lv, i, j, k)] = f;
          keep(lv, i, j, k, f, deviation);
        }
  }
  build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::array<glm::vec4, 6> ColorCubeOctree::cell_faces(int level, int i, int j, int k) const {
  if (level == 0) return leaf_faces(i, j, k);
  return unpack(packed_[static_cast<std::size_t>(level)][cell_index(level, i, j, k)]);
}

void ColorCubeOctree::refine(const mrbsp::Camera& camera, const RefineOptions& options, std::vector<mrbsp::ColorBox>& out,
                             RefineStats& stats) const {
  const auto t0 = std::chrono::steady_clock::now();
  stats = {};
  stats.per_level.assign(dims_.size(), 0);
  const auto planes = frustum(camera);
  const double focal_px = camera.height * 0.5 / std::tan(glm::radians(camera.fov_y_deg) * 0.5);
  const glm::dvec3 eye = camera.eye;
  struct Item {
    std::int32_t level, i, j, k;
    int mask;  // frustum planes still to test
  };
  // A subtree walked on its own (the subtrees of the level `split` are walked in parallel): its
  // boxes go to `out` after the `at` boxes the walk above them had made by then.
  struct Task {
    Item root;
    std::size_t at = 0;
    std::vector<mrbsp::ColorBox> boxes;
    RefineStats stats;
  };
  const int top = levels() - 1;
  const auto emit = [&](std::vector<mrbsp::ColorBox>& drawn, RefineStats& counts, int level, int i,
                        int j, int k, const glm::dvec3& lo, const glm::dvec3& hi, const Faces& f) {
    mrbsp::ColorBox b;
    b.lo = glm::vec3(lo);
    b.hi = glm::vec3(hi);
    // The path through the box along the view: its faces' opacities are for paths along their
    // normals (the box's extent L_a), but from direction v the box's optical mass sigma V spreads
    // over its projected area P = sum_a |v_a| A_a, so that the mean path is V / P, not L_a:
    // each face's optical depth is scaled by (V / P) / L_a = A_a / P (1 on an axis, down to
    // 1/sqrt(3) for a cube seen along its diagonal). Without it a medium looks up to 1.7
    // times too dense off the axes (docs/architecture.md).
    const glm::dvec3 side = hi - lo;
    const glm::dvec3 area(side.y * side.z, side.x * side.z, side.x * side.y);
    const glm::dvec3 view = glm::normalize(0.5 * (lo + hi) - eye);
    const double projected = std::abs(view.x) * area.x + std::abs(view.y) * area.y + std::abs(view.z) * area.z;
    for (int q = 0; q < 6; ++q) {
      const glm::vec4& v = f[static_cast<std::size_t>(q)];
      if (!(v.a > 0.0f)) continue;
      // Only the faces that face the eye are drawn (mrbsp::ColorBox); the others stay clear.
      if (!((q & 1) ? eye[q / 2] > hi[q / 2] : eye[q / 2] < lo[q / 2])) continue;
      const glm::vec3 c = glm::clamp(glm::vec3(v) / v.a, 0.0f, 1.0f);
      const double scale = projected > 0.0 ? area[q / 2] / projected : 1.0;
      const double alpha = v.a >= 1.0f ? 1.0 : -std::expm1(scale * std::log1p(-static_cast<double>(v.a)));
      const float a = static_cast<float>(std::min(alpha, 1.0)) * 255.0f;
      const float fl = std::floor(a);
      const float a8 = fl + (a - fl > dither(level, i, j, k, q) ? 1.0f : 0.0f);
      b.rgba[static_cast<std::size_t>(q)] =
          glm::u8vec4(static_cast<std::uint8_t>(c.r * 255.0f + 0.5f), static_cast<std::uint8_t>(c.g * 255.0f + 0.5f),
                      static_cast<std::uint8_t>(c.b * 255.0f + 0.5f), static_cast<std::uint8_t>(a8));
    }
    drawn.push_back(b);
    ++counts.boxes;
    ++counts.per_level[static_cast<std::size_t>(level)];
  };
  // The walk from `root`; an item of level `split` is left as a task (none when split < 0).
  const auto walk = [&](const Item& root, std::vector<mrbsp::ColorBox>& drawn, RefineStats& counts,
                        int split, std::vector<Task>* tasks) {
    std::vector<Item> stack{root};
    while (!stack.empty()) {
      const Item it = stack.back();
      stack.pop_back();
      if (it.level == split) {
        tasks->push_back({it, drawn.size(), {}, {}});
        continue;
      }
      ++counts.visited;
      if (!maybe_filled(it.level, it.i, it.j, it.k)) {
        ++counts.empty;
        continue;
      }
      glm::dvec3 lo, hi;
      cell_box(it.level, it.i, it.j, it.k, lo, hi);
      int mask = options.cull ? it.mask : 0;
      for (int p = 0; p < 5 && mask != 0; ++p) {
        if (!(mask & (1 << p))) continue;
        const Plane& pl = planes[static_cast<std::size_t>(p)];
        // The box's corner farthest along the normal, and the nearest.
        const glm::dvec3 far(pl.n.x >= 0 ? hi.x : lo.x, pl.n.y >= 0 ? hi.y : lo.y,
                             pl.n.z >= 0 ? hi.z : lo.z);
        const glm::dvec3 near(pl.n.x >= 0 ? lo.x : hi.x, pl.n.y >= 0 ? lo.y : hi.y,
                              pl.n.z >= 0 ? lo.z : hi.z);
        if (glm::dot(pl.n, far) + pl.d < 0.0) {
          mask = -1;
          break;
        }
        if (glm::dot(pl.n, near) + pl.d >= 0.0) mask &= ~(1 << p);
      }
      if (mask < 0) {
        ++counts.culled;
        continue;
      }
      if (it.level == 0) {
        const Faces f = leaf_faces(it.i, it.j, it.k);
        if (clear(f)) {
          ++counts.empty;
          continue;
        }
        emit(drawn, counts, 0, it.i, it.j, it.k, lo, hi, f);
        continue;
      }
      const Packed& packed =
          packed_[static_cast<std::size_t>(it.level)][cell_index(it.level, it.i, it.j, it.k)];
      bool any = false;
      for (const glm::u8vec4& p : packed) any |= p.a > 0;
      if (!any) {
        ++counts.empty;
        continue;
      }
      if (!options.leaves_only) {
        const glm::dvec3 nearest = glm::clamp(eye, lo, hi);
        const double dist = std::max(glm::length(nearest - eye), camera.near_plane);
        const glm::dvec3 side = hi - lo;
        const double size_px = std::max({side.x, side.y, side.z}) * focal_px / dist;
        const bool within =
            options.error_tolerance > 0.0 && size_px < options.max_size_px &&
            errors_[static_cast<std::size_t>(it.level)][cell_index(it.level, it.i, it.j, it.k)] <=
                options.error_tolerance * 255.0 + 1e-9;
        if (size_px < options.threshold_px || within) {
          emit(drawn, counts, it.level, it.i, it.j, it.k, lo, hi, unpack(packed));
          continue;
        }
      }
      // The children, far side first along every axis: pushed in reverse.
      const auto& dc = dims_[static_cast<std::size_t>(it.level - 1)];
      const glm::dvec3 mid =
          grid_.origin + grid_.size * glm::dvec3((2 * it.i + 1) << (it.level - 1),
                                                 (2 * it.j + 1) << (it.level - 1),
                                                 (2 * it.k + 1) << (it.level - 1));
      int far = 0;
      for (int a = 0; a < 3; ++a)
        if (eye[a] < mid[a]) far |= 1 << a;  // the high child is the far one
      for (int n = 7; n >= 0; --n) {
        const int c = n ^ far;
        const int ci = 2 * it.i + (c & 1), cj = 2 * it.j + ((c >> 1) & 1), ck = 2 * it.k + (c >> 2);
        if (ci >= dc[0] || cj >= dc[1] || ck >= dc[2]) continue;
        stack.push_back({it.level - 1, ci, cj, ck, mask});
      }
    }
  };
  // The walk down to the parallel level, then its subtrees in parallel (TBB), each into its own
  // boxes, put in place after: the same boxes in the same order as one walk. The default view
  // over the bundled DEM refines 588k cells.
  const int split = parallel_level();
  std::vector<mrbsp::ColorBox> above;
  std::vector<Task> tasks;
  walk({top, 0, 0, 0, 31}, above, stats, split < top ? split : -1, &tasks);
  tbb::parallel_for(std::size_t{0}, tasks.size(), [&](std::size_t t) {
    Task& task = tasks[t];
    task.stats.per_level.assign(dims_.size(), 0);
    walk(task.root, task.boxes, task.stats, -1, nullptr);
  });
  std::size_t total = above.size();
  for (const Task& task : tasks) total += task.boxes.size();
  out.reserve(out.size() + total);
  std::size_t from = 0;
  for (const Task& task : tasks) {
    out.insert(out.end(), above.begin() + static_cast<std::ptrdiff_t>(from),
               above.begin() + static_cast<std::ptrdiff_t>(task.at));
    from = task.at;
    out.insert(out.end(), task.boxes.begin(), task.boxes.end());
    stats.visited += task.stats.visited;
    stats.boxes += task.stats.boxes;
    stats.culled += task.stats.culled;
    stats.empty += task.stats.empty;
    for (std::size_t l = 0; l < dims_.size(); ++l) stats.per_level[l] += task.stats.per_level[l];
  }
  out.insert(out.end(), above.begin() + static_cast<std::ptrdiff_t>(from), above.end());
  stats.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace terravol::density
