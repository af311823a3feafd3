// Hierarchical polygon tiling with coverage masks, as an antialiased renderer: N. Greene,
// "Hierarchical Polygon Tiling with Coverage Masks", SIGGRAPH 1996.
//  - Section 3.1 / listing 1 and section 4.1 (the coverage pyramid): each triangle, nearest
//    first, is tiled into a pyramid whose finest level holds one bit per sub-sample and whose
//    levels above hold triage masks; only vacant cells the triangle reaches are visited, and a
//    covered sample is never written again. coverage::Pyramid does the tiling, at sample
//    resolution: with aa = 8 its finest tiles are exactly the paper's 8x8 one-bit masks per
//    pixel (figure 2: "a four-level pyramid of 8x8 masks corresponds to a 512x512 image with
//    8x8 oversampling"); with aa = 4, 2, 1 a tile holds 2x2, 4x4 or 8x8 pixels.
//  - Section 3.1, "evaluate shading and update accumulation buffer": the W masks (newly covered
//    samples) come back from the pyramid tile by tile (Pyramid::cover with a report), and the
//    samples are shaded and box-filtered into their pixel's accumulation, A-buffer style
//    (section 2.2: "a single shading value is computed, weighted by the bit count of its
//    mask"): one colour per fragment, evaluated at the centroid of the fragment's samples, so
//    colours that are linear across a triangle (vertex colours, haze, the sky) are exact for
//    the samples. Textured terrain is not linear in a pixel that spans several texels, so there
//    the fragment is cut into blocks of samples shaded at their own centroids
//    (Settings::texel_rate), down to every sample.
//  - Section 4.3: the pyramid starts a triangle at the smallest enclosing cells and stops at
//    once when they are covered (its bounding-box test). Section 4.4, box filtering: the
//    accumulation buffer is in floats, one sum per pixel, divided by aa^2 at the end.
//  - Section 5.2 (hierarchical object-space culling, test-only tiling of node boxes) is the
//    traversal's: mrbsp's occlusion pass, which the caller runs on a camera at sample
//    resolution (app/render/tiled_view.h) so that it culls only nodes whose every sample is
//    covered; this renderer sees the triangles the traversal kept.
// Where this departs from the paper:
//  - Translucent triangles (isosurfaces, slices) are not tiled into the pyramid: the samples of
//    theirs that are still vacant (Pyramid::vacant) get colour times alpha times the
//    transmittance of what lies in front of them, and that transmittance is scaled by 1 - alpha
//    (front-to-back "under" compositing, exact in the tree's exact order). Transmittance is kept
//    per pixel, uniform while every translucent triangle in front covered all of the pixel's
//    open samples, else as a short list of classes (a sample mask and its transmittance) split
//    as translucent edges cross the pixel.
//  - The image is cut into horizontal bands, each with its own pyramid, tiled in parallel
//    (TBB); triangles are binned by the bands their projection reaches, in order.
//  - Triangles are clipped at the near and far planes and at a guard band of 2^16 pixels
//    around the viewport (the pyramid takes coordinates up to 2^24 samples); the clip point of
//    an edge is computed from its inside end, so two triangles sharing a clipped edge agree.
#include "tiler/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "coverage/pyramid.h"

namespace terravol::tiler {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

constexpr double kGuard = 65536.0;  // pixels beyond the viewport that a clipped polygon may reach
constexpr int kMaxClipped = 3 + 6;  // a triangle clipped by six planes

int popcount(std::uint64_t x) {
  // Without -mpopcnt std::popcount is a library call; the usual SWAR count.
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return static_cast<int>((x * 0x0101010101010101ull) >> 56);
}

// Masks of a pixel's samples in the 8x8 layout of a tile: sample (sx, sy) is bit sy * 8 + sx,
// the aa x aa samples of a pixel at the low corner (bits outside it are 0).
constexpr std::uint64_t kRow = 0x0101010101010101ull;
constexpr std::uint64_t rect_mask(int x0, int w, int y0, int h) {
  const std::uint64_t cols = ((std::uint64_t{1} << w) - 1) << x0;
  std::uint64_t m = 0;
  for (int r = y0; r < y0 + h; ++r) m |= cols << (8 * r);
  return m;
}
// Samples whose x (y) has bit k set, for centroids: sum of x over a mask = sum_k 2^k popcount(m & X[k]).
constexpr std::uint64_t kX1 = 0xAAAAAAAAAAAAAAAAull, kX2 = 0xCCCCCCCCCCCCCCCCull, kX4 = 0xF0F0F0F0F0F0F0F0ull;
constexpr std::uint64_t kY1 = 0xFF00FF00FF00FF00ull, kY2 = 0xFFFF0000FFFF0000ull, kY4 = 0xFFFFFFFF00000000ull;
static_assert(kRow * 0xFF == ~std::uint64_t{0});

// The centroid of a non-empty mask's samples, in samples from the pixel's low corner (centres
// at +0.5).
glm::dvec2 centroid(std::uint64_t m, int count) {
  const int sx = popcount(m & kX1) + 2 * popcount(m & kX2) + 4 * popcount(m & kX4);
  const int sy = popcount(m & kY1) + 2 * popcount(m & kY2) + 4 * popcount(m & kY4);
  return {static_cast<double>(sx) / count + 0.5, static_cast<double>(sy) / count + 0.5};
}

int pow2_at_least(double v, int cap) {
  int k = 1;
  while (k < cap && k < v) k *= 2;
  return k;
}

// An affine function of window position (output pixels from the bottom-left corner).
struct Plane {
  double a = 0, b = 0, c = 0;
  double at(double x, double y) const { return a * x + b * y + c; }
};

// Eye space: x right, y up, z the depth along the view axis (GL's clip w).
struct Eye {
  double x, y, z;
};

enum class Kind : std::uint8_t { kTextured, kWall, kMerged };

// What a triangle is shaded with: attributes interpolated perspective-correctly by the
// homogeneous barycentrics of the pixel ray (Olano and Greer 1997): with the vertices' eye
// positions V0, V1, V2 and the ray direction D(x, y) = ((x - w/2) / f, (y - h/2) / f, 1), the
// barycentrics are e_i / (e_0 + e_1 + e_2) for e_i = (V_j x V_k) . D, affine in (x, y); an
// attribute is then (sum A_i e_i) / (sum e_i), the quotient of two planes. No division by the
// determinant and no clipping is needed for it.
struct Shade {
  Kind kind = Kind::kTextured;
  bool translucent = false;
  int kx = 1, ky = 1;       // shading blocks per pixel along x and y (textured)
  Plane s;                  // sum e_i
  std::array<Plane, 5> n;   // textured: u, v (texels), haze; wall: haze; merged: r, g, b, a (0..255), haze
};

struct Class {
  std::uint64_t mask;  // open samples with this transmittance
  float t;
  std::int32_t next;
};

}  // namespace

struct Renderer::Impl {
  // Per band and thread: the band's pyramid (one per band height: the last band may be
  // shorter), the pyramid's reports, transmittance classes, polygon scratch, counters.
  struct BandState {
    std::vector<std::unique_ptr<coverage::Pyramid>> pyramids;
    std::vector<coverage::TileMask> records;
    std::vector<Class> classes;
    std::vector<glm::dvec2> poly;
    Stats stats;
    coverage::Pyramid& pyramid(int w, int h) {
      for (auto& p : pyramids)
        if (p->width() == w && p->height() == h) {
          p->clear();
          return *p;
        }
      pyramids.push_back(std::make_unique<coverage::Pyramid>(w, h));
      return *pyramids.back();
    }
  };
  tbb::enumerable_thread_specific<BandState> states;
  // Per triangle of the frame: the bands its projection reaches (first > last: none).
  std::vector<std::int32_t> band_first, band_last;
  std::vector<std::uint32_t> band_start, band_items;  // triangles of band b: items [start[b], start[b+1])
  // Per pixel, rows from the bottom: the accumulated colour (sum over samples, 0..255), the
  // uniform transmittance, the head of the transmittance classes (-1: uniform), shaded samples.
  std::vector<float> acc, uniform_t;
  std::vector<std::int32_t> head;
  std::vector<std::uint8_t> counts;
};

Renderer::Renderer(const Settings& settings) : settings_(settings), impl_(std::make_unique<Impl>()) {
  const Settings& s = settings;
  if (s.aa != 1 && s.aa != 2 && s.aa != 4 && s.aa != 8) {
    throw std::invalid_argument("tiler::Renderer: aa " + std::to_string(s.aa) + " is not 1, 2, 4 or 8");
  }
  const int limit = coverage::kMaxViewport / s.aa;
  if (s.width < 1 || s.height < 1 || s.width > limit || s.height > limit) {
    throw std::invalid_argument("tiler::Renderer: " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                                " outside 1.." + std::to_string(limit) + " pixels per side at aa " + std::to_string(s.aa));
  }
  if (!(s.texel_rate >= 0.0) || !std::isfinite(s.texel_rate)) {
    throw std::invalid_argument("tiler::Renderer: texel_rate must be a finite number >= 0");
  }
  if (s.band_rows < 1) throw std::invalid_argument("tiler::Renderer: band_rows must be >= 1");
  if (s.threads < 0) throw std::invalid_argument("tiler::Renderer: threads must be >= 0");
  const std::size_t pixels = static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height);
  rgb_.assign(pixels * 3, 0);
  counts_.assign(pixels, 0);
  impl_->acc.assign(pixels * 3, 0.0f);
  impl_->uniform_t.assign(pixels, 1.0f);
  impl_->head.assign(pixels, -1);
  impl_->counts.assign(pixels, 0);
}

Renderer::~Renderer() = default;

namespace {

// The view as GL sees it (vtkCamera from mrbsp::Camera: app/render/vtk_camera.h).
struct View {
  glm::dvec3 eye, r, u, f;
  double focal = 1, hw = 0, hh = 0, near = 1, far = 2;
  Eye to_eye(const glm::vec3& p) const {
    const glm::dvec3 d = glm::dvec3(p) - eye;
    return {glm::dot(d, r), glm::dot(d, u), glm::dot(d, f)};
  }
  glm::dvec2 window(const Eye& e) const { return {hw + focal * e.x / e.z, hh + focal * e.y / e.z}; }
  // The clip planes' values (inside where >= 0): near, far, and the guard band's four sides.
  double plane(int k, const Eye& e) const {
    switch (k) {
      case 0: return e.z - near;
      case 1: return far - e.z;
      case 2: return (hw + kGuard) * e.z + focal * e.x;
      case 3: return (hw + kGuard) * e.z - focal * e.x;
      case 4: return (hh + kGuard) * e.z + focal * e.y;
      default: return (hh + kGuard) * e.z - focal * e.y;
    }
  }
};

// The triangle's polygon in window coordinates (output pixels), clipped where it must be.
// Returns the vertex count (0: nothing in view) and whether it was clipped.
int window_polygon(const View& v, const std::array<Eye, 3>& tri, std::array<glm::dvec2, kMaxClipped>& out, bool& clipped) {
  int outside_any = 0;
  for (int k = 0; k < 6; ++k) {
    int outside = 0;
    for (const Eye& e : tri) outside += v.plane(k, e) < 0 ? 1 : 0;
    if (outside == 3) return 0;
    outside_any |= outside > 0 ? 1 << k : 0;
  }
  clipped = outside_any != 0;
  if (!clipped) {
    for (int i = 0; i < 3; ++i) out[static_cast<std::size_t>(i)] = v.window(tri[static_cast<std::size_t>(i)]);
    return 3;
  }
  // Sutherland-Hodgman in eye space, plane by plane.
  std::array<Eye, kMaxClipped> a{}, b{};
  int n = 3;
  std::copy(tri.begin(), tri.end(), a.begin());
  for (int k = 0; k < 6; ++k) {
    if (!(outside_any & (1 << k))) continue;
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const Eye& p = a[static_cast<std::size_t>(i)];
      const Eye& q = a[static_cast<std::size_t>((i + 1) % n)];
      const double dp = v.plane(k, p), dq = v.plane(k, q);
      if (dp >= 0) b[static_cast<std::size_t>(m++)] = p;
      if ((dp >= 0) != (dq >= 0)) {
        // From the inside end, so that both triangles of a shared edge get the same point.
        const Eye& in = dp >= 0 ? p : q;
        const Eye& out_end = dp >= 0 ? q : p;
        const double di = dp >= 0 ? dp : dq, d_out = dp >= 0 ? dq : dp;
        const double t = di / (di - d_out);
        b[static_cast<std::size_t>(m++)] = {in.x + (out_end.x - in.x) * t, in.y + (out_end.y - in.y) * t,
                                            in.z + (out_end.z - in.z) * t};
      }
    }
    n = m;
    if (n < 3) return 0;
    std::swap(a, b);
  }
  for (int i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = v.window(a[static_cast<std::size_t>(i)]);
  return n;
}

std::array<Eye, 3> eye_triangle(const View& v, std::span<const glm::vec3> positions, const std::uint32_t* idx) {
  return {v.to_eye(positions[idx[0]]), v.to_eye(positions[idx[1]]), v.to_eye(positions[idx[2]])};
}

// Bilinear lookup of the lattice texture at texel coordinates (u, v) (texel centres at whole
// numbers), clamped to the edge: GL's LINEAR filter with CLAMP_TO_EDGE.
glm::dvec3 texel(std::span<const std::uint8_t> tex, int side, double u, double v) {
  const double hi = side - 1;
  u = std::clamp(u, 0.0, hi);
  v = std::clamp(v, 0.0, hi);
  const int i0 = std::min(static_cast<int>(u), side - 2 < 0 ? 0 : side - 2);
  const int j0 = std::min(static_cast<int>(v), side - 2 < 0 ? 0 : side - 2);
  const double fu = u - i0, fv = v - j0;
  const int i1 = std::min(i0 + 1, side - 1), j1 = std::min(j0 + 1, side - 1);
  const auto at = [&](int i, int j) {
    const std::uint8_t* c = &tex[4 * (static_cast<std::size_t>(j) * static_cast<std::size_t>(side) + static_cast<std::size_t>(i))];
    return glm::dvec3(c[0], c[1], c[2]);
  };
  const glm::dvec3 bottom = at(i0, j0) + (at(i1, j0) - at(i0, j0)) * fu;
  const glm::dvec3 top = at(i0, j1) + (at(i1, j1) - at(i0, j1)) * fu;
  return bottom + (top - bottom) * fv;
}

}  // namespace

Stats Renderer::render(const SceneColors& colors, const Look& look, const mrbsp::Camera& camera, double far_plane,
                       std::span<const std::uint32_t> indices) {
  const auto t_start = Clock::now();
  const Settings& s = settings_;
  const int W = s.width, H = s.height, aa = s.aa;
  if (camera.width != W || camera.height != H) {
    throw std::invalid_argument("tiler::Renderer::render: camera of " + std::to_string(camera.width) + "x" +
                                std::to_string(camera.height) + " for a " + std::to_string(W) + "x" + std::to_string(H) +
                                " renderer");
  }
  if (!(camera.near_plane > 0.0) || !(far_plane > camera.near_plane) || !std::isfinite(far_plane)) {
    throw std::invalid_argument("tiler::Renderer::render: near and far planes must satisfy 0 < near < far");
  }
  const std::size_t side = static_cast<std::size_t>(std::max(colors.lattice_side, 0));
  const std::size_t lattice = side * side;
  if (colors.texture.size() != 4 * lattice || colors.merged_base < lattice || colors.merged_base > colors.positions.size() ||
      colors.merged_colors.size() != colors.positions.size() - colors.merged_base) {
    throw std::invalid_argument("tiler::Renderer::render: vertex layout does not match (" + std::to_string(colors.positions.size()) +
                                " positions, " + std::to_string(lattice) + " lattice samples, texture " +
                                std::to_string(colors.texture.size()) + " bytes, merged base " + std::to_string(colors.merged_base) +
                                ", " + std::to_string(colors.merged_colors.size()) + " merged colours)");
  }
  if (indices.size() % 3 != 0) throw std::invalid_argument("tiler::Renderer::render: index count not a multiple of 3");
  const std::size_t n_vertices = colors.positions.size();
  if (std::any_of(indices.begin(), indices.end(), [&](std::uint32_t i) { return i >= n_vertices; })) {
    throw std::invalid_argument("tiler::Renderer::render: an index is beyond the " + std::to_string(n_vertices) + " positions");
  }

  View view;
  view.eye = camera.eye;
  view.f = glm::normalize(camera.forward);
  view.r = glm::normalize(glm::cross(view.f, camera.up));
  view.u = glm::cross(view.r, view.f);
  view.focal = H * 0.5 / std::tan(camera.fov_y_deg * 0.5 * 3.14159265358979323846 / 180.0);
  view.hw = 0.5 * W;
  view.hh = 0.5 * H;
  view.near = camera.near_plane;
  view.far = far_plane;

  Impl& m = *impl_;
  const std::size_t n_tri = indices.size() / 3;
  const int R = std::min(s.band_rows, H);
  const int bands = (H + R - 1) / R;
  m.band_first.resize(n_tri);
  m.band_last.resize(n_tri);
  for (auto& st : m.states) st.stats = Stats{};

  std::unique_ptr<tbb::task_arena> arena;
  if (s.threads > 0) arena = std::make_unique<tbb::task_arena>(s.threads);
  const auto run = [&](const auto& f) {
    if (arena) {
      arena->execute(f);
    } else {
      f();
    }
  };

  // Setup: the bands each triangle reaches, then the triangles of each band in order.
  run([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_tri, 4096), [&](const tbb::blocked_range<std::size_t>& range) {
      std::array<glm::dvec2, kMaxClipped> poly;
      for (std::size_t t = range.begin(); t != range.end(); ++t) {
        bool clipped = false;
        const int n = window_polygon(view, eye_triangle(view, colors.positions, &indices[3 * t]), poly, clipped);
        double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
        for (int i = 0; i < n; ++i) {
          x0 = std::min(x0, poly[static_cast<std::size_t>(i)].x);
          x1 = std::max(x1, poly[static_cast<std::size_t>(i)].x);
          y0 = std::min(y0, poly[static_cast<std::size_t>(i)].y);
          y1 = std::max(y1, poly[static_cast<std::size_t>(i)].y);
        }
        if (n == 0 || x1 < 0 || x0 > W || y1 < 0 || y0 > H || !(x0 <= x1) || !(y0 <= y1)) {
          m.band_first[t] = 1;
          m.band_last[t] = 0;
          continue;
        }
        m.band_first[t] = std::clamp(static_cast<int>(std::floor(y0)) / R, 0, bands - 1);
        m.band_last[t] = std::clamp(static_cast<int>(std::floor(y1)) / R, 0, bands - 1);
      }
    });
  });
  m.band_start.assign(static_cast<std::size_t>(bands) + 1, 0);
  for (std::size_t t = 0; t < n_tri; ++t)
    for (int b = m.band_first[t]; b <= m.band_last[t]; ++b) ++m.band_start[static_cast<std::size_t>(b) + 1];
  for (int b = 0; b < bands; ++b) m.band_start[static_cast<std::size_t>(b) + 1] += m.band_start[static_cast<std::size_t>(b)];
  m.band_items.resize(m.band_start.back());
  {
    std::vector<std::uint32_t> fill(m.band_start.begin(), m.band_start.end() - 1);
    for (std::size_t t = 0; t < n_tri; ++t)
      for (int b = m.band_first[t]; b <= m.band_last[t]; ++b) m.band_items[fill[static_cast<std::size_t>(b)]++] = static_cast<std::uint32_t>(t);
  }
  const double setup_ms = ms_since(t_start);
  const auto t_tile = Clock::now();

  const int N = aa * aa;
  const std::uint64_t full = rect_mask(0, aa, 0, aa);
  const int per_tile = 8 / aa;  // pixels per tile side
  const double inv_aa = 1.0 / aa;
  const glm::dvec3 haze_color = look.haze_color;
  const bool hazy = look.haze_distance > 0.0;

  // One band: its triangles tiled into its own pyramid, front to back, then the sky.
  const auto draw_band = [&](int band) {
    Impl::BandState& st = m.states.local();
    const int row0 = band * R, rows = std::min(R, H - row0);
    coverage::Pyramid& pyramid = st.pyramid(W * aa, rows * aa);
    st.classes.clear();
    for (int y = row0; y < row0 + rows; ++y) {
      const std::size_t p0 = static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      std::fill_n(m.acc.begin() + static_cast<std::ptrdiff_t>(3 * p0), 3 * W, 0.0f);
      std::fill_n(m.uniform_t.begin() + static_cast<std::ptrdiff_t>(p0), W, 1.0f);
      std::fill_n(m.head.begin() + static_cast<std::ptrdiff_t>(p0), W, -1);
      std::fill_n(m.counts.begin() + static_cast<std::ptrdiff_t>(p0), W, std::uint8_t{0});
    }
    // Adds colour c to pixel p for the samples of mask, weighted by their transmittance.
    const auto add = [&](std::size_t p, std::uint64_t mask, const glm::dvec3& c, double weight) {
      double w = 0;
      const std::int32_t h0 = m.head[p];
      if (h0 < 0) {
        w = popcount(mask) * static_cast<double>(m.uniform_t[p]);
      } else {
        for (std::int32_t k = h0; k >= 0; k = st.classes[static_cast<std::size_t>(k)].next) {
          const Class& cl = st.classes[static_cast<std::size_t>(k)];
          const std::uint64_t i = cl.mask & mask;
          if (i) w += popcount(i) * static_cast<double>(cl.t);
        }
      }
      w *= weight;
      float* a = &m.acc[3 * p];
      a[0] += static_cast<float>(c.r * w);
      a[1] += static_cast<float>(c.g * w);
      a[2] += static_cast<float>(c.b * w);
    };
    // A translucent fragment: colour c with opacity alpha over the samples of mask (all open),
    // the pixel's covered samples `covered`.
    const auto add_translucent = [&](std::size_t p, std::uint64_t mask, std::uint64_t covered, const glm::dvec3& c,
                                     double alpha) {
      add(p, mask, c, alpha);
      const auto keep = static_cast<float>(1.0 - alpha);
      std::int32_t& h0 = m.head[p];
      if (h0 < 0) {
        const std::uint64_t rest = full & ~mask & ~covered;
        if (!rest) {
          m.uniform_t[p] *= keep;
          return;
        }
        const float t = m.uniform_t[p];
        st.classes.push_back({rest, t, -1});
        st.classes.push_back({mask, t * keep, static_cast<std::int32_t>(st.classes.size()) - 1});
        h0 = static_cast<std::int32_t>(st.classes.size()) - 1;
        ++st.stats.class_splits;
        return;
      }
      for (std::int32_t k = h0; k >= 0;) {
        Class& cl = st.classes[static_cast<std::size_t>(k)];
        const std::int32_t next = cl.next;
        const std::uint64_t i = cl.mask & mask;
        if (i) {
          const std::uint64_t rest = cl.mask & ~mask & ~covered;
          if (!rest) {
            cl.mask = i;
            cl.t *= keep;
          } else {
            cl.mask = rest;
            const float t = cl.t * keep;
            st.classes.push_back({i, t, h0});  // at the head: not met again in this loop
            h0 = static_cast<std::int32_t>(st.classes.size()) - 1;
            ++st.stats.class_splits;
          }
        }
        k = next;
      }
      // Classes of equal transmittance join (the two triangles of a translucent quad split the
      // pixels on their shared edge, and the second one makes the halves equal again), classes
      // of covered samples go, and one class left is the uniform case again.
      const std::uint64_t open = full & ~covered;
      std::int32_t* link = &h0;
      while (*link >= 0) {
        Class& cl = st.classes[static_cast<std::size_t>(*link)];
        cl.mask &= open;
        if (!cl.mask) {
          *link = cl.next;
          continue;
        }
        for (std::int32_t* other = &cl.next; *other >= 0;) {
          Class& o = st.classes[static_cast<std::size_t>(*other)];
          if (o.t == cl.t) {
            cl.mask |= o.mask & open;
            *other = o.next;
          } else {
            other = &o.next;
          }
        }
        link = &cl.next;
      }
      // (mask is open and not empty, so some class is left.)
      if (st.classes[static_cast<std::size_t>(h0)].next < 0) {
        m.uniform_t[p] = st.classes[static_cast<std::size_t>(h0)].t;
        h0 = -1;
      }
    };

    const std::size_t begin = m.band_start[static_cast<std::size_t>(band)];
    const std::size_t end = m.band_start[static_cast<std::size_t>(band) + 1];
    std::array<glm::dvec2, kMaxClipped> poly;
    for (std::size_t item = begin; item < end; ++item) {
      const std::uint32_t t = m.band_items[item];
      const std::uint32_t* idx = &indices[3 * static_cast<std::size_t>(t)];
      const std::array<Eye, 3> tri = eye_triangle(view, colors.positions, idx);
      bool clipped = false;
      const int n = window_polygon(view, tri, poly, clipped);
      if (n == 0) continue;
      st.stats.clipped += clipped && band == m.band_first[t] ? 1 : 0;
      // Shading setup.
      Shade sh;
      const std::uint32_t v0 = idx[0];
      sh.kind = v0 < lattice ? Kind::kTextured : v0 < colors.merged_base ? Kind::kWall : Kind::kMerged;
      std::array<double, 3> haze{0, 0, 0};
      if (hazy) {
        for (int i = 0; i < 3; ++i) haze[static_cast<std::size_t>(i)] = 0.85 * (1.0 - std::exp(-tri[static_cast<std::size_t>(i)].z / look.haze_distance));
      }
      std::array<std::array<double, 5>, 3> attr{};  // per vertex
      int n_attr = 0;
      if (sh.kind == Kind::kTextured) {
        n_attr = 3;
        for (int i = 0; i < 3; ++i) {
          const std::uint32_t v = idx[i];
          const double ti = v < lattice ? static_cast<double>(v % side) : 0.0, tj = v < lattice ? static_cast<double>(v / side) : 0.0;
          attr[static_cast<std::size_t>(i)] = {ti, tj, haze[static_cast<std::size_t>(i)], 0, 0};
        }
      } else if (sh.kind == Kind::kWall) {
        n_attr = 1;
        for (int i = 0; i < 3; ++i) attr[static_cast<std::size_t>(i)][0] = haze[static_cast<std::size_t>(i)];
      } else {
        n_attr = 5;
        for (int i = 0; i < 3; ++i) {
          const std::uint32_t v = idx[i];
          const glm::u8vec4 c = v >= colors.merged_base ? colors.merged_colors[v - colors.merged_base] : colors.wall_color;
          attr[static_cast<std::size_t>(i)] = {static_cast<double>(c.r), static_cast<double>(c.g), static_cast<double>(c.b),
                                               static_cast<double>(c.a), haze[static_cast<std::size_t>(i)]};
          sh.translucent = sh.translucent || c.a < 255;
        }
      }
      for (int i = 0; i < 3; ++i) {
        const Eye& a = tri[static_cast<std::size_t>((i + 1) % 3)];
        const Eye& b = tri[static_cast<std::size_t>((i + 2) % 3)];
        // e_i = (a x b) . D, D = ((x - hw) / f, (y - hh) / f, 1).
        const double cx = a.y * b.z - a.z * b.y, cy = a.z * b.x - a.x * b.z, cz = a.x * b.y - a.y * b.x;
        const Plane e{cx / view.focal, cy / view.focal, cz - (cx * view.hw + cy * view.hh) / view.focal};
        sh.s.a += e.a;
        sh.s.b += e.b;
        sh.s.c += e.c;
        for (int k = 0; k < n_attr; ++k) {
          const double v = attr[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)];
          sh.n[static_cast<std::size_t>(k)].a += v * e.a;
          sh.n[static_cast<std::size_t>(k)].b += v * e.b;
          sh.n[static_cast<std::size_t>(k)].c += v * e.c;
        }
      }
      if (sh.kind == Kind::kTextured) {
        if (s.texel_rate == 0.0) {
          sh.kx = sh.ky = aa;
        } else {
          // The texels a pixel spans along x and y, at the polygon's centroid.
          glm::dvec2 c(0.0);
          for (int i = 0; i < n; ++i) c += poly[static_cast<std::size_t>(i)];
          c /= n;
          const double S = sh.s.at(c.x, c.y);
          if (S != 0.0 && std::isfinite(S)) {
            const Plane& pu = sh.n[0];
            const Plane& pv = sh.n[1];
            const double U = pu.at(c.x, c.y), V = pv.at(c.x, c.y), s2 = S * S;
            const double du_dx = (pu.a * S - U * sh.s.a) / s2, dv_dx = (pv.a * S - V * sh.s.a) / s2;
            const double du_dy = (pu.b * S - U * sh.s.b) / s2, dv_dy = (pv.b * S - V * sh.s.b) / s2;
            sh.kx = pow2_at_least(s.texel_rate * std::hypot(du_dx, dv_dx), aa);
            sh.ky = pow2_at_least(s.texel_rate * std::hypot(du_dy, dv_dy), aa);
          }
        }
      }
      st.stats.translucent += sh.translucent && band == m.band_first[t] ? 1 : 0;

      // Tiling: the band's pyramid is in samples, its row 0 the band's first.
      st.poly.resize(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i) {
        st.poly[static_cast<std::size_t>(i)] = {poly[static_cast<std::size_t>(i)].x * aa,
                                                (poly[static_cast<std::size_t>(i)].y - row0) * aa};
      }
      st.records.clear();
      if (sh.translucent) {
        pyramid.vacant(st.poly, 0.0, st.records);
      } else {
        pyramid.cover(st.poly, 0.0, st.records);
      }
      ++st.stats.tiled;

      // The colour (0..255) and opacity at window point (x, y).
      const auto shade_at = [&](double x, double y, double& alpha) {
        ++st.stats.shading_points;
        double S = sh.s.at(x, y);
        if (S == 0.0 || !std::isfinite(S)) S = std::numeric_limits<double>::min();
        const double inv = 1.0 / S;
        glm::dvec3 c;
        double h = 0;
        alpha = 1.0;
        switch (sh.kind) {
          case Kind::kTextured:
            c = texel(colors.texture, static_cast<int>(side), sh.n[0].at(x, y) * inv, sh.n[1].at(x, y) * inv);
            h = sh.n[2].at(x, y) * inv;
            break;
          case Kind::kWall:
            c = glm::dvec3(colors.wall_color.r, colors.wall_color.g, colors.wall_color.b);
            h = sh.n[0].at(x, y) * inv;
            break;
          case Kind::kMerged:
            c = glm::dvec3(sh.n[0].at(x, y), sh.n[1].at(x, y), sh.n[2].at(x, y)) * inv;
            alpha = std::clamp(sh.n[3].at(x, y) * inv / 255.0, 0.0, 1.0);
            h = sh.n[4].at(x, y) * inv;
            break;
        }
        if (hazy) c = c + (haze_color - c) * h;
        return c;
      };

      for (const coverage::TileMask& rec : st.records) {
        for (int j = 0; j < per_tile; ++j) {
          for (int i = 0; i < per_tile; ++i) {
            const std::uint64_t sub = (rec.mask >> (8 * j * aa + i * aa)) & full;
            if (!sub) continue;
            const int px = rec.tx * per_tile + i, py = row0 + rec.ty * per_tile + j;
            const std::size_t p = static_cast<std::size_t>(py) * static_cast<std::size_t>(W) + static_cast<std::size_t>(px);
            ++st.stats.fragments;
            const int count = popcount(sub);
            if (sh.translucent) {
              const std::uint64_t covered = (pyramid.tile_bits(rec.tx, rec.ty) >> (8 * j * aa + i * aa)) & full;
              const glm::dvec2 q = centroid(sub, count);
              double alpha = 1;
              const glm::dvec3 c = shade_at(px + q.x * inv_aa, py + q.y * inv_aa, alpha);
              add_translucent(p, sub, covered, c, alpha);
              continue;
            }
            st.stats.samples_covered += static_cast<std::uint64_t>(count);
            m.counts[p] = static_cast<std::uint8_t>(m.counts[p] + count);
            if (sh.kx == 1 && sh.ky == 1) {
              const glm::dvec2 q = centroid(sub, count);
              double alpha = 1;
              add(p, sub, shade_at(px + q.x * inv_aa, py + q.y * inv_aa, alpha), 1.0);
              continue;
            }
            const int bw = aa / sh.kx, bh = aa / sh.ky;
            for (int by = 0; by < sh.ky; ++by) {
              for (int bx = 0; bx < sh.kx; ++bx) {
                const std::uint64_t part = sub & rect_mask(bx * bw, bw, by * bh, bh);
                if (!part) continue;
                const glm::dvec2 q = centroid(part, popcount(part));
                double alpha = 1;
                add(p, part, shade_at(px + q.x * inv_aa, py + q.y * inv_aa, alpha), 1.0);
              }
            }
          }
        }
      }
    }

    // The sky over every sample still vacant (section 4.5: "composite a screen-sized polygon of
    // the desired background color"), then the pixels of the band.
    const int tiles_x = pyramid.grid_width(0), tiles_y = pyramid.grid_height(0);
    const glm::dvec3 bottom = look.sky_bottom, top = look.sky_top;
    for (int ty = 0; ty < tiles_y; ++ty) {
      for (int tx = 0; tx < tiles_x; ++tx) {
        const std::uint64_t open = ~pyramid.tile_bits(tx, ty);
        if (!open) continue;
        for (int j = 0; j < per_tile; ++j) {
          for (int i = 0; i < per_tile; ++i) {
            const std::uint64_t sub = (open >> (8 * j * aa + i * aa)) & full;
            if (!sub) continue;
            const int px = tx * per_tile + i, py = row0 + ty * per_tile + j;
            const std::size_t p = static_cast<std::size_t>(py) * static_cast<std::size_t>(W) + static_cast<std::size_t>(px);
            const int count = popcount(sub);
            const glm::dvec2 q = centroid(sub, count);
            const double y = (py + q.y * inv_aa) / H;
            add(p, sub, bottom + (top - bottom) * y, 1.0);
            st.stats.samples_background += static_cast<std::uint64_t>(count);
            m.counts[p] = static_cast<std::uint8_t>(m.counts[p] + count);
          }
        }
      }
    }
    const float scale = 1.0f / static_cast<float>(N);
    for (int y = row0; y < row0 + rows; ++y) {
      const std::size_t src = static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      const std::size_t dst = static_cast<std::size_t>(H - 1 - y) * static_cast<std::size_t>(W);
      for (int x = 0; x < W; ++x) {
        for (int k = 0; k < 3; ++k) {
          const float v = m.acc[3 * (src + static_cast<std::size_t>(x)) + static_cast<std::size_t>(k)] * scale;
          rgb_[3 * (dst + static_cast<std::size_t>(x)) + static_cast<std::size_t>(k)] =
              static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
        }
        counts_[dst + static_cast<std::size_t>(x)] = m.counts[src + static_cast<std::size_t>(x)];
      }
    }
    st.stats.cells_visited += pyramid.stats().cells_visited;
  };

  run([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& r) {
      for (int b = r.begin(); b != r.end(); ++b) draw_band(b);
    });
  });

  Stats out;
  out.triangles = n_tri;
  for (const Impl::BandState& st : m.states) {
    out.translucent += st.stats.translucent;
    out.clipped += st.stats.clipped;
    out.tiled += st.stats.tiled;
    out.fragments += st.stats.fragments;
    out.shading_points += st.stats.shading_points;
    out.samples_covered += st.stats.samples_covered;
    out.samples_background += st.stats.samples_background;
    out.cells_visited += st.stats.cells_visited;
    out.class_splits += st.stats.class_splits;
  }
  out.setup_ms = setup_ms;
  out.tile_ms = ms_since(t_tile);
  out.total_ms = ms_since(t_start);
  return out;
}

}  // namespace terravol::tiler
