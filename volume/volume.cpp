#include "volume/volume.h"

#include <GeographicLib/LocalCartesian.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace terravol::volume {

namespace {

// Parses "a,b,c" into three finite doubles.
bool parse_three(const std::string& text, double out[3]) {
  const char* p = text.c_str();
  for (int n = 0; n < 3; ++n) {
    char* end = nullptr;
    out[n] = std::strtod(p, &end);
    if (end == p || !std::isfinite(out[n])) return false;
    p = end;
    if (n < 2) {
      if (*p != ',') return false;
      ++p;
    }
  }
  return *p == '\0';
}

}  // namespace

VolumeFrame parse_frame(const std::string& text) {
  VolumeFrame f;
  if (text == "none") return f;
  if (text == "geographic") {
    f.kind = FrameKind::kGeographic;
    return f;
  }
  if (text == "geographic-agl") {
    f.kind = FrameKind::kGeographic;
    f.height = HeightRef::kGround;
    return f;
  }
  if (text.rfind("enu:", 0) == 0) {
    double v[3];
    if (!parse_three(text.substr(4), v)) {
      throw std::invalid_argument(text + ": expected enu:LAT,LON,H (degrees, degrees, metres)");
    }
    if (std::abs(v[0]) > 90.0 || std::abs(v[1]) > 360.0) {
      throw std::invalid_argument(text + ": origin latitude must be within [-90, 90] and longitude within [-360, 360]");
    }
    f.kind = FrameKind::kEnu;
    f.origin_lat = v[0];
    f.origin_lon = v[1];
    f.origin_h = v[2];
    return f;
  }
  throw std::invalid_argument(text + ": expected geographic, geographic-agl, enu:LAT,LON,H or none");
}

std::string format_frame(const VolumeFrame& frame) {
  switch (frame.kind) {
    case FrameKind::kNone:
      return "none";
    case FrameKind::kGeographic:
      return frame.height == HeightRef::kGround ? "geographic-agl" : "geographic";
    case FrameKind::kEnu: {
      char b[96];
      std::snprintf(b, sizeof b, "enu:%.17g,%.17g,%.17g", frame.origin_lat, frame.origin_lon, frame.origin_h);
      return b;
    }
  }
  return "none";
}

LatticeMapper::LatticeMapper(const Volume& volume, const io::SceneFrame& scene, GroundFunction ground)
    : frame_(volume.frame), lattice_(volume.lattice), scene_(scene), ground_(std::move(ground)) {
  if (frame_.kind == FrameKind::kNone) {
    throw std::invalid_argument(volume.name + ": the volume has no frame (give one, e.g. geographic or enu:LAT,LON,H)");
  }
  if (frame_.kind == FrameKind::kGeographic && frame_.height == HeightRef::kGround && !ground_) {
    throw std::invalid_argument(volume.name + ": heights are above ground, and no ground was given");
  }
  if (frame_.kind == FrameKind::kEnu) {
    enu_ = std::make_unique<GeographicLib::LocalCartesian>(frame_.origin_lat, frame_.origin_lon, frame_.origin_h);
  }
}

LatticeMapper::~LatticeMapper() = default;
LatticeMapper::LatticeMapper(LatticeMapper&&) noexcept = default;
LatticeMapper& LatticeMapper::operator=(LatticeMapper&&) noexcept = default;

io::Geodetic LatticeMapper::geodetic(double i, double j, double k) const {
  const double w0 = lattice_.world(0, i), w1 = lattice_.world(1, j), w2 = lattice_.world(2, k);
  io::Geodetic g;
  if (frame_.kind == FrameKind::kEnu) {
    enu_->Reverse(w0, w1, w2, g.lat, g.lon, g.h);
  } else {
    g.lon = w0;
    g.lat = w1;
    g.h = w2;
    if (frame_.height == HeightRef::kGround) g.h += ground_(g.lat, g.lon);
  }
  return g;
}

}  // namespace terravol::volume
