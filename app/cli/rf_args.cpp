// Parsing of the options `terravol rf` and `terravol splat-volume` share (rf_args.h).
#include "app/cli/rf_args.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
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

volume::Transmitter parse_tx(const std::string& text, const std::string& where_in, const std::filesystem::path& base) {
  const std::string where = where_in.empty() ? "--tx " + text : where_in;
  auto bad = [&](const std::string& what) { throw std::runtime_error(where + ": " + what); };
  const auto parts = split(text, ',');
  std::size_t positional = 0;
  while (positional < parts.size() && parts[positional].find('=') == std::string::npos) ++positional;
  if (positional < 3 || positional > 5) {
    bad("expected LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]][,name=NAME][,pattern=FILE.az[:FILE.el]][,azimuth=DEG][,tilt=DEG]");
  }
  double v[5] = {0, 0, 0, 900.0, 0};
  static const char* names[] = {"latitude", "longitude", "height", "frequency", "ERP"};
  for (std::size_t n = 0; n < positional; ++n) {
    if (!to_number(parts[n], v[n]))
      bad(std::string(names[n]) + " '" + parts[n] + "' is not a number");
  }
  if (std::abs(v[0]) > 85.0) bad("latitude must be within [-85, 85] degrees");
  if (std::abs(v[1]) > 180.0) bad("longitude must be within [-180, 180] degrees");
  if (v[2] < 0.0 || v[2] > 100000.0) bad("height must be within [0, 100000] m above ground");
  if (v[3] <= 0.0 || v[3] > 100000.0) bad("frequency must be within (0, 100000] MHz");
  if (positional == 5 && (v[4] <= 0.0 || v[4] > 1e9)) bad("ERP must be within (0, 1e9] W");
  volume::Transmitter tx;
  tx.lat = v[0];
  tx.lon = v[1];
  tx.height_agl = v[2];
  tx.frequency_mhz = v[3];
  if (positional == 5) tx.erp_w = v[4];

  std::map<std::string, std::string> keyed;
  for (std::size_t n = positional; n < parts.size(); ++n) {
    const std::size_t eq = parts[n].find('=');
    if (eq == std::string::npos) bad("'" + parts[n] + "': numbers come first, then KEY=VALUE fields");
    const std::string key = parts[n].substr(0, eq), value = parts[n].substr(eq + 1);
    if (key != "name" && key != "pattern" && key != "azimuth" && key != "tilt")
      bad("unknown field '" + key + "' (expected name, pattern, azimuth or tilt)");
    if (!keyed.emplace(key, value).second) bad(key + " given twice");
  }
  if (const auto it = keyed.find("name"); it != keyed.end()) {
    const std::string& name = it->second;
    const bool ok = !name.empty() && name.size() <= 32 && std::all_of(name.begin(), name.end(), [](unsigned char c) {
      return std::isalnum(c) || c == '_' || c == '-' || c == '.';
    });
    if (!ok) bad("name '" + name + "': 1 to 32 letters, digits, '_', '-' or '.'");
    tx.name = name;
  }
  std::optional<double> azimuth, tilt;
  for (const char* key : {"azimuth", "tilt"}) {
    const auto it = keyed.find(key);
    if (it == keyed.end()) continue;
    double a = 0.0;
    if (!to_number(it->second, a)) bad(std::string(key) + " '" + it->second + "' is not a number of degrees");
    (std::string(key) == "azimuth" ? azimuth : tilt) = a;
  }
  const auto pattern = keyed.find("pattern");
  if (pattern == keyed.end()) {
    if (azimuth || tilt) bad(std::string(azimuth ? "azimuth" : "tilt") + " needs pattern=FILE.az[:FILE.el]");
    return tx;
  }
  std::string spec = pattern->second;
  if (!base.empty()) {
    const std::size_t colon = spec.find(':');
    auto resolve = [&](const std::string& file) {
      return file.empty() || std::filesystem::path(file).is_absolute() ? file : (base / file).string();
    };
    spec = colon == std::string::npos ? resolve(spec) : resolve(spec.substr(0, colon)) + ":" + resolve(spec.substr(colon + 1));
  }
  try {
    tx.antenna = volume::read_antenna_pattern(spec, azimuth, tilt);
  } catch (const std::exception& e) {
    bad(e.what());
  }
  return tx;
}

std::vector<volume::Transmitter> read_tx_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::vector<volume::Transmitter> out;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    std::size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line[start] == '#') continue;
    out.push_back(parse_tx(line.substr(start), path + ": line " + std::to_string(n),
                           std::filesystem::path(path).parent_path()));
  }
  if (in.bad()) throw std::runtime_error(path + ": cannot read");
  if (out.empty()) throw std::runtime_error(path + ": no transmitter (one --tx text per line)");
  return out;
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

void add_model_options(CLI::App& cmd, ModelArgs& a) {
  cmd.add_option("--model", a.model, "Propagation model: deygout or itm (Longley-Rice point-to-point)")
      ->capture_default_str();
  a.itm_options = {
      cmd.add_option("--polarization", a.polarization, "ITM: horizontal or vertical")->capture_default_str(),
      cmd.add_option("--permittivity", a.permittivity, "ITM: relative permittivity of the ground")->capture_default_str(),
      cmd.add_option("--conductivity", a.conductivity, "ITM: ground conductivity, S/m")->capture_default_str(),
      cmd.add_option("--refractivity", a.refractivity,
                     "ITM: surface refractivity at sea level N_0, N-units (SPLAT!'s bending constant)")
          ->capture_default_str(),
      cmd.add_option("--climate", a.climate,
                     "ITM: radio climate 1..7 (1 equatorial, 2 continental subtropical, 3 maritime subtropical, 4 "
                     "desert, 5 continental temperate, 6 maritime temperate over land, 7 maritime temperate over sea)")
          ->capture_default_str(),
      cmd.add_option("--time", a.time, "ITM: fraction of time the loss is not exceeded")->capture_default_str(),
      cmd.add_option("--location", a.location, "ITM: fraction of locations")->capture_default_str(),
      cmd.add_option("--situation", a.situation, "ITM: fraction of situations (confidence)")->capture_default_str(),
      cmd.add_option("--mdvar", a.mdvar,
                     "ITM: variability mode 0..3 (single message, accidental, mobile, broadcast), +10 without "
                     "location variability, +20 without direct situation variability (SPLAT!: 12)")
          ->capture_default_str(),
  };
}

volume::RfModel parse_model(const ModelArgs& a) {
  if (a.model == "itm") return volume::RfModel::kItm;
  if (a.model != "deygout") throw std::runtime_error("--model " + a.model + ": must be itm or deygout");
  for (const CLI::Option* option : a.itm_options) {
    if (option->count() > 0) throw std::runtime_error(option->get_name() + ": only with --model itm");
  }
  return volume::RfModel::kDeygout;
}

volume::ItmParameters itm_parameters(const ModelArgs& o) {
  volume::ItmParameters p;
  if (o.polarization == "horizontal" || o.polarization == "h") {
    p.polarization = volume::ItmPolarization::kHorizontal;
  } else if (o.polarization == "vertical" || o.polarization == "v") {
    p.polarization = volume::ItmPolarization::kVertical;
  } else {
    throw std::runtime_error("--polarization " + o.polarization + ": must be horizontal or vertical");
  }
  auto range = [](const char* option, double v, bool ok, const char* what) {
    if (ok) return;
    char b[32];
    std::snprintf(b, sizeof b, "%g", v);
    throw std::runtime_error(std::string(option) + " " + b + ": must be within " + what);
  };
  range("--permittivity", o.permittivity, o.permittivity > 1.0 && o.permittivity <= 100.0, "(1, 100]");
  range("--conductivity", o.conductivity, o.conductivity > 0.0 && o.conductivity <= 100.0, "(0, 100] S/m");
  range("--refractivity", o.refractivity, o.refractivity >= 250.0 && o.refractivity <= 400.0, "[250, 400] N-units");
  range("--time", o.time, o.time > 0.0 && o.time < 1.0, "(0, 1)");
  range("--location", o.location, o.location > 0.0 && o.location < 1.0, "(0, 1)");
  range("--situation", o.situation, o.situation > 0.0 && o.situation < 1.0, "(0, 1)");
  if (o.climate < 1 || o.climate > 7) {
    throw std::runtime_error("--climate " + std::to_string(o.climate) +
                             ": must be within 1..7 (1 equatorial, 2 continental subtropical, 3 maritime subtropical, 4 "
                             "desert, 5 continental temperate, 6 maritime temperate over land, 7 maritime temperate over sea)");
  }
  const int mode = o.mdvar % 10;
  if (o.mdvar < 0 || o.mdvar > 33 || mode > 3) {
    throw std::runtime_error("--mdvar " + std::to_string(o.mdvar) +
                             ": must be 0..3 (single message, accidental, mobile, broadcast), plus 10 without location "
                             "variability, plus 20 without direct situation variability");
  }
  p.permittivity = o.permittivity;
  p.conductivity = o.conductivity;
  p.refractivity = o.refractivity;
  p.climate = static_cast<volume::ItmClimate>(o.climate);
  p.time = o.time;
  p.location = o.location;
  p.situation = o.situation;
  p.variability = static_cast<volume::ItmVariability>(mode);
  p.location_variability = (o.mdvar % 20) < 10;
  p.situation_variability = o.mdvar < 20;
  return p;
}

}  // namespace terravol::app::cli
