// Parsing of the options `terravol rf` and `terravol splat-volume` share (rf_args.h).
#include "app/cli/rf_args.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace terravol::app::cli {

namespace {

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(sep, start);
    parts.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return parts;
}

// A finite number filling the whole text, or nothing.
bool to_number(const std::string& text, double& out) {
  if (text.empty()) return false;
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return *end == '\0' && std::isfinite(out);
}

}  // namespace

volume::Transmitter parse_tx(const std::string& text) {
  auto bad = [&](const std::string& what) {
    throw std::runtime_error("--tx " + text + ": " + what);
  };
  const auto parts = split(text, ',');
  if (parts.size() < 3 || parts.size() > 5) bad("expected LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]]");
  double v[5] = {0, 0, 0, 900.0, 0};
  static const char* names[] = {"latitude", "longitude", "height", "frequency", "ERP"};
  for (std::size_t n = 0; n < parts.size(); ++n) {
    if (!to_number(parts[n], v[n]))
      bad(std::string(names[n]) + " '" + parts[n] + "' is not a number");
  }
  if (std::abs(v[0]) > 85.0) bad("latitude must be within [-85, 85] degrees");
  if (std::abs(v[1]) > 180.0) bad("longitude must be within [-180, 180] degrees");
  if (v[2] < 0.0 || v[2] > 100000.0) bad("height must be within [0, 100000] m above ground");
  if (v[3] <= 0.0 || v[3] > 100000.0) bad("frequency must be within (0, 100000] MHz");
  if (parts.size() == 5 && (v[4] <= 0.0 || v[4] > 1e9)) bad("ERP must be within (0, 1e9] W");
  volume::Transmitter tx;
  tx.lat = v[0];
  tx.lon = v[1];
  tx.height_agl = v[2];
  tx.frequency_mhz = v[3];
  if (parts.size() == 5) tx.erp_w = v[4];
  return tx;
}

// "START:STOP:STEP" (STOP included when it falls on a step), "H1,H2,..." evenly spaced, or "H".
std::vector<double> parse_heights(const std::string& text) {
  auto bad = [&](const std::string& what) {
    throw std::runtime_error("--heights " + text + ": " + what);
  };
  std::vector<double> h;
  if (text.find(':') != std::string::npos) {
    const auto parts = split(text, ':');
    double a, b, step;
    if (parts.size() != 3 || !to_number(parts[0], a) || !to_number(parts[1], b) ||
        !to_number(parts[2], step)) {
      bad("expected START:STOP:STEP in metres, e.g. 0:2000:50");
    }
    if (step <= 0.0) bad("STEP must be > 0");
    if (b < a) bad("STOP must not be below START");
    const double count = std::floor((b - a) / step + 1e-9) + 1.0;
    if (count > 100000.0) bad("too many heights");
    for (int n = 0; n < static_cast<int>(count); ++n) h.push_back(a + n * step);
  } else {
    for (const auto& p : split(text, ',')) {
      double v;
      if (!to_number(p, v)) bad("'" + p + "' is not a number");
      h.push_back(v);
    }
  }
  for (std::size_t n = 0; n < h.size(); ++n) {
    if (h[n] < 0.0 || h[n] > 100000.0) bad("heights must be within [0, 100000] m above ground");
    if (n > 0 && h[n] <= h[n - 1]) bad("heights must increase");
    if (n > 1 && std::abs((h[n] - h[n - 1]) - (h[1] - h[0])) > 1e-6)
      bad("heights must be evenly spaced (a regular lattice)");
  }
  return h;
}

}  // namespace terravol::app::cli
