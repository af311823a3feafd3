// Camera paths. Positions: centripetal Catmull-Rom (alpha = 1/2; Yuksel, Schaefer and Keyser
// 2009) evaluated with the Barry-Goldman pyramid, end points mirrored to make the end segments.
// The spline is C1 in its own knot parameter u; time reaches u through a monotone cubic (Fritsch
// and Carlson 1980) through the keys' (t, u), so the position is C1 in time as well (plain
// Catmull-Rom with u linear in t per segment would jump in speed at every key).
// Orientations: Shoemake's squad (1985), with inner points chosen from a three-point tangent in
// the quaternions' log space scaled by each segment's duration, so that the angular velocity
// is continuous at keys spaced unevenly in time (squad itself assumes equal spacing).
#include "app/scene/camera_path.h"

#include "app/scene/json_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>
#include <utility>

#include <glm/geometric.hpp>

namespace terravol::app::scene {

namespace {

using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// Errors name the document and the field, e.g. "path.json: keys[2].pitch: ...".
struct Reader : JsonReader {
  explicit Reader(std::string source) : JsonReader(std::move(source), "field") {}
};

double altitude(const Reader& r, const json& j, const std::string& where, bool agl) {
  // Above the ground: strictly positive; in the datum: from below the Dead Sea to orbit.
  if (agl) {
    const double v = r.number(j, where, 0.0, 1e6);
    if (!(v > 0.0)) r.fail(where, "must be above the ground (> 0 with agl), is " + format_number(v));
    return v;
  }
  return r.number(j, where, -500.0, 1e6);
}

LookAt look_at_of(const Reader& r, const json& j, const std::string& where) {
  r.only_keys(j, where, {"lat", "lon", "alt", "agl"});
  LookAt a;
  a.lat = r.number(r.required(j, where, "lat"), Reader::join(where, "lat"), -85.0, 85.0);
  a.lon = r.number(r.required(j, where, "lon"), Reader::join(where, "lon"), -360.0, 360.0);
  if (j.contains("agl")) a.agl = r.boolean(j["agl"], Reader::join(where, "agl"));
  const json& alt = r.required(j, where, "alt");
  a.alt = a.agl ? r.number(alt, Reader::join(where, "alt"), 0.0, 1e6) : r.number(alt, Reader::join(where, "alt"), -500.0, 1e6);
  return a;
}

PathKey key_of(const Reader& r, const json& j, const std::string& where) {
  r.only_keys(j, where, {"t", "lat", "lon", "alt", "agl", "heading", "pitch", "roll", "look_at", "fov", "threshold"});
  PathKey k;
  k.t = r.number(r.required(j, where, "t"), Reader::join(where, "t"), 0.0, 1e7);
  k.lat = r.number(r.required(j, where, "lat"), Reader::join(where, "lat"), -85.0, 85.0);
  k.lon = r.number(r.required(j, where, "lon"), Reader::join(where, "lon"), -360.0, 360.0);
  if (j.contains("agl")) k.agl = r.boolean(j["agl"], Reader::join(where, "agl"));
  k.alt = altitude(r, r.required(j, where, "alt"), Reader::join(where, "alt"), k.agl);
  if (j.contains("look_at")) {
    for (const char* clash : {"heading", "pitch"}) {
      if (j.contains(clash)) r.fail(Reader::join(where, clash), "not allowed with look_at (the target sets it)");
    }
    k.look_at = look_at_of(r, j["look_at"], Reader::join(where, "look_at"));
  } else {
    if (!j.contains("heading")) r.fail(where, "needs \"heading\" (and \"pitch\") or \"look_at\"");
    k.heading_deg = r.number(j["heading"], Reader::join(where, "heading"), -360.0, 360.0);
    if (j.contains("pitch")) k.pitch_deg = r.number(j["pitch"], Reader::join(where, "pitch"), -90.0, 90.0);
  }
  if (j.contains("roll")) k.roll_deg = r.number(j["roll"], Reader::join(where, "roll"), -180.0, 180.0);
  if (j.contains("fov")) k.fov_y_deg = r.number(j["fov"], Reader::join(where, "fov"), 1.0, 179.0);
  if (j.contains("threshold")) k.threshold = r.number(j["threshold"], Reader::join(where, "threshold"), 1e-3, 1e7);
  return k;
}

// Keys in order and apart; `name(i)` names key i in messages.
template <class Name>
void check_order(const std::vector<PathKey>& keys, const Name& name, const std::string& prefix) {
  if (keys.size() < 2) {
    throw std::invalid_argument(prefix + "keys: a path needs at least two keys, has " + std::to_string(keys.size()));
  }
  for (std::size_t i = 1; i < keys.size(); ++i) {
    const double t = keys[i].t, before = keys[i - 1].t;
    if (!(t > before)) {
      throw std::invalid_argument(prefix + name(i) + ".t: " + format_number(t) + " is not after " + name(i - 1) + ".t (" +
                                  format_number(before) + "); keys must be in time order");
    }
    if (t - before < kMinKeyGap) {
      throw std::invalid_argument(prefix + name(i) + ".t: " + format_number(t) + " is within " + format_number(kMinKeyGap) +
                                  " s of " + name(i - 1) + ".t (" + format_number(before) + "); keys too close");
    }
  }
}

std::string key_name(std::size_t i) { return "keys[" + std::to_string(i) + "]"; }

// Monotone cubic Hermite slopes (Fritsch-Carlson, with the weighted harmonic mean of PCHIP):
// no overshoot between the points, C1.
std::vector<double> pchip_slopes(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  std::vector<double> m(n, 0.0);
  std::vector<double> h(n - 1), d(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    h[k] = x[k + 1] - x[k];
    d[k] = (y[k + 1] - y[k]) / h[k];
  }
  m[0] = d[0];
  m[n - 1] = d[n - 2];
  for (std::size_t k = 1; k + 1 < n; ++k) {
    if (d[k - 1] * d[k] <= 0.0) continue;
    const double w1 = 2.0 * h[k] + h[k - 1], w2 = h[k] + 2.0 * h[k - 1];
    m[k] = (w1 + w2) / (w1 / d[k - 1] + w2 / d[k]);
  }
  return m;
}

// The segment k with x[k] <= v <= x[k + 1] (v clamped to the ends).
std::size_t segment_of(const std::vector<double>& x, double v) {
  const auto it = std::upper_bound(x.begin() + 1, x.end() - 1, v);
  return static_cast<std::size_t>(it - x.begin()) - 1;
}

double hermite(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& m, double v) {
  v = std::clamp(v, x.front(), x.back());
  const std::size_t k = segment_of(x, v);
  const double h = x[k + 1] - x[k], s = (v - x[k]) / h;
  const double s2 = s * s, s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * y[k] + (s3 - 2 * s2 + s) * h * m[k] + (-2 * s3 + 3 * s2) * y[k + 1] +
         (s3 - s2) * h * m[k + 1];
}

// Unit quaternion logarithm and exponential (pure quaternions as vectors; half angles).
glm::dvec3 qlog(const glm::dquat& q) {
  const glm::dvec3 v(q.x, q.y, q.z);
  const double s = glm::length(v);
  if (s < 1e-15) return glm::dvec3(0.0);
  return v * (std::atan2(s, q.w) / s);
}

glm::dquat qexp(const glm::dvec3& v) {
  const double a = glm::length(v);
  if (a < 1e-15) return glm::dquat(1.0, v.x, v.y, v.z);
  const glm::dvec3 u = v * (std::sin(a) / a);
  return glm::dquat(std::cos(a), u.x, u.y, u.z);
}

// q1 exp(f log(q1^-1 q2)): along the great arc, the way the two quaternions' signs say.
glm::dquat arc(const glm::dquat& q1, const glm::dquat& q2, double f) {
  return q1 * qexp(f * qlog(glm::conjugate(q1) * q2));
}

glm::dquat squad(const glm::dquat& q1, const glm::dquat& q2, const glm::dquat& a, const glm::dquat& b, double f) {
  return arc(arc(q1, q2, f), arc(a, b, f), 2.0 * f * (1.0 - f));
}

// East-north-up: heading about -up, then pitch about east, then roll about the view axis.
glm::dquat orientation(double heading_deg, double pitch_deg, double roll_deg) {
  return glm::angleAxis(-heading_deg * kDeg, glm::dvec3(0, 0, 1)) *
         glm::angleAxis(pitch_deg * kDeg, glm::dvec3(1, 0, 0)) * glm::angleAxis(roll_deg * kDeg, glm::dvec3(0, 1, 0));
}

void angles_of(const glm::dquat& q, double& heading, double& pitch, double& roll) {
  const glm::dmat3 m = glm::mat3_cast(glm::normalize(q));  // m[column][row]
  const double sp = std::clamp(m[1][2], -1.0, 1.0);
  pitch = std::asin(sp) / kDeg;
  if (std::sqrt(1.0 - sp * sp) > 1e-9) {
    roll = std::atan2(-m[0][2], m[2][2]) / kDeg;
    heading = std::atan2(m[1][0], m[1][1]) / kDeg;
  } else {  // straight up or down: heading and roll are one rotation; call it heading
    roll = 0.0;
    heading = -std::atan2(m[0][1], m[0][0]) / kDeg;
  }
  heading = std::fmod(heading, 360.0);
  if (heading < 0.0) heading += 360.0;
  if (heading >= 360.0) heading = 0.0;
}

// Heading and pitch (degrees) from an eye to a target, both in the datum, against the local
// horizon at the eye (the tangent frame make_scene_camera uses).
void aim(const io::SceneFrame& frame, double lat, double lon, double h, const LookAt& target, double target_h,
         double& heading, double& pitch, const std::string& name) {
  const io::ScenePoint e = frame.to_scene({lat, lon, h}), t = frame.to_scene({target.lat, target.lon, target_h});
  const glm::dvec3 d(t.x - e.x, t.y - e.y, t.z - e.z);
  const double len = glm::length(d);
  if (len < 1e-3) throw std::invalid_argument(name + ".look_at: the target is at the eye");
  const double r = frame.curvature_radius();
  const glm::dvec3 up = glm::normalize(glm::dvec3(e.x / r, e.y / r, 1.0));
  const glm::dvec3 north = glm::normalize(glm::dvec3(0.0, 1.0, 0.0) - up.y * up);
  const glm::dvec3 east = glm::cross(north, up);
  heading = std::atan2(glm::dot(d, east), glm::dot(d, north)) / kDeg;
  pitch = std::asin(std::clamp(glm::dot(d, up) / len, -1.0, 1.0)) / kDeg;
}

}  // namespace

CameraPathFile parse_camera_path(const json& doc, const std::filesystem::path& base_dir, const std::string& source) {
  const Reader r(source);
  if (!doc.is_object()) r.fail("(top level)", "expected an object with \"scene\" and \"keys\"");
  r.only_keys(doc, "(top level)", {"scene", "keys", "speed"});
  CameraPathFile f;
  f.base_dir = base_dir;
  const json& scene = r.required(doc, "(top level)", "scene");
  if (scene.is_string() && !scene.get<std::string>().empty()) {
    const std::filesystem::path p(scene.get<std::string>());
    f.scene_file = p.is_absolute() ? p : base_dir / p;
  } else if (scene.is_object()) {
    f.scene = scene;
  } else {
    r.fail("scene", "expected a scene file name or a scene object, got " + scene.dump());
  }
  if (doc.contains("speed")) {
    const json& s = doc["speed"];
    if (s == "keys") {
      f.speed = PathSpeed::kKeys;
    } else if (s == "constant") {
      f.speed = PathSpeed::kConstant;
    } else {
      r.fail("speed", "expected \"keys\" or \"constant\", got " + s.dump());
    }
  }
  const json& keys = r.required(doc, "(top level)", "keys");
  if (!keys.is_array()) r.fail("keys", "expected a list of keys");
  for (std::size_t i = 0; i < keys.size(); ++i) f.keys.push_back(key_of(r, keys[i], key_name(i)));
  check_order(f.keys, key_name, source + ": ");
  return f;
}

CameraPathFile load_camera_path(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw std::invalid_argument(source + ": is a folder, not a path file");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw std::invalid_argument(source + ": cannot read (" + ec.message() + ")");
  if (size > (16u << 20)) throw std::invalid_argument(source + ": larger than 16 MiB; not a camera path");
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw std::invalid_argument(source + ": cannot read");
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    throw std::invalid_argument(source + ": not valid JSON (byte " + std::to_string(e.byte) + ")");
  }
  return parse_camera_path(doc, path.parent_path(), source);
}

json path_to_json(const json& scene, const std::vector<PathKey>& keys, PathSpeed speed) {
  json doc;
  doc["scene"] = scene;
  if (speed == PathSpeed::kConstant) doc["speed"] = "constant";
  json list = json::array();
  for (const PathKey& k : keys) {
    json j;
    j["t"] = k.t;
    j["lat"] = k.lat;
    j["lon"] = k.lon;
    j["alt"] = k.alt;
    if (k.agl) j["agl"] = true;
    if (k.look_at) {
      j["look_at"] = {{"lat", k.look_at->lat}, {"lon", k.look_at->lon}, {"alt", k.look_at->alt}};
      if (k.look_at->agl) j["look_at"]["agl"] = true;
    } else {
      j["heading"] = k.heading_deg;
      j["pitch"] = k.pitch_deg;
    }
    if (k.roll_deg != 0.0) j["roll"] = k.roll_deg;
    if (k.fov_y_deg) j["fov"] = *k.fov_y_deg;
    if (k.threshold) j["threshold"] = *k.threshold;
    list.push_back(std::move(j));
  }
  doc["keys"] = std::move(list);
  return doc;
}

CameraPath::CameraPath(std::vector<PathKey> keys, const io::SceneFrame& frame, const Ground& ground, PathSpeed speed,
                       double default_fov_deg, double default_threshold)
    : frame_(frame), speed_(speed) {
  check_order(keys, key_name, "");
  const std::size_t n = keys.size();
  auto ground_at = [&](double lat, double lon, std::size_t i) {
    if (!ground) throw std::logic_error("CameraPath: " + key_name(i) + " needs the ground, and none was given");
    return ground(lat, lon);
  };
  agl_ = std::all_of(keys.begin(), keys.end(), [](const PathKey& k) { return k.agl; });

  for (std::size_t i = 0; i < n; ++i) {
    const PathKey& k = keys[i];
    times_.push_back(k.t);
    const double channel = (k.agl && !agl_) ? ground_at(k.lat, k.lon, i) + k.alt : k.alt;
    points_.emplace_back(frame.x_of_lon(k.lon), frame.y_of_lat(k.lat), channel);
    double heading = k.heading_deg, pitch = k.pitch_deg;
    if (k.look_at) {
      const double eye_h = k.agl ? ground_at(k.lat, k.lon, i) + k.alt : k.alt;
      const double target_h = k.look_at->agl ? ground_at(k.look_at->lat, k.look_at->lon, i) + k.look_at->alt
                                             : k.look_at->alt;
      aim(frame, k.lat, k.lon, eye_h, *k.look_at, target_h, heading, pitch, key_name(i));
    }
    glm::dquat q = orientation(heading, pitch, k.roll_deg);
    // One hemisphere: each rotation the short way from the one before (no flip at 359 -> 1).
    if (i > 0 && glm::dot(q, rotations_.back()) < 0.0) q = -q;
    rotations_.push_back(q);
    fov_.push_back(k.fov_y_deg.value_or(default_fov_deg));
    threshold_.push_back(k.threshold.value_or(default_threshold));
  }

  // Centripetal knots: u_{i+1} - u_i = |P_{i+1} - P_i|^(1/2); a key at its neighbour's place
  // (turning on the spot) gets a tiny interval, not a division by zero.
  knots_.push_back(0.0);
  for (std::size_t i = 1; i < n; ++i) {
    const double d = glm::length(points_[i] - points_[i - 1]);
    if (speed == PathSpeed::kConstant && d < 1e-3) {
      throw std::invalid_argument(key_name(i) + ": at the position of " + key_name(i - 1) +
                                  "; \"speed\": \"constant\" needs every key to move the camera");
    }
    knots_.push_back(knots_.back() + std::max(std::sqrt(d), 1e-3));
  }
  u_slope_ = pchip_slopes(times_, knots_);
  t_slope_ = pchip_slopes(knots_, times_);
  fov_slope_ = pchip_slopes(times_, fov_);
  threshold_slope_ = pchip_slopes(times_, threshold_);

  // Squad inner points. Tangent at key i in log space per second, from the three-point
  // derivative over unequal intervals; the ends use the chord to their neighbour.
  out_ctrl_.resize(n);
  in_ctrl_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dquat inv = glm::conjugate(rotations_[i]);
    const glm::dvec3 next = i + 1 < n ? qlog(inv * rotations_[i + 1]) : glm::dvec3(0.0);
    const glm::dvec3 prev = i > 0 ? qlog(inv * rotations_[i - 1]) : glm::dvec3(0.0);
    const double h_next = i + 1 < n ? times_[i + 1] - times_[i] : 0.0;
    const double h_prev = i > 0 ? times_[i] - times_[i - 1] : 0.0;
    glm::dvec3 tangent;
    if (i == 0) {
      tangent = next / h_next;
    } else if (i + 1 == n) {
      tangent = -prev / h_prev;
    } else {
      tangent = (h_prev * (next / h_next) + h_next * (-prev / h_prev)) / (h_prev + h_next);
    }
    // Squad's derivative in f at the start of a segment is q (L+ + 2 log(q^-1 a)), at its end
    // q (-L- - 2 log(q^-1 b)); both must equal q * tangent * duration.
    out_ctrl_[i] = i + 1 < n ? rotations_[i] * qexp((tangent * h_next - next) / 2.0) : rotations_[i];
    in_ctrl_[i] = i > 0 ? rotations_[i] * qexp(-(tangent * h_prev + prev) / 2.0) : rotations_[i];
  }

  // Arc length along the spline: a table of u against distance.
  constexpr int kSteps = 256;
  arc_u_.push_back(knots_.front());
  arc_s_.push_back(0.0);
  glm::dvec3 last = points_.front();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    for (int s = 1; s <= kSteps; ++s) {
      const double u = knots_[i] + (knots_[i + 1] - knots_[i]) * s / kSteps;
      const glm::dvec3 p = position(u);
      arc_s_.push_back(arc_s_.back() + glm::length(p - last));
      arc_u_.push_back(u);
      last = p;
    }
  }
  length_ = arc_s_.back();
}

double CameraPath::knot_of_time(double t) const { return hermite(times_, knots_, u_slope_, t); }

double CameraPath::time_of_knot(double u) const { return hermite(knots_, times_, t_slope_, u); }

glm::dvec3 CameraPath::position(double u) const {
  const std::size_t n = points_.size();
  u = std::clamp(u, knots_.front(), knots_.back());
  const std::size_t i = segment_of(knots_, u);
  // Control points i-1 .. i+2, the missing ones mirrored through the end key.
  const glm::dvec3 p1 = points_[i], p2 = points_[i + 1];
  const double t1 = knots_[i], t2 = knots_[i + 1];
  const glm::dvec3 p0 = i > 0 ? points_[i - 1] : 2.0 * p1 - p2;
  const double t0 = i > 0 ? knots_[i - 1] : t1 - (t2 - t1);
  const glm::dvec3 p3 = i + 2 < n ? points_[i + 2] : 2.0 * p2 - p1;
  const double t3 = i + 2 < n ? knots_[i + 2] : t2 + (t2 - t1);
  const glm::dvec3 a1 = ((t1 - u) * p0 + (u - t0) * p1) / (t1 - t0);
  const glm::dvec3 a2 = ((t2 - u) * p1 + (u - t1) * p2) / (t2 - t1);
  const glm::dvec3 a3 = ((t3 - u) * p2 + (u - t2) * p3) / (t3 - t2);
  const glm::dvec3 b1 = ((t2 - u) * a1 + (u - t0) * a2) / (t2 - t0);
  const glm::dvec3 b2 = ((t3 - u) * a2 + (u - t1) * a3) / (t3 - t1);
  return ((t2 - u) * b1 + (u - t1) * b2) / (t2 - t1);
}

PathSample CameraPath::at(double t) const {
  t = std::clamp(t, start(), end());
  double u = 0.0, tau = t;  // spline parameter, and the key time the other quantities follow
  if (speed_ == PathSpeed::kKeys || length_ <= 0.0) {
    u = knot_of_time(t);
  } else {
    const double s = length_ * (t - start()) / (end() - start());
    const auto it = std::lower_bound(arc_s_.begin(), arc_s_.end(), s);
    const std::size_t k = std::clamp<std::size_t>(static_cast<std::size_t>(it - arc_s_.begin()), 1, arc_s_.size() - 1);
    const double ds = arc_s_[k] - arc_s_[k - 1];
    const double w = ds > 0.0 ? std::clamp((s - arc_s_[k - 1]) / ds, 0.0, 1.0) : 0.0;
    u = arc_u_[k - 1] + w * (arc_u_[k] - arc_u_[k - 1]);
    tau = std::clamp(time_of_knot(u), start(), end());
  }
  const glm::dvec3 p = position(u);
  const std::size_t i = segment_of(times_, tau);
  const double f = std::clamp((tau - times_[i]) / (times_[i + 1] - times_[i]), 0.0, 1.0);
  const glm::dquat q = squad(rotations_[i], rotations_[i + 1], out_ctrl_[i], in_ctrl_[i + 1], f);

  PathSample out;
  out.pose.lat = frame_.lat_of_y(p.y);
  out.pose.lon = frame_.lon_of_x(p.x);
  out.pose.alt = p.z;
  angles_of(q, out.pose.heading_deg, out.pose.pitch_deg, out.pose.roll_deg);
  out.fov_y_deg = hermite(times_, fov_, fov_slope_, tau);
  out.threshold = hermite(times_, threshold_, threshold_slope_, tau);
  return out;
}

}  // namespace terravol::app::scene
