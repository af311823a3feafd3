// Colour boxes given per frame, ordered exactly with the tree (issue 15; mrbsp/color_boxes.h).
//
// The boxes are the drawn colour cubes of a volume density (Chamberlain et al. 1996, section 3),
// one list per frame in a back-to-front order of their own (any order in which no box is drawn
// before a box it can hide: an octree's). Merging them into the tree as polygons (Wiley et al.
// 1997, section 4.2; merge.cpp) would cost hundreds of milliseconds per frame. Instead each
// traversal sends them through the tree as it decided it for this frame, without changing it,
// and keeps each piece in a bucket at the place of the tree's order where it belongs:
//   - the window's boundary planes first, in the walk's chain (west, east, south, north: a box
//     beyond two belongs to the first): what lies beyond is cut into that side's bands and
//     their level-0 rows or columns as the merge cuts pieces (merge.cpp, to_bands), each
//     part into its place's outside slot, or a bucket drawn where that slot would be;
//   - at every cell the walk enters, the plane z = h of its separation height (an LOD cell's
//     terrain zmax; a top cell's zmax or the top of its subtree's merged content, whichever is
//     higher): everything the cell's subtree draws lies below it, so what lies above is drawn
//     before the subtree when the eye is below the plane and after it otherwise, like the
//     pieces of the cell's above slot, into whose small BSP it goes when the cell has one;
//   - below the cell's zmin (under all of its terrain, so hidden from any eye above the
//     ground) it is dropped;
//   - between, it goes down the cell's split planes x = c and y = c (the middle lattice lines);
//   - a cell not entered (outside the view frustum, or found hidden by the occlusion pass)
//     keeps everything of its column in one bucket, drawn where the walk leaves the cell out:
//     its content box is out of view or hidden, and nothing the tree draws lies in its column;
//   - at a drawn cell the faces (the boxes' faces that face the eye, cut to the piece) are
//     ordered against its terrain: through its low slot's small BSP when merged pieces lie
//     there (the planes of its two triangles and of the pieces; below a triangle they are
//     dropped), else by the cell's diagonal plane and the plane of each triangle (below
//     dropped; above, drawn after the triangle when the eye is above its plane).
// Cuts by the tree's axis-aligned planes keep a piece a box (Part), with the box's own faces
// marked; only faces reaching a drawn cell's triangles or a small BSP become polygons (Poly).
// Within a bucket the pieces keep the boxes' order, so they are drawn in a valid order among
// themselves (a subsequence of a valid order); the faces of one box never overlap on screen.
// So nothing is drawn before something it can hide: the same argument as the tree's (a
// separating plane between any two things the order puts in different places), with the
// boxes' own order inside a bucket.
//
// Classification tolerance: 1e-7 times the window's side (a part within it of a plane is not
// cut, but goes wholly to the side of its middle): floats hold the boxes, a few millimetres at
// 50 km, and an overlap of that much across a plane is far below a pixel.
#include "mrbsp/box_order.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace terravol::mrbsp {

namespace {

enum : std::uint64_t { kKeyWhole = 1, kKeyAbove = 2, kKeyLeaf = 3, kKeyOutside = 4, kKeyBsp = 5 };

std::uint64_t cell_key(std::uint64_t kind, int level_index, int ci, int cj, int half = 0) {
  return kind << 61 | static_cast<std::uint64_t>(half) << 51 | static_cast<std::uint64_t>(cj) << 30 |
         static_cast<std::uint64_t>(ci) << 9 | static_cast<std::uint64_t>(level_index) << 3;
}
std::uint64_t bsp_key(std::int32_t slot, std::int32_t node, int side) {
  return kKeyBsp << 61 | static_cast<std::uint64_t>(side) << 60 | static_cast<std::uint64_t>(slot) << 31 |
         static_cast<std::uint64_t>(node);
}

// A region of the walk: a square (half -1) or one x half of it.
struct Region {
  int level_index, ci, cj, half;
};
std::uint64_t pack_region(const Region& r) {
  return static_cast<std::uint64_t>(r.level_index) | static_cast<std::uint64_t>(r.ci) << 6 |
         static_cast<std::uint64_t>(r.cj) << 27 | static_cast<std::uint64_t>(r.half + 1) << 48;
}
Region unpack_region(std::uint64_t v) {
  return {static_cast<int>(v & 63u), static_cast<int>((v >> 6) & 0x1FFFFFu), static_cast<int>((v >> 27) & 0x1FFFFFu),
          static_cast<int>((v >> 48) & 3u) - 1};
}

// Cuts `p` by the plane (axis a) = c into the part below and the part above. A piece within
// tol of the plane is not cut: it goes wholly to the side of its middle (returns -1 or +1);
// else 0 and both parts set.
int cut(const BoxScratch::Part& p, int a, double c, double tol, BoxScratch::Part& below, BoxScratch::Part& above) {
  if (!(p.lo[a] < c - tol && p.hi[a] > c + tol)) return 0.5 * (static_cast<double>(p.lo[a]) + p.hi[a]) < c ? -1 : 1;
  below = p;
  above = p;
  below.hi[a] = static_cast<float>(c);
  above.lo[a] = static_cast<float>(c);
  below.faces = static_cast<std::uint8_t>(below.faces & ~(1u << (2 * a + 1)));
  above.faces = static_cast<std::uint8_t>(above.faces & ~(1u << (2 * a)));
  return 0;
}

// Whether face f of a box from lo to hi faces the eye.
bool faces_eye(int f, const glm::vec3& lo, const glm::vec3& hi, const glm::dvec3& eye) {
  const int a = f / 2;
  return (f & 1) ? eye[a] > hi[a] : eye[a] < lo[a];
}

// The rectangle of face f of the box (lo, hi): four corners, counter-clockwise about the axis.
void face_corners(int f, const glm::vec3& lo, const glm::vec3& hi, glm::dvec3 out[4]) {
  const int a = f / 2, u = (a + 1) % 3, v = (a + 2) % 3;
  const double c = (f & 1) ? hi[a] : lo[a];
  const double us[4] = {lo[u], hi[u], hi[u], lo[u]}, vs[4] = {lo[v], lo[v], hi[v], hi[v]};
  for (int k = 0; k < 4; ++k) {
    out[k][a] = c;
    out[k][u] = us[k];
    out[k][v] = vs[k];
  }
}

// Sutherland-Hodgman against one plane: the parts of the convex polygon `in` with
// dot(n, p) + d >= 0 (front) and <= 0 (back). Vertices within tol of the plane go to both.
// Returns -1 when all of it lies behind (within tol), +1 in front (or in the plane), 0 when cut.
// A cut adds at most one vertex to each part; a polygon already holding Poly3::kMax vertices
// is not cut but goes to the side of its vertices' mean distance.
int split(const BoxScratch::Poly3& in, const glm::dvec3& n, double d, double tol, BoxScratch::Poly3& front,
          BoxScratch::Poly3& back) {
  bool any_front = false, any_back = false;
  double s[BoxScratch::Poly3::kMax];
  double mean = 0.0;
  for (int k = 0; k < in.n; ++k) {
    s[k] = glm::dot(n, in.v[static_cast<std::size_t>(k)]) + d;
    mean += s[k];
    any_front |= s[k] > tol;
    any_back |= s[k] < -tol;
  }
  if (!any_back) return 1;
  if (!any_front) return -1;
  if (in.n + 1 > BoxScratch::Poly3::kMax) return mean >= 0.0 ? 1 : -1;
  front.n = 0;
  back.n = 0;
  for (int k = 0; k < in.n; ++k) {
    const int k1 = k + 1 == in.n ? 0 : k + 1;
    const glm::dvec3& a = in.v[static_cast<std::size_t>(k)];
    const double sa = s[k], sb = s[k1];
    if (sa >= -tol) front.v[static_cast<std::size_t>(front.n++)] = a;
    if (sa <= tol) back.v[static_cast<std::size_t>(back.n++)] = a;
    if ((sa > tol && sb < -tol) || (sa < -tol && sb > tol)) {
      const glm::dvec3& b = in.v[static_cast<std::size_t>(k1)];
      const glm::dvec3 x = a + (b - a) * (sa / (sa - sb));
      front.v[static_cast<std::size_t>(front.n++)] = x;
      back.v[static_cast<std::size_t>(back.n++)] = x;
    }
  }
  return 0;
}

// The face f of the box (lo, hi) as a polygon.
BoxScratch::Poly3 face_polygon(int f, const glm::vec3& lo, const glm::vec3& hi) {
  BoxScratch::Poly3 p;
  glm::dvec3 c[4];
  face_corners(f, lo, hi, c);
  for (int k = 0; k < 4; ++k) p.v[static_cast<std::size_t>(k)] = c[k];
  p.n = 4;
  return p;
}

double window_tolerance(const TerrainTree::Impl& m) {
  const double side = std::max(m.xs.back() - m.xs.front(), m.ys.back() - m.ys.front());
  return 1e-7 * std::max(side, 1.0);
}

const CellContent* content_of(const TerrainTree::Impl& m, int level, int ci, int cj) {
  if (level < 0 || m.content_index.empty()) return nullptr;
  const std::int32_t c = m.content_index.find(m.cell_id(level, ci, cj));
  return c < 0 ? nullptr : &m.content[static_cast<std::size_t>(c)];
}

// The plane of a terrain triangle, its normal pointing up.
void triangle_plane(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, glm::dvec3& n, double& d) {
  n = glm::cross(b - a, c - a);
  if (n.z < 0.0) n = -n;
  n = glm::normalize(n);
  d = -glm::dot(n, a);
}

}  // namespace

float separation_height(const TerrainTree::Impl& m, int level, int ci, int cj) {
  const CellZ cz = m.cell_z(level, ci, cj);
  if (level >= 0 || m.top_content.empty()) return cz.zmax;
  return std::max(cz.zmax,
                  m.top_content[static_cast<std::size_t>(level + m.top)][static_cast<std::size_t>(cj * m.cells_at(level) + ci)]);
}

std::int32_t BoxScratch::find(std::uint64_t key) const {
  const auto it = index.find(key);
  return it == index.end() ? -1 : it->second;
}

std::int32_t BoxScratch::bucket(std::uint64_t key, bool holds_polys) {
  const auto [it, inserted] = index.try_emplace(key, static_cast<std::int32_t>(buckets.size()));
  if (inserted) buckets.push_back(Bucket{-1, -1, holds_polys});
  return it->second;
}

void BoxScratch::add_part(std::uint64_t key, const Part& p) {
  Bucket& b = buckets[static_cast<std::size_t>(bucket(key, false))];
  const auto at = static_cast<std::int32_t>(parts.size());
  parts.push_back(p);
  parts.back().next = -1;
  if (b.tail >= 0) parts[static_cast<std::size_t>(b.tail)].next = at; else b.head = at;
  b.tail = at;
  ++stats.parts;
}

void BoxScratch::add_poly(std::uint64_t key, const glm::dvec3* v, std::size_t n, glm::u8vec4 rgba) {
  if (n < 3) return;
  Bucket& b = buckets[static_cast<std::size_t>(bucket(key, true))];
  const auto at = static_cast<std::int32_t>(polys.size());
  polys.push_back(Poly{static_cast<std::uint32_t>(verts.size()), static_cast<std::uint32_t>(n), rgba, -1});
  verts.insert(verts.end(), v, v + n);
  if (b.tail >= 0) polys[static_cast<std::size_t>(b.tail)].next = at; else b.head = at;
  b.tail = at;
}

std::int32_t BoxScratch::whole(int level_index, int ci, int cj) const {
  return active ? find(cell_key(kKeyWhole, level_index, ci, cj)) : -1;
}
std::int32_t BoxScratch::above(int level_index, int ci, int cj) const {
  return active ? find(cell_key(kKeyAbove, level_index, ci, cj)) : -1;
}
void BoxScratch::to_outside(const TerrainTree::Impl& m, int side, const Part& p, double tol) {
  const int axis = side < 2 ? 0 : 1;
  const bool low_side = side % 2 == 0;  // west and south lie below their planes
  const auto to_place = [&](int band, int column, const Part& q) {
    const SlotKey key = outside_key(side, band, column);
    if (const auto it = outside_slot_.find(key); it != outside_slot_.end()) {
      insert_into_slot(m, it->second, q, tol);
      return;
    }
    const std::uint64_t bucket_key = kKeyOutside << 61 | static_cast<std::uint64_t>(side) << 40 |
                                     static_cast<std::uint64_t>(band) << 20 | static_cast<std::uint64_t>(column);
    const bool fresh = find(bucket_key) < 0;
    add_part(bucket_key, q);
    if (fresh) outside_places_[static_cast<std::size_t>(side)].push_back({band, column, find(bucket_key)});
  };
  const auto to_columns = [&](int band, Part q) {
    const int columns = m.place_columns();
    for (int column = 0; column + 1 < columns; ++column) {
      Part west{}, east{};  // south and north of the line for west and east's rows
      const double line = m.place_line(side, column + 1);
      const int c = cut(q, m.column_axis(side), line, tol, west, east);
      if (c < 0) {
        to_place(band, column, q);
        return;
      }
      if (c == 0) {
        to_place(band, column, west);
        q = east;
      }
    }
    to_place(band, columns - 1, q);
  };
  Part q = p;
  for (int band = 0; band + 1 < kBands; ++band) {
    Part below{}, above{};
    const int c = cut(q, axis, m.band_plane(side, band + 1), tol, below, above);
    const int near = low_side ? 1 : -1;  // the window's side of the band plane
    if (c == near) {
      to_columns(band, q);
      return;
    }
    if (c == 0) {
      to_columns(band, low_side ? above : below);
      q = low_side ? below : above;
    }
  }
  to_columns(kBands - 1, q);
}
bool BoxScratch::leaf(int level_index, int ci, int cj) const {
  return active && (find(cell_key(kKeyLeaf, level_index, ci, cj, 0)) >= 0 || find(cell_key(kKeyLeaf, level_index, ci, cj, 1)) >= 0);
}
std::int32_t BoxScratch::bsp(std::int32_t slot, std::int32_t node, int side) const {
  return active ? find(bsp_key(slot, node, side)) : -1;
}

void BoxScratch::insert_into_slot(const TerrainTree::Impl& m, std::int32_t slot, const Part& p, double tol) {
  const BspStore& store = *m.slots[static_cast<std::size_t>(slot)].store;
  slot_boxed[static_cast<std::size_t>(slot)] = 1;
  int faces[3], count = 0;
  for (int f = 0; f < 6; ++f)
    if ((p.faces & (1u << f)) && faces_eye(f, p.lo, p.hi, eye_)) faces[count++] = f;
  if (count == 0) return;
  stats.faces += static_cast<std::size_t>(count);
  stats.bsp_faces += static_cast<std::size_t>(count);
  const auto colour = [&](int f) { return boxes[p.box].rgba[static_cast<std::size_t>(f)]; };
  if (store.root < 0) {  // an empty store: one region
    for (int q = 0; q < count; ++q) {
      const Poly3 poly = face_polygon(faces[q], p.lo, p.hi);
      add_poly(bsp_key(slot, kRootless, 0), poly.v.data(), static_cast<std::size_t>(poly.n), colour(faces[q]));
    }
    return;
  }
  // The box goes down whole while a plane leaves it on one side (one test for all its faces);
  // where a plane passes through it, its faces go on as polygons, cut where needed.
  const glm::dvec3 centre = 0.5 * (glm::dvec3(p.lo) + glm::dvec3(p.hi)), half = 0.5 * (glm::dvec3(p.hi) - glm::dvec3(p.lo));
  std::vector<Item>& stack = bsp_stack_;
  std::vector<Poly3>& pool = poly_pool_;
  pool.clear();
  stack.assign(1, Item{store.root, -1, 0});
  const auto arrive = [&](std::int32_t node, int side, const Poly3& poly, int face) {
    add_poly(bsp_key(slot, node, side), poly.v.data(), static_cast<std::size_t>(poly.n), colour(face));
  };
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const BspNode& bn = store.nodes[static_cast<std::size_t>(it.node)];
    const glm::dvec3 n(bn.n);
    const double d = static_cast<double>(bn.d);
    if (it.poly < 0) {  // the whole box
      const double s = glm::dot(n, centre) + d, r = glm::dot(glm::abs(n), half);
      int side = -1;
      if (s - r >= -tol) side = 1;
      else if (s + r <= tol) side = 0;
      if (side >= 0) {
        const std::int32_t child = side ? bn.front : bn.back;
        if (child >= 0) {
          stack.push_back(Item{child, -1, 0});
        } else if (child == kDropSide) {
          stats.dropped += static_cast<std::size_t>(count);
        } else {
          for (int q = 0; q < count; ++q) arrive(it.node, side, face_polygon(faces[q], p.lo, p.hi), faces[q]);
        }
        continue;
      }
      // Cut here: each face from this node on as a polygon.
      for (int q = 0; q < count; ++q) {
        pool.push_back(face_polygon(faces[q], p.lo, p.hi));
        stack.push_back(Item{it.node, static_cast<std::int32_t>(pool.size() - 1), faces[q]});
      }
      continue;
    }
    const Poly3 poly = pool[static_cast<std::size_t>(it.poly)];
    Poly3 front, back;
    const int s = split(poly, n, d, tol, front, back);
    const auto go = [&](int side, const Poly3& piece) {
      const std::int32_t child = side ? bn.front : bn.back;
      if (child == kDropSide) {
        ++stats.dropped;
      } else if (child < 0) {
        arrive(it.node, side, piece, it.face);
      } else {
        pool.push_back(piece);
        stack.push_back(Item{child, static_cast<std::int32_t>(pool.size() - 1), it.face});
      }
    };
    if (s > 0) {
      go(1, poly);
    } else if (s < 0) {
      go(0, poly);
    } else {
      go(1, front);
      go(0, back);
    }
  }
}

void BoxScratch::distribute(TerrainTree::Impl& m, const Camera& camera, const Decided& d, std::span<const ColorBox> given) {
  const auto t0 = std::chrono::steady_clock::now();
  boxes = given;
  parts.clear();
  polys.clear();
  verts.clear();
  buckets.clear();
  index.clear();
  slot_boxed.assign(m.slots.size(), 0);
  stats = {};
  stats.boxes = given.size();
  active = true;
  eye_ = camera.eye;
  for (auto& places : outside_places_) places.clear();
  outside_slot_.clear();
  for (const auto& slots : m.outside)
    for (const std::int32_t slot : slots) outside_slot_.emplace(m.slots[static_cast<std::size_t>(slot)].key, slot);
  const double tol = window_tolerance(m);
  const double wx0 = m.xs.front(), wx1 = m.xs.back(), wy0 = m.ys.front(), wy1 = m.ys.back();
  constexpr std::uint32_t kDrawnState = 1;

  // A piece above a cell's separation height: into its above slot, else its above bucket.
  const auto to_above = [&](const Region& r, int level, const Part& p) {
    const CellContent* content = content_of(m, level, r.ci, r.cj);
    if (content && content->above >= 0) {
      insert_into_slot(m, content->above, p, tol);
    } else {
      add_part(cell_key(kKeyAbove, r.level_index, r.ci, r.cj), p);
    }
  };
  // A piece in a drawn cell, between its zmin and zmax.
  const auto to_leaf = [&](const Region& r, int level, const Part& p) {
    const CellContent* content = content_of(m, level, r.ci, r.cj);
    if (content && content->low >= 0) {
      const auto slot = static_cast<std::size_t>(content->low);
      if (!m.slots[slot].built) m.build_pending(slot);
      insert_into_slot(m, content->low, p, tol);
      return;
    }
    const int s = m.cell_size(level), i0 = r.ci * s, j0 = r.cj * s;
    const glm::dvec3 sw(m.positions[m.vertex(i0, j0)]), se(m.positions[m.vertex(i0 + s, j0)]),
        ne(m.positions[m.vertex(i0 + s, j0 + s)]), nw(m.positions[m.vertex(i0, j0 + s)]);
    // The diagonal plane: negative on the south-east side (the walk's convention).
    const double x0 = m.xs[static_cast<std::size_t>(i0)], x1 = m.xs[static_cast<std::size_t>(i0 + s)];
    const double y0 = m.ys[static_cast<std::size_t>(j0)], y1 = m.ys[static_cast<std::size_t>(j0 + s)];
    const glm::dvec3 dn(-(y1 - y0), x1 - x0, 0.0);
    const double dd = -(dn.x * x0 + dn.y * y0);
    glm::dvec3 tn[2];
    double td[2];
    triangle_plane(sw, se, ne, tn[0], td[0]);  // half 0: south-east
    triangle_plane(sw, ne, nw, tn[1], td[1]);  // half 1: north-west
    for (int f = 0; f < 6; ++f) {
      if (!(p.faces & (1u << f)) || !faces_eye(f, p.lo, p.hi, eye_)) continue;
      ++stats.faces;
      const glm::u8vec4 rgba = boxes[p.box].rgba[static_cast<std::size_t>(f)];
      const Poly3 face = face_polygon(f, p.lo, p.hi);
      Poly3 north_west, south_east;
      const int s_diag = split(face, dn, dd, tol, north_west, south_east);
      const Poly3* halves[2] = {nullptr, nullptr};  // south-east (behind the diagonal plane), north-west
      if (s_diag < 0) {
        halves[0] = &face;
      } else if (s_diag > 0) {
        halves[1] = &face;
      } else {
        halves[0] = &south_east;
        halves[1] = &north_west;
      }
      for (int h = 0; h < 2; ++h) {
        if (halves[h] == nullptr) continue;
        Poly3 keep, below;
        const int st = split(*halves[h], tn[h], td[h], tol, keep, below);
        if (st < 0) {
          ++stats.dropped;
          continue;
        }
        const Poly3& piece = st > 0 ? *halves[h] : keep;
        add_poly(cell_key(kKeyLeaf, r.level_index, r.ci, r.cj, h), piece.v.data(), static_cast<std::size_t>(piece.n), rgba);
      }
    }
  };

  for (std::uint32_t k = 0; k < given.size(); ++k) {
    Part p{given[k].lo, given[k].hi, k, 0x3F, -1};
    // The window's boundary chain: west, east, south, north.
    bool gone = false;
    const double bounds[4] = {wx0, wx1, wy0, wy1};
    for (int side = 0; side < 4 && !gone; ++side) {
      const int a = side / 2;
      Part lo_part{}, hi_part{};
      const int c = cut(p, a, bounds[side], tol, lo_part, hi_part);
      const bool beyond_is_low = side % 2 == 0;
      // Beyond the side: into its bands' small BSPs or buckets (to_outside).
      const auto beyond = [&](const Part& q) { to_outside(m, side, q, tol); };
      if (c == 0) {
        beyond(beyond_is_low ? lo_part : hi_part);
        p = beyond_is_low ? hi_part : lo_part;
      } else if ((c < 0) == beyond_is_low) {
        beyond(p);
        gone = true;
      }
    }
    if (gone) continue;
    work.clear();
    work.emplace_back(p, pack_region(Region{0, 0, 0, -1}));
    while (!work.empty()) {
      Part q = work.back().first;
      Region r = unpack_region(work.back().second);
      work.pop_back();
      const int level = r.level_index - m.top;
      const int s = m.cell_size(level), i0 = r.ci * s, j0 = r.cj * s, half = s / 2;
      if (r.half >= 0) {  // the y split of an x half
        Part south{}, north{};
        const int c = cut(q, 1, m.ys[static_cast<std::size_t>(j0 + half)], tol, south, north);
        const Region rs{r.level_index + 1, 2 * r.ci + r.half, 2 * r.cj, -1}, rn{r.level_index + 1, 2 * r.ci + r.half, 2 * r.cj + 1, -1};
        if (c == 0) {
          work.emplace_back(north, pack_region(rn));
          work.emplace_back(south, pack_region(rs));
        } else {
          work.emplace_back(q, pack_region(c < 0 ? rs : rn));
        }
        continue;
      }
      const CellZ cz = m.cell_z(level, r.ci, r.cj);
      // A cell the walk leaves out keeps its column's pieces, less what lies below all of its
      // terrain (hidden from any eye above the ground by nearer terrain, which is drawn later).
      const auto left_out = [&] {
        Part below{}, upper{};
        if (q.hi.z <= cz.zmin + tol) {
          ++stats.dropped;
        } else if (cut(q, 2, cz.zmin, tol, below, upper) == 0) {
          add_part(cell_key(kKeyWhole, r.level_index, r.ci, r.cj), upper);
        } else {
          add_part(cell_key(kKeyWhole, r.level_index, r.ci, r.cj), q);
        }
      };
      std::uint32_t st = 2;
      if (level >= 0) {
        const std::uint32_t cell = m.cell_id(level, r.ci, r.cj);
        st = d.state(cell);
        if (st == 0 || d.is_hidden(cell)) {
          left_out();
          continue;
        }
      } else if (!d.top_in_view[static_cast<std::size_t>(r.level_index)][static_cast<std::size_t>(r.cj * m.cells_at(level) + r.ci)]) {
        left_out();
        continue;
      }
      const double zsep = separation_height(m, level, r.ci, r.cj);
      if (q.lo.z >= zsep - tol) {
        to_above(r, level, q);
        continue;
      }
      if (q.hi.z <= cz.zmin + tol) {
        ++stats.dropped;
        continue;
      }
      Part below{}, upper{};
      if (cut(q, 2, zsep, tol, below, upper) == 0) {
        to_above(r, level, upper);
        q = below;
      }
      if (level >= 0 && st == kDrawnState) {
        to_leaf(r, level, q);
        continue;
      }
      Part west{}, east{};
      const int c = cut(q, 0, m.xs[static_cast<std::size_t>(i0 + half)], tol, west, east);
      const Region rw{r.level_index, r.ci, r.cj, 0}, re{r.level_index, r.ci, r.cj, 1};
      if (c == 0) {
        work.emplace_back(east, pack_region(re));
        work.emplace_back(west, pack_region(rw));
      } else {
        work.emplace_back(q, pack_region(c < 0 ? rw : re));
      }
    }
  }
  stats.distribute_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void BoxScratch::emit_part(const Part& p, const glm::dvec3& eye, Frame& frame) {
  for (int f = 0; f < 6; ++f) {
    if (!(p.faces & (1u << f)) || !faces_eye(f, p.lo, p.hi, eye)) continue;
    glm::dvec3 c[4];
    face_corners(f, p.lo, p.hi, c);
    const glm::u8vec4 rgba = boxes[p.box].rgba[static_cast<std::size_t>(f)];
    const auto v0 = static_cast<std::uint32_t>(frame.transient_base + frame.transient_positions.size());
    for (const glm::dvec3& q : c) {
      frame.transient_positions.emplace_back(q);
      frame.transient_colors.push_back(rgba);
    }
    tris.push_back({v0, v0 + 1, v0 + 2, kBoxLevel});
    tris.push_back({v0, v0 + 2, v0 + 3, kBoxLevel});
    ++stats.faces;
  }
}

void BoxScratch::emit_poly(const Poly& p, Frame& frame) {
  const auto v0 = static_cast<std::uint32_t>(frame.transient_base + frame.transient_positions.size());
  for (std::uint32_t k = 0; k < p.count; ++k) {
    frame.transient_positions.emplace_back(verts[p.first + k]);
    frame.transient_colors.push_back(p.rgba);
  }
  for (std::uint32_t k = 1; k + 1 < p.count; ++k) tris.push_back({v0, v0 + k, v0 + k + 1, kBoxLevel});
}

void BoxScratch::emit_bucket(std::int32_t b, const glm::dvec3& eye, bool back_to_front, Frame& frame) {
  tris.clear();
  const Bucket& bucket_ = buckets[static_cast<std::size_t>(b)];
  order.clear();
  for (std::int32_t k = bucket_.head; k >= 0;
       k = bucket_.polys ? polys[static_cast<std::size_t>(k)].next : parts[static_cast<std::size_t>(k)].next) {
    order.push_back(k);
  }
  if (!back_to_front) std::reverse(order.begin(), order.end());
  for (const std::int32_t k : order) {
    if (bucket_.polys) emit_poly(polys[static_cast<std::size_t>(k)], frame); else emit_part(parts[static_cast<std::size_t>(k)], eye, frame);
  }
}

void BoxScratch::emit_leaf(const TerrainTree::Impl& m, int level_index, int ci, int cj, const glm::dvec3& eye,
                           bool eye_south_east, bool back_to_front, Frame& frame) {
  std::vector<Tri> out;
  const int level = level_index - m.top;
  const int s = m.cell_size(level), i0 = ci * s, j0 = cj * s;
  const std::uint32_t sw = m.vertex(i0, j0), se = m.vertex(i0 + s, j0), ne = m.vertex(i0 + s, j0 + s), nw = m.vertex(i0, j0 + s);
  const std::uint32_t tri[2][3] = {{sw, se, ne}, {sw, ne, nw}};  // half 0 south-east, 1 north-west
  // The walk's order: the north-west triangle first when eye_south_east == back_to_front.
  const int first = eye_south_east == back_to_front ? 1 : 0;
  for (const int h : {first, 1 - first}) {
    glm::dvec3 n;
    double d;
    triangle_plane(glm::dvec3(m.positions[tri[h][0]]), glm::dvec3(m.positions[tri[h][1]]), glm::dvec3(m.positions[tri[h][2]]), n, d);
    const bool eye_above = glm::dot(n, eye) + d >= 0.0;
    const std::int32_t b = find(cell_key(kKeyLeaf, level_index, ci, cj, h));
    std::vector<Tri> faces;
    if (b >= 0) {
      emit_bucket(b, eye, back_to_front, frame);
      faces.swap(tris);
    }
    const Tri terrain{tri[h][0], tri[h][1], tri[h][2], static_cast<std::int8_t>(level)};
    // The faces lie above the triangle: nearer than it when the eye is above its plane.
    const bool faces_after = eye_above == back_to_front;
    if (!faces_after) out.insert(out.end(), faces.begin(), faces.end());
    out.push_back(terrain);
    if (faces_after) out.insert(out.end(), faces.begin(), faces.end());
  }
  tris.swap(out);
}

}  // namespace terravol::mrbsp
