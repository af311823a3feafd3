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
//    samples) come back from the pyramid tile by tile, whole cells as runs of tiles
//    (Pyramid::cover with a report), and the
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
//    resolution (app/render/tiled_renderer.h) so that it culls only nodes whose every sample is
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
#include <cstring>
#include <ctime>
#include <limits>
#include <stdexcept>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <glm/geometric.hpp>

#include "coverage/pyramid.h"

namespace terravol::tiler {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// CPU time of the calling thread, milliseconds.
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

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
constexpr std::uint64_t rect_mask(int x0, int w, int y0, int h) {
  const std::uint64_t cols = ((std::uint64_t{1} << w) - 1) << x0;
  std::uint64_t m = 0;
  for (int r = y0; r < y0 + h; ++r) m |= cols << (8 * r);
  return m;
}

// A non-empty mask's samples: how many, and their centroid in samples from the pixel's low
// corner (sample centres at +0.5). Row by row from a table of each byte's count and sum of x
// (8 lookups, inlined): the build targets baseline x86-64, without the popcnt instruction, and a
// call to a popcnt version chosen at run time cost more than the counts (its return went
// through the stack). The centroid comes first: with the count first, copies of the struct read
// the count and centroid.x as one 8-byte word written as two, a store-forwarding stall that perf
// put at a tenth of the band loop.
struct Samples {
  glm::vec2 centroid;
  int count;
};
struct SampleTables {
  std::array<std::uint16_t, 256> row{};  // count in the low byte, the sum of x in the high one
  std::array<float, 65> inverse{};       // 1 / count
  constexpr SampleTables() {
    for (int b = 0; b < 256; ++b) {
      int count = 0, sum = 0;
      for (int x = 0; x < 8; ++x)
        if (b & (1 << x)) {
          ++count;
          sum += x;
        }
      row[static_cast<std::size_t>(b)] = static_cast<std::uint16_t>(count | (sum << 8));
    }
    for (int c = 1; c <= 64; ++c) inverse[static_cast<std::size_t>(c)] = 1.0f / static_cast<float>(c);
  }
};
constexpr SampleTables kSampleTables;
inline Samples samples(std::uint64_t m) {
  unsigned both = 0, sy = 0;
  for (unsigned j = 0; j < 8; ++j) {
    const unsigned v = kSampleTables.row[static_cast<std::size_t>((m >> (8 * j)) & 0xFFu)];
    both += v;
    sy += j * (v & 0xFFu);
  }
  const unsigned count = both & 0xFFu, sx = both >> 8;
  const float inv = kSampleTables.inverse[count];
  return {{static_cast<float>(sx) * inv + 0.5f, static_cast<float>(sy) * inv + 0.5f}, static_cast<int>(count)};
}

int pow2_at_least(double v, int cap) {
  int k = 1;
  while (k < cap && k < v) k *= 2;
  return k;
}

// Eye space: x right, y up, z the depth along the view axis (GL's clip w).
struct Eye {
  double x, y, z;
};

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
    for (std::size_t i = 0; i < 3; ++i) out[i] = v.window(tri[i]);
    return 3;
  }
  // Sutherland-Hodgman in eye space, plane by plane.
  std::array<Eye, kMaxClipped> a{}, b{};
  int n = 3;
  std::copy(tri.begin(), tri.end(), a.begin());
  for (int k = 0; k < 6; ++k) {
    if (!(outside_any & (1 << k))) continue;
    std::size_t m = 0;
    for (int i = 0; i < n; ++i) {
      const Eye& p = a[static_cast<std::size_t>(i)];
      const Eye& q = a[static_cast<std::size_t>((i + 1) % n)];
      const double dp = v.plane(k, p), dq = v.plane(k, q);
      if (dp >= 0) b[m++] = p;
      if ((dp >= 0) != (dq >= 0)) {
        // From the inside end, so that both triangles of a shared edge get the same point.
        const Eye& in = dp >= 0 ? p : q;
        const Eye& out_end = dp >= 0 ? q : p;
        const double d_in = dp >= 0 ? dp : dq, d_out = dp >= 0 ? dq : dp;
        const double t = d_in / (d_in - d_out);
        b[m++] = {in.x + (out_end.x - in.x) * t, in.y + (out_end.y - in.y) * t, in.z + (out_end.z - in.z) * t};
      }
    }
    n = static_cast<int>(m);
    if (n < 3) return 0;
    std::swap(a, b);
  }
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) out[i] = v.window(a[i]);
  return n;
}

std::array<Eye, 3> eye_triangle(const View& v, std::span<const glm::vec3> positions, const std::uint32_t* idx) {
  return {v.to_eye(positions[idx[0]]), v.to_eye(positions[idx[1]]), v.to_eye(positions[idx[2]])};
}

enum class Kind : std::uint8_t { kTextured, kWall, kMerged };

// A colour, 0..255 per channel (r, g, b; the fourth lane unused): one SSE2 register where there
// is SSE2 (every x86-64), four floats otherwise.
#if defined(__SSE2__)
struct Color {
  __m128 v;
  Color() : v(_mm_setzero_ps()) {}
  explicit Color(__m128 x) : v(x) {}
  Color(float r, float g, float b) : v(_mm_set_ps(0.0f, b, g, r)) {}
  friend Color operator+(Color a, Color b) { return Color(_mm_add_ps(a.v, b.v)); }
  friend Color operator-(Color a, Color b) { return Color(_mm_sub_ps(a.v, b.v)); }
  friend Color operator*(Color a, float s) { return Color(_mm_mul_ps(a.v, _mm_set1_ps(s))); }
  Color& operator+=(Color b) { return *this = *this + b; }
  // (0, 0, 0, x): the fourth lane is free for a count (Pixel).
  static Color fourth(float x) { return Color(_mm_set_ps(x, 0.0f, 0.0f, 0.0f)); }
  float get_fourth() const { return _mm_cvtss_f32(_mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 3, 3, 3))); }
  // r, g, b rounded half up and clamped to 0..255, as three bytes at out.
  void store_rgb(std::uint8_t* out) const {
    const __m128 r = _mm_min_ps(_mm_max_ps(_mm_add_ps(v, _mm_set1_ps(0.5f)), _mm_setzero_ps()), _mm_set1_ps(255.0f));
    const __m128i w = _mm_cvttps_epi32(r);
    const std::int32_t word = _mm_cvtsi128_si32(_mm_packus_epi16(_mm_packs_epi32(w, w), w));
    std::memcpy(out, &word, 3);  // little-endian: r, g, b first
  }
};
#else
struct Color {
  std::array<float, 4> c{0, 0, 0, 0};
  Color() = default;
  Color(float r, float g, float b) : c{r, g, b, 0.0f} {}
  friend Color operator+(Color a, Color b) {
    for (std::size_t k = 0; k < 4; ++k) a.c[k] += b.c[k];
    return a;
  }
  friend Color operator-(Color a, Color b) {
    for (std::size_t k = 0; k < 4; ++k) a.c[k] -= b.c[k];
    return a;
  }
  friend Color operator*(Color a, float s) {
    for (float& x : a.c) x *= s;
    return a;
  }
  Color& operator+=(Color b) { return *this = *this + b; }
  static Color fourth(float x) {
    Color c;
    c.c[3] = x;
    return c;
  }
  float get_fourth() const { return c[3]; }
  void store_rgb(std::uint8_t* out) const {
    for (std::size_t k = 0; k < 3; ++k) out[k] = static_cast<std::uint8_t>(std::clamp(c[k] + 0.5f, 0.0f, 255.0f));
  }
};
#endif

// An affine function of window position, about the triangle's centre: at + a dx + b dy
// (evaluated by eval(), four points at once).
struct Plane {
  float a = 0, b = 0, at = 0;
};

// What a triangle is shaded with. Attributes are interpolated perspective-correctly by the
// homogeneous barycentrics of the pixel ray (Olano and Greer 1997): with the vertices' eye
// positions V0, V1, V2 and the ray direction D(x, y) = ((x - w/2) / f, (y - h/2) / f, 1), the
// barycentrics are e_i / (e_0 + e_1 + e_2) for e_i = (V_j x V_k) . D, affine in (x, y); an
// attribute is then (sum A_i e_i) / (sum e_i), the quotient of two planes: no clipping and no
// determinant needed. The planes are set up in double precision about the triangle's centre
// (x0, y0), scaled so that the denominator is 1 there, and evaluated in float.
struct Shade {
  Kind kind = Kind::kTextured;
  bool translucent = false;
  int kx = 1, ky = 1;        // shading blocks per pixel along x and y (textured)
  float x0 = 0, y0 = 0;
  Plane s;                   // sum e_i
  std::array<Plane, 5> n;    // textured: u, v (texels), haze; wall: haze; merged: r, g, b, a (0..255), haze
};

// Four floats or ints, one per shading point, in GCC's vector extension: one SSE2 register each
// on x86-64, plain arithmetic elsewhere. The shader runs on four points of one triangle at once
// (the same operations in the same order as one point at a time, so the images are the same
// bytes); hand-written because VTK and the libraries here shade on the GPU, not per fragment in
// software.
using F4 = float __attribute__((vector_size(16)));
using I4 = std::int32_t __attribute__((vector_size(16)));

F4 eval(const Plane& p, F4 dx, F4 dy) { return p.at + p.a * dx + p.b * dy; }

// The colour (0..255) and opacity of a triangle at four window points (x[k], y[k]).
struct Shaded4 {
  std::array<Color, 4> color;
  std::array<float, 4> alpha;
};

// The lattice texture: bilinear between texel centres (whole texel coordinates), clamped to the
// edge (GL's LINEAR filter with CLAMP_TO_EDGE).
struct Texture {
  const std::uint8_t* rgba = nullptr;
  int side = 0;
  // Channels r, g, b at the four points (u[k], v[k]).
  void at(F4 u, F4 v, F4& r, F4& g, F4& b) const {
    const float hi = static_cast<float>(side - 1), lim = static_cast<float>(std::max(side - 2, 0));
    u = u > 0.0f ? u : 0.0f;  // (NaN goes to 0)
    v = v > 0.0f ? v : 0.0f;
    u = u < hi ? u : hi;
    v = v < hi ? v : hi;
    F4 i0 = __builtin_convertvector(__builtin_convertvector(u, I4), F4);  // floor: u >= 0
    F4 j0 = __builtin_convertvector(__builtin_convertvector(v, I4), F4);
    i0 = i0 < lim ? i0 : lim;
    j0 = j0 < lim ? j0 : lim;
    const F4 fu = u - i0, fv = v - j0;
    const I4 i = __builtin_convertvector(i0, I4), j = __builtin_convertvector(j0, I4);
    const std::size_t step = side > 1 ? 4 : 0, row = step * static_cast<std::size_t>(side);
    I4 w00, w10, w01, w11;
    for (int k = 0; k < 4; ++k) {
      const std::uint8_t* p = rgba + 4 * (static_cast<std::size_t>(j[k]) * static_cast<std::size_t>(side) + static_cast<std::size_t>(i[k]));
      std::int32_t w[4];
      std::memcpy(&w[0], p, 4);
      std::memcpy(&w[1], p + step, 4);
      std::memcpy(&w[2], p + row, 4);
      std::memcpy(&w[3], p + row + step, 4);
      w00[k] = w[0];
      w10[k] = w[1];
      w01[k] = w[2];
      w11[k] = w[3];
    }
    const auto channel = [&](int shift) {
      const auto c = [&](I4 w) { return __builtin_convertvector((w >> shift) & 0xFF, F4); };  // little-endian
      const F4 c00 = c(w00), c10 = c(w10), c01 = c(w01), c11 = c(w11);
      const F4 bottom = c00 + (c10 - c00) * fu, top = c01 + (c11 - c01) * fu;
      return bottom + (top - bottom) * fv;
    };
    r = channel(0);
    g = channel(8);
    b = channel(16);
  }
};

// What every triangle is shaded with: the lattice texture, the walls' colour, the haze; a call
// shades four points of one triangle.
struct Shader {
  Texture texture;
  std::array<float, 3> wall_rgb{};
  std::array<float, 3> haze{};
  bool hazy = false;
  Shaded4 operator()(const Shade& sh, const float* x, const float* y) const {
    const F4 dx = F4{x[0], x[1], x[2], x[3]} - sh.x0, dy = F4{y[0], y[1], y[2], y[3]} - sh.y0;
    F4 S = eval(sh.s, dx, dy);
    const F4 mag = S < 0.0f ? -S : S;
    S = (S == 0.0f) | ~(mag < std::numeric_limits<float>::infinity()) ? F4{1.0f, 1.0f, 1.0f, 1.0f} : S;  // edge-on: any point of it
    const F4 inv = 1.0f / S;
    F4 r{}, g{}, b{}, h{}, alpha = {1.0f, 1.0f, 1.0f, 1.0f};
    switch (sh.kind) {
      case Kind::kTextured:
        texture.at(eval(sh.n[0], dx, dy) * inv, eval(sh.n[1], dx, dy) * inv, r, g, b);
        h = eval(sh.n[2], dx, dy) * inv;
        break;
      case Kind::kWall:
        r = F4{} + wall_rgb[0];
        g = F4{} + wall_rgb[1];
        b = F4{} + wall_rgb[2];
        h = eval(sh.n[0], dx, dy) * inv;
        break;
      case Kind::kMerged:
        r = eval(sh.n[0], dx, dy) * inv;
        g = eval(sh.n[1], dx, dy) * inv;
        b = eval(sh.n[2], dx, dy) * inv;
        alpha = eval(sh.n[3], dx, dy) * inv * (1.0f / 255.0f);
        alpha = alpha > 0.0f ? alpha : 0.0f;
        alpha = alpha < 1.0f ? alpha : 1.0f;
        h = eval(sh.n[4], dx, dy) * inv;
        break;
    }
    if (hazy) {
      r += (haze[0] - r) * h;
      g += (haze[1] - g) * h;
      b += (haze[2] - b) * h;
    }
    Shaded4 out;
    for (int k = 0; k < 4; ++k) {
      out.color[static_cast<std::size_t>(k)] = Color(r[k], g[k], b[k]);
      out.alpha[static_cast<std::size_t>(k)] = alpha[k];
    }
    return out;
  }
};

struct Class {
  std::uint64_t mask;  // open samples with this transmittance
  float t;
  std::int32_t next;
};

// What a pixel accumulates, in one 16-byte record: the colour summed over its samples (0..255
// each) in r, g, b, and the samples shaded in the fourth lane (whole numbers, exact in a float).
// Half the 32 bytes that held the transmittance too: the records are the tiler's largest
// working set, a band's worth per thread.
struct Pixel {
  Color acc;
};

// The transmittance of a pixel's open samples when it is uniform, else the head of its
// transmittance classes (-1: uniform). Kept once a band has met a translucent triangle: before
// that (front to back) every pixel's is 1, uniform.
struct Transmittance {
  float t = 1.0f;
  std::int32_t head = -1;
};

}  // namespace

struct Renderer::Impl {
  // Shading points of one triangle waiting to be shaded four at a time: pixel p's samples mask
  // (count of them; covered: the pixel's covered samples, for translucent triangles) at window
  // point (x, y).
  struct Point {
    std::size_t p;
    std::uint64_t mask, covered;
    int count;
  };
  struct Queue {
    std::array<Point, 4> points;
    alignas(16) float x[4];
    alignas(16) float y[4];
    int n = 0;
  };
  // Per band and thread: the band's pyramid (one per band height: the last band may be
  // shorter), the pyramid's reports, transmittance classes, polygon scratch, counters.
  struct BandState {
    std::vector<std::unique_ptr<coverage::Pyramid>> pyramids;
    std::vector<coverage::TileMask> records;
    std::vector<Class> classes;
    std::vector<Pixel> pixels;  // the band's, rows from its first (bottom) one
    bool pixels_dirty = false;  // pixels not all zero: a band was left unfinished
    std::vector<Transmittance> transmittance;  // the band's pixels', once it has met translucency
    std::vector<glm::dvec2> poly;
    Queue queue;
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
};

namespace {

// Transmittance classes closer than this join, at their samples' mean (which keeps the sum of
// the pixel's transmittances, so a later fragment over all of their samples is weighted
// exactly; one over some of them is off by less than this). A density's colour-box faces split
// a pixel at every face edge into classes that equal transmittances alone never joined: at 8 x 8
// samples the bench's 6 km density (2.5 million face triangles at 480x270) made 14 million
// splits and took 17-27 s to tile, 1.8 s with this join, no pixel more than 1/255 away.
constexpr float kJoinTolerance = 1.0f / 256.0f;

// A band's pixels being accumulated: the colour sums, transmittance and sample counts of the
// pixels of one band (rows from the bottom), and its transmittance classes.
struct Accumulator {
  Pixel* px;
  std::size_t n_pixels;
  std::vector<Transmittance>& tr;  // empty until the band's first translucent fragment
  std::vector<Class>& classes;
  Stats& stats;
  std::uint64_t full;  // a pixel's samples

  // Counts count samples shaded in pixel p.
  void shaded(std::size_t p, int count) { px[p].acc += Color::fourth(static_cast<float>(count)); }

  // Adds colour c times weight to pixel p for the samples of mask (all open), each weighted by
  // its transmittance.
  void add(std::size_t p, std::uint64_t mask, int count, Color c, float weight) {
    float w = 0;
    const std::int32_t h0 = tr.empty() ? -1 : tr[p].head;
    if (tr.empty()) {
      w = static_cast<float>(count);
    } else if (h0 < 0) {
      w = static_cast<float>(count) * tr[p].t;
    } else {
      for (std::int32_t k = h0; k >= 0; k = classes[static_cast<std::size_t>(k)].next) {
        const Class& cl = classes[static_cast<std::size_t>(k)];
        const std::uint64_t i = cl.mask & mask;
        if (i) w += static_cast<float>(popcount(i)) * cl.t;
      }
    }
    px[p].acc += c * (w * weight);
  }

  // A translucent fragment: colour c with opacity alpha over the samples of mask (all open);
  // the pixel's covered samples are `covered`.
  void translucent(std::size_t p, std::uint64_t mask, int count, std::uint64_t covered, Color c, float alpha) {
    add(p, mask, count, c, alpha);
    if (tr.empty()) tr.assign(n_pixels, Transmittance());
    const float keep = 1.0f - alpha;
    std::int32_t& h0 = tr[p].head;
    if (h0 < 0) {
      const std::uint64_t rest = full & ~mask & ~covered;
      if (!rest) {
        tr[p].t *= keep;
        return;
      }
      const float t = tr[p].t;
      classes.push_back({rest, t, -1});
      classes.push_back({mask, t * keep, static_cast<std::int32_t>(classes.size()) - 1});
      h0 = static_cast<std::int32_t>(classes.size()) - 1;
      ++stats.class_splits;
      return;
    }
    for (std::int32_t k = h0; k >= 0;) {
      Class& cl = classes[static_cast<std::size_t>(k)];
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
          classes.push_back({i, t, h0});  // at the head: not met again in this loop
          h0 = static_cast<std::int32_t>(classes.size()) - 1;
          ++stats.class_splits;
        }
      }
      k = next;
    }
    // Classes of equal or near transmittance join (the two triangles of a translucent quad split
    // the pixels on their shared edge, and the second one makes the halves equal again), classes
    // of covered samples go, and one class left is the uniform case again.
    const std::uint64_t open = full & ~covered;
    std::int32_t* link = &h0;
    while (*link >= 0) {
      Class& cl = classes[static_cast<std::size_t>(*link)];
      cl.mask &= open;
      if (!cl.mask) {
        *link = cl.next;
        continue;
      }
      for (std::int32_t* other = &cl.next; *other >= 0;) {
        Class& o = classes[static_cast<std::size_t>(*other)];
        if (std::abs(o.t - cl.t) <= kJoinTolerance) {
          const std::uint64_t joined = o.mask & open;
          if (joined && o.t != cl.t) {
            const auto a = static_cast<float>(popcount(cl.mask)), b = static_cast<float>(popcount(joined));
            cl.t = (cl.t * a + o.t * b) / (a + b);
          }
          cl.mask |= joined;
          *other = o.next;
        } else {
          other = &o.next;
        }
      }
      link = &cl.next;
    }
    // (mask is open and not empty, so some class is left.)
    if (classes[static_cast<std::size_t>(h0)].next < 0) {
      tr[p].t = classes[static_cast<std::size_t>(h0)].t;
      h0 = -1;
    }
  }
};

}  // namespace

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
}

Renderer::~Renderer() = default;

namespace {

// The shading of triangle idx (its eye-space vertices tri, its clipped window polygon poly).
Shade setup_shade(const View& view, const SceneColors& colors, const Look& look, double texel_rate, int aa,
                  const std::uint32_t* idx, const std::array<Eye, 3>& tri, const std::array<glm::dvec2, kMaxClipped>& poly,
                  int n) {
  const std::size_t side = static_cast<std::size_t>(colors.lattice_side), lattice = side * side;
  Shade sh;
  const std::uint32_t v0 = idx[0];
  sh.kind = v0 < lattice ? Kind::kTextured : v0 < colors.merged_base ? Kind::kWall : Kind::kMerged;
  std::array<double, 3> haze{0, 0, 0};
  if (look.haze_distance > 0.0) {
    for (std::size_t i = 0; i < 3; ++i) haze[i] = 0.85 * (1.0 - std::exp(-tri[i].z / look.haze_distance));
  }
  std::array<std::array<double, 5>, 3> attr{};  // per vertex
  std::size_t n_attr = 0;
  if (sh.kind == Kind::kTextured) {
    n_attr = 3;
    for (std::size_t i = 0; i < 3; ++i) {
      const std::uint32_t v = idx[i];
      const bool on = v < lattice;  // (a textured triangle has lattice vertices only)
      attr[i] = {on ? static_cast<double>(v % side) : 0.0, on ? static_cast<double>(v / side) : 0.0, haze[i], 0, 0};
    }
  } else if (sh.kind == Kind::kWall) {
    n_attr = 1;
    for (std::size_t i = 0; i < 3; ++i) attr[i][0] = haze[i];
  } else {
    n_attr = 5;
    for (std::size_t i = 0; i < 3; ++i) {
      const std::uint32_t v = idx[i];
      const glm::u8vec4 c = v >= colors.merged_base ? colors.merged_colors[v - colors.merged_base] : colors.wall_color;
      attr[i] = {static_cast<double>(c.r), static_cast<double>(c.g), static_cast<double>(c.b), static_cast<double>(c.a), haze[i]};
      sh.translucent = sh.translucent || c.a < 255;
    }
  }
  // The centre: the polygon's vertex mean.
  glm::dvec2 centre(0.0);
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) centre += poly[i];
  centre /= static_cast<double>(n);
  // e_i = (V_j x V_k) . D, D = ((x - hw) / f, (y - hh) / f, 1): gradient and value at the centre.
  struct Affine {
    double a = 0, b = 0, at = 0;
  };
  Affine s;
  std::array<Affine, 5> num;
  const double dx = (centre.x - view.hw) / view.focal, dy = (centre.y - view.hh) / view.focal;
  for (std::size_t i = 0; i < 3; ++i) {
    const Eye& a = tri[(i + 1) % 3];
    const Eye& b = tri[(i + 2) % 3];
    const double cx = a.y * b.z - a.z * b.y, cy = a.z * b.x - a.x * b.z, cz = a.x * b.y - a.y * b.x;
    const Affine e{cx / view.focal, cy / view.focal, cx * dx + cy * dy + cz};
    s.a += e.a;
    s.b += e.b;
    s.at += e.at;
    for (std::size_t k = 0; k < n_attr; ++k) {
      num[k].a += attr[i][k] * e.a;
      num[k].b += attr[i][k] * e.b;
      num[k].at += attr[i][k] * e.at;
    }
  }
  const double scale = s.at != 0.0 && std::isfinite(s.at) ? 1.0 / s.at : 1.0;
  sh.x0 = static_cast<float>(centre.x);
  sh.y0 = static_cast<float>(centre.y);
  sh.s = {static_cast<float>(s.a * scale), static_cast<float>(s.b * scale), static_cast<float>(s.at * scale)};
  for (std::size_t k = 0; k < n_attr; ++k) {
    sh.n[k] = {static_cast<float>(num[k].a * scale), static_cast<float>(num[k].b * scale), static_cast<float>(num[k].at * scale)};
  }
  if (sh.kind == Kind::kTextured) {
    if (texel_rate == 0.0) {
      sh.kx = sh.ky = aa;
    } else {
      // The texels a pixel spans along x and y at the centre (the denominator is 1 there).
      const double U = num[0].at * scale, V = num[1].at * scale;
      const double sa = s.a * scale, sb = s.b * scale;
      const double du_dx = num[0].a * scale - U * sa, dv_dx = num[1].a * scale - V * sa;
      const double du_dy = num[0].b * scale - U * sb, dv_dy = num[1].b * scale - V * sb;
      sh.kx = pow2_at_least(texel_rate * std::hypot(du_dx, dv_dx), aa);
      sh.ky = pow2_at_least(texel_rate * std::hypot(du_dy, dv_dy), aa);
    }
  }
  return sh;
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
        for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
          x0 = std::min(x0, poly[i].x);
          x1 = std::max(x1, poly[i].x);
          y0 = std::min(y0, poly[i].y);
          y1 = std::max(y1, poly[i].y);
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
  for (std::size_t b = 0; b < static_cast<std::size_t>(bands); ++b) m.band_start[b + 1] += m.band_start[b];
  m.band_items.resize(m.band_start.back());
  {
    std::vector<std::uint32_t> next(m.band_start.begin(), m.band_start.end() - 1);
    for (std::size_t t = 0; t < n_tri; ++t)
      for (int b = m.band_first[t]; b <= m.band_last[t]; ++b) m.band_items[next[static_cast<std::size_t>(b)]++] = static_cast<std::uint32_t>(t);
  }
  const double setup_ms = ms_since(t_start);
  const auto t_tile = Clock::now();

  const int N = aa * aa;
  const std::uint64_t full = rect_mask(0, aa, 0, aa);
  const int per_tile = 8 / aa;  // pixels per tile side
  const float inv_aa = 1.0f / static_cast<float>(aa);
  const glm::vec2 centre(0.5f * static_cast<float>(aa));  // of a pixel's samples, from its low corner
  // A pixel's samples `sub` (not empty): a whole pixel's without counting.
  const auto pixel_samples = [&](std::uint64_t sub) {
    return sub == full ? Samples{centre, N} : samples(sub);
  };
  Shader shader;
  shader.texture = {colors.texture.data(), static_cast<int>(side)};
  shader.wall_rgb = {static_cast<float>(colors.wall_color.r), static_cast<float>(colors.wall_color.g), static_cast<float>(colors.wall_color.b)};
  shader.haze = {static_cast<float>(look.haze_color.r), static_cast<float>(look.haze_color.g), static_cast<float>(look.haze_color.b)};
  shader.hazy = look.haze_distance > 0.0;

  // One band: its triangles tiled into its own pyramid, front to back, then the sky.
  const auto draw_band = [&](int band) {
    Impl::BandState& st = m.states.local();
    const double cpu0 = thread_cpu_ms();
    const int row0 = band * R, rows = std::min(R, H - row0);
    coverage::Pyramid& pyramid = st.pyramid(W * aa, rows * aa);
    st.classes.clear();
    const std::size_t count = static_cast<std::size_t>(rows) * static_cast<std::size_t>(W);
    // The records are zero between bands: the last pass below clears each as it reads it, while
    // it is in the cache, instead of a pass of its own here (unless a band was left unfinished).
    if (st.pixels_dirty) {
      st.pixels.assign(count, Pixel());
    } else if (st.pixels.size() < count) {
      st.pixels.resize(count);
    }
    st.pixels_dirty = true;
    st.transmittance.clear();
    // Pixel p of the band: (x, y) with y counted from the band's first row.
    Accumulator out{st.pixels.data(), count, st.transmittance, st.classes, st.stats, full};

    std::array<glm::dvec2, kMaxClipped> poly;
    for (std::size_t item = m.band_start[static_cast<std::size_t>(band)]; item < m.band_start[static_cast<std::size_t>(band) + 1]; ++item) {
      const std::uint32_t t = m.band_items[item];
      const std::uint32_t* idx = &indices[3 * static_cast<std::size_t>(t)];
      const std::array<Eye, 3> tri = eye_triangle(view, colors.positions, idx);
      bool clipped = false;
      const int n = window_polygon(view, tri, poly, clipped);
      if (n == 0) continue;
      const bool first_band = band == m.band_first[t];
      st.stats.clipped += clipped && first_band ? 1 : 0;
      const Shade sh = setup_shade(view, colors, look, s.texel_rate, aa, idx, tri, poly, n);
      st.stats.translucent += sh.translucent && first_band ? 1 : 0;

      // Tiling: the band's pyramid is in samples, its row 0 the band's first.
      st.poly.resize(static_cast<std::size_t>(n));
      for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) st.poly[i] = {poly[i].x * aa, (poly[i].y - row0) * aa};
      st.records.clear();
      if (sh.translucent) {
        pyramid.vacant(st.poly, 0.0, st.records);
      } else {
        pyramid.cover(st.poly, 0.0, st.records);
      }
      ++st.stats.tiled;

      // The fragments: per pixel of each reported tile, its newly covered (or shown) samples,
      // shaded in fours (st.queue), each point added to its pixel in the order it came.
      const bool blocks = sh.kx > 1 || sh.ky > 1;
      const float y_base = static_cast<float>(row0);
      Impl::Queue& queue = st.queue;
      const auto flush = [&] {
        for (int k = queue.n; k < 4; ++k) {  // (the lanes left over shade the first point again)
          queue.x[k] = queue.x[0];
          queue.y[k] = queue.y[0];
        }
        const Shaded4 shaded = shader(sh, queue.x, queue.y);
        for (std::size_t k = 0; k < static_cast<std::size_t>(queue.n); ++k) {
          const Impl::Point& q = queue.points[k];
          if (sh.translucent) {
            out.translucent(q.p, q.mask, q.count, q.covered, shaded.color[k], shaded.alpha[k]);
          } else {
            out.add(q.p, q.mask, q.count, shaded.color[k], 1.0f);
          }
        }
        queue.n = 0;
      };
      // A shading point: samples mask (count of them) of pixel p, shaded at window point (x, y).
      const auto shade = [&](std::size_t p, std::uint64_t mask, int samples_in, float x, float y, std::uint64_t covered) {
        ++st.stats.shading_points;
        queue.points[static_cast<std::size_t>(queue.n)] = {p, mask, covered, samples_in};
        queue.x[queue.n] = x;
        queue.y[queue.n] = y;
        if (++queue.n == 4) flush();
      };
      // Pixel (px, py) of the band, its samples sub (count c, centroid q in samples), the pixel's
      // covered samples (translucent triangles only).
      const auto fragment = [&](int px, int py, std::uint64_t sub, int c, glm::vec2 q, std::uint64_t covered) {
        const std::size_t p = static_cast<std::size_t>(py) * static_cast<std::size_t>(W) + static_cast<std::size_t>(px);
        ++st.stats.fragments;
        if (!sh.translucent) {
          out.shaded(p, c);
          st.stats.samples_covered += static_cast<std::uint64_t>(c);
        }
        if (sh.translucent || !blocks) {
          shade(p, sub, c, static_cast<float>(px) + q.x * inv_aa, y_base + static_cast<float>(py) + q.y * inv_aa, covered);
          return;
        }
        // Block by block: each block's samples shaded at their centroid.
        const int bw = aa / sh.kx, bh = aa / sh.ky;
        for (int by = 0; by < sh.ky; ++by) {
          for (int bx = 0; bx < sh.kx; ++bx) {
            const std::uint64_t part = sub & rect_mask(bx * bw, bw, by * bh, bh);
            if (!part) continue;
            const auto [pq, pc] = samples(part);
            shade(p, part, pc, static_cast<float>(px) + pq.x * inv_aa, y_base + static_cast<float>(py) + pq.y * inv_aa, 0);
          }
        }
      };
      for (const coverage::TileMask& rec : st.records) {
        if (rec.run > 1) {
          // Whole tiles (a cell the triangle covers): every sample of every pixel, vacant before.
          for (int j = 0; j < per_tile; ++j) {
            const int py = rec.ty * per_tile + j;
            for (int px = rec.tx * per_tile; px < (rec.tx + rec.run) * per_tile; ++px) fragment(px, py, full, N, centre, 0);
          }
          continue;
        }
        if (per_tile == 1) {  // aa = 8: the tile is one pixel, its mask the pixel's samples
          const std::uint64_t sub = rec.mask;
          if (!sub) continue;
          const Samples at = pixel_samples(sub);
          fragment(rec.tx, rec.ty, sub, at.count, at.centroid, sh.translucent ? pyramid.tile_bits(rec.tx, rec.ty) : 0);
          continue;
        }
        for (int j = 0; j < per_tile; ++j) {
          for (int i = 0; i < per_tile; ++i) {
            const int shift = 8 * j * aa + i * aa;
            const std::uint64_t sub = (rec.mask >> shift) & full;
            if (!sub) continue;
            const Samples at = pixel_samples(sub);
            const std::uint64_t covered = sh.translucent ? (pyramid.tile_bits(rec.tx, rec.ty) >> shift) & full : 0;
            fragment(rec.tx * per_tile + i, rec.ty * per_tile + j, sub, at.count, at.centroid, covered);
          }
        }
      }
      if (queue.n > 0) flush();
    }

    // The sky over every sample still vacant (section 4.5: "composite a screen-sized polygon of
    // the desired background color"), then the band's pixels.
    const int tiles_x = pyramid.grid_width(0), tiles_y = pyramid.grid_height(0);
    const Color bottom(static_cast<float>(look.sky_bottom.r), static_cast<float>(look.sky_bottom.g), static_cast<float>(look.sky_bottom.b));
    const Color top(static_cast<float>(look.sky_top.r), static_cast<float>(look.sky_top.g), static_cast<float>(look.sky_top.b));
    const float inv_h = 1.0f / static_cast<float>(H);
    for (int ty = 0; ty < tiles_y; ++ty) {
      for (int tx = 0; tx < tiles_x; ++tx) {
        const std::uint64_t open = ~pyramid.tile_bits(tx, ty);
        if (!open) continue;
        for (int j = 0; j < per_tile; ++j) {
          for (int i = 0; i < per_tile; ++i) {
            const std::uint64_t sub = (open >> (8 * j * aa + i * aa)) & full;
            if (!sub) continue;
            const int px = tx * per_tile + i, py = ty * per_tile + j;
            const std::size_t p = static_cast<std::size_t>(py) * static_cast<std::size_t>(W) + static_cast<std::size_t>(px);
            const Samples at = pixel_samples(sub);
            const int c = at.count;
            const float qy = at.centroid.y;
            const float f = (static_cast<float>(row0 + py) + qy * inv_aa) * inv_h;
            out.add(p, sub, c, bottom + (top - bottom) * f, 1.0f);
            out.shaded(p, c);
            st.stats.samples_background += static_cast<std::uint64_t>(c);
          }
        }
      }
    }
    const float scale = 1.0f / static_cast<float>(N);
    for (int y = 0; y < rows; ++y) {
      const std::size_t src = static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      const std::size_t dst = static_cast<std::size_t>(H - 1 - row0 - y) * static_cast<std::size_t>(W);
      for (std::size_t x = 0; x < static_cast<std::size_t>(W); ++x) {
        const Color acc = out.px[src + x].acc;
        out.px[src + x].acc = Color();
        (acc * scale).store_rgb(&rgb_[3 * (dst + x)]);
        counts_[dst + x] = static_cast<std::uint8_t>(std::min(acc.get_fourth(), 255.0f));
      }
    }
    st.pixels_dirty = false;
    st.stats.cells_visited += pyramid.stats().cells_visited;
    st.stats.tile_cpu_ms += thread_cpu_ms() - cpu0;
  };

  run([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& r) {
      for (int b = r.begin(); b != r.end(); ++b) draw_band(b);
    });
  });

  Stats total;
  total.triangles = n_tri;
  for (const Impl::BandState& st : m.states) {
    total.translucent += st.stats.translucent;
    total.clipped += st.stats.clipped;
    total.tiled += st.stats.tiled;
    total.fragments += st.stats.fragments;
    total.shading_points += st.stats.shading_points;
    total.samples_covered += st.stats.samples_covered;
    total.samples_background += st.stats.samples_background;
    total.cells_visited += st.stats.cells_visited;
    total.class_splits += st.stats.class_splits;
    total.tile_cpu_ms += st.stats.tile_cpu_ms;
  }
  total.setup_ms = setup_ms;
  total.tile_ms = ms_since(t_tile);
  total.total_ms = ms_since(t_start);
  return total;
}

}  // namespace terravol::tiler
