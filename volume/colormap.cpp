// Colour map tables.
//
// Sources (no VTK 9.1 module ships these maps: vtkColorSeries holds Brewer schemes only, and
// the matplotlib presets of vtkDiscretizableColorTransferFunction live in ParaView):
// - viridis, plasma, inferno, magma (van der Walt and Smith, BIDS, 2015) and turbo (Mikhailov,
//   Google, 2019): matplotlib 3.6.3 `_cm_listed.py` (Debian python3-matplotlib), 33 of the 256
//   entries (indices round(i * 255 / 32)), rounded to 8 bits. Linear interpolation between them
//   reproduces the full 256-entry tables to within 3.1/255 per channel (plasma; 2.4 for turbo,
//   under 1.8 for the others).
// - coolwarm: K. Moreland, "Diverging Color Maps for Scientific Visualization" (ISVC 2009),
//   CoolWarmFloat33, as in matplotlib `_cm.py`: all 33 points, exact up to 8-bit rounding.
// - the categorical colours: matplotlib 3.6.3 `_cm.py` `_tab20_data` (Tableau 20), rounded to 8
//   bits.
// - jet: matplotlib `_cm.py` `_jet_data`, its per-channel breakpoints merged into 12 stops, so
//   it is exact up to 8-bit rounding.
#include "volume/colormap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace terravol::volume {

namespace {

// 33 evenly spaced colours as stops at t = i / 32.
using Table33 = std::array<glm::u8vec3, 33>;

constexpr std::array<ColorStop, 33> even_stops(const Table33& rgb) {
  std::array<ColorStop, 33> s{};
  for (std::size_t i = 0; i < rgb.size(); ++i) s[i] = ColorStop{static_cast<float>(i) / 32.0f, rgb[i]};
  return s;
}

constexpr Table33 kViridis{{
    {68, 1, 84}, {71, 13, 96}, {72, 24, 106}, {72, 35, 116}, {71, 45, 123}, {69, 55, 129},
    {66, 64, 134}, {62, 73, 137}, {59, 82, 139}, {55, 91, 141}, {51, 99, 141}, {47, 107, 142},
    {44, 114, 142}, {41, 122, 142}, {38, 130, 142}, {35, 137, 142}, {33, 145, 140}, {31, 151, 139},
    {31, 159, 136}, {33, 166, 133}, {39, 173, 129}, {49, 181, 123}, {61, 188, 116}, {76, 194, 108},
    {92, 200, 99}, {110, 206, 88}, {129, 211, 77}, {149, 216, 64}, {170, 220, 50}, {192, 223, 37},
    {213, 226, 26}, {234, 229, 26}, {253, 231, 37},
}};

constexpr Table33 kPlasma{{
    {13, 8, 135}, {34, 6, 144}, {49, 5, 151}, {63, 4, 156}, {76, 2, 161}, {89, 1, 165},
    {102, 0, 167}, {114, 1, 168}, {126, 3, 168}, {138, 9, 165}, {149, 17, 161}, {160, 26, 156},
    {170, 35, 149}, {179, 44, 142}, {188, 53, 135}, {196, 62, 127}, {204, 71, 120}, {210, 79, 113},
    {217, 88, 106}, {223, 98, 99}, {229, 107, 93}, {235, 117, 86}, {240, 127, 79}, {244, 137, 72},
    {248, 148, 65}, {251, 159, 58}, {253, 171, 51}, {254, 183, 45}, {253, 195, 40}, {252, 208, 37},
    {249, 221, 37}, {245, 235, 39}, {240, 249, 33},
}};

constexpr Table33 kInferno{{
    {0, 0, 4}, {4, 3, 18}, {11, 7, 36}, {21, 11, 55}, {33, 12, 74}, {47, 10, 91},
    {61, 9, 101}, {74, 12, 107}, {87, 16, 110}, {100, 21, 110}, {113, 25, 110}, {125, 30, 109},
    {138, 34, 106}, {151, 39, 102}, {163, 44, 97}, {176, 49, 91}, {188, 55, 84}, {198, 61, 77},
    {208, 69, 69}, {218, 78, 60}, {227, 89, 51}, {235, 100, 41}, {241, 113, 31}, {246, 126, 20},
    {249, 140, 10}, {251, 155, 6}, {252, 170, 15}, {251, 186, 31}, {249, 201, 50}, {245, 217, 73},
    {242, 232, 101}, {243, 245, 134}, {252, 255, 164},
}};

constexpr Table33 kMagma{{
    {0, 0, 4}, {3, 3, 18}, {10, 8, 34}, {19, 13, 52}, {29, 17, 71}, {41, 17, 90},
    {54, 16, 107}, {68, 15, 118}, {81, 18, 124}, {93, 23, 127}, {106, 28, 129}, {118, 33, 129},
    {131, 38, 129}, {144, 42, 129}, {156, 46, 127}, {170, 51, 125}, {183, 55, 121}, {194, 59, 117},
    {207, 64, 112}, {219, 71, 106}, {229, 80, 100}, {238, 91, 94}, {244, 105, 92}, {249, 120, 93},
    {251, 135, 97}, {253, 150, 104}, {254, 165, 113}, {254, 180, 123}, {254, 194, 135}, {254, 209, 148},
    {253, 224, 161}, {252, 238, 176}, {252, 253, 191},
}};

constexpr Table33 kTurbo{{
    {48, 18, 59}, {57, 42, 115}, {64, 64, 162}, {68, 86, 199}, {70, 107, 227}, {70, 128, 246},
    {66, 148, 255}, {55, 168, 250}, {40, 188, 235}, {28, 205, 216}, {24, 221, 194}, {31, 233, 175},
    {50, 242, 152}, {78, 249, 125}, {109, 254, 98}, {139, 255, 75}, {164, 252, 60}, {183, 247, 53},
    {203, 237, 52}, {221, 224, 55}, {236, 209, 58}, {247, 193, 58}, {253, 174, 53}, {254, 153, 44},
    {251, 129, 34}, {245, 105, 24}, {236, 83, 15}, {225, 65, 9}, {210, 49, 5}, {193, 35, 2},
    {172, 23, 1}, {149, 13, 1}, {122, 4, 3},
}};

constexpr Table33 kCoolwarm{{
    {59, 76, 192}, {68, 90, 204}, {77, 104, 215}, {87, 117, 225}, {98, 130, 234}, {108, 142, 241},
    {119, 154, 247}, {130, 165, 251}, {141, 176, 254}, {152, 185, 255}, {163, 194, 255}, {174, 201, 253},
    {184, 208, 249}, {194, 213, 244}, {204, 217, 238}, {213, 219, 230}, {221, 221, 221}, {229, 216, 209},
    {236, 211, 197}, {241, 204, 185}, {245, 196, 173}, {247, 187, 160}, {247, 177, 148}, {247, 166, 135},
    {244, 154, 123}, {241, 141, 111}, {236, 127, 99}, {229, 112, 88}, {222, 96, 77}, {213, 80, 66},
    {203, 62, 56}, {192, 40, 47}, {180, 4, 38},
}};

constexpr auto kViridisStops = even_stops(kViridis);
constexpr auto kPlasmaStops = even_stops(kPlasma);
constexpr auto kInfernoStops = even_stops(kInferno);
constexpr auto kMagmaStops = even_stops(kMagma);
constexpr auto kTurboStops = even_stops(kTurbo);
constexpr auto kCoolwarmStops = even_stops(kCoolwarm);

constexpr std::array<ColorStop, 12> kJetStops{{
    {0.0f, {0, 0, 128}},
    {0.11f, {0, 0, 255}},
    {0.125f, {0, 0, 255}},
    {0.34f, {0, 219, 255}},
    {0.35f, {0, 229, 247}},
    {0.375f, {21, 255, 226}},
    {0.64f, {239, 255, 8}},
    {0.65f, {247, 246, 0}},
    {0.66f, {255, 236, 0}},
    {0.89f, {255, 19, 0}},
    {0.91f, {232, 0, 0}},
    {1.0f, {128, 0, 0}},
}};

constexpr std::array<ColorStop, 2> kGreyStops{{{0.0f, {0, 0, 0}}, {1.0f, {255, 255, 255}}}};

struct Named {
  std::string_view name;
  std::span<const ColorStop> stops;
};

const std::array<Named, 8> kMaps{{
    {"viridis", kViridisStops},
    {"plasma", kPlasmaStops},
    {"inferno", kInfernoStops},
    {"magma", kMagmaStops},
    {"turbo", kTurboStops},
    {"coolwarm", kCoolwarmStops},
    {"jet", kJetStops},
    {"grey", kGreyStops},
}};

}  // namespace

glm::u8vec3 Colormap::map(double t) const {
  if (!(t > 0.0)) return stops_.front().rgb;  // also NaN
  if (t >= 1.0) return stops_.back().rgb;
  // The first stop beyond t; stops_[0].t == 0 < t, so i >= 1.
  const auto it = std::upper_bound(stops_.begin(), stops_.end(), t,
                                   [](double x, const ColorStop& s) { return x < static_cast<double>(s.t); });
  const ColorStop& b = *it;
  const ColorStop& a = *(it - 1);
  const double f = (t - a.t) / (static_cast<double>(b.t) - a.t);
  glm::u8vec3 out;
  for (int c = 0; c < 3; ++c) {
    out[c] = static_cast<std::uint8_t>(std::lround(a.rgb[c] + f * (static_cast<double>(b.rgb[c]) - a.rgb[c])));
  }
  return out;
}

Colormap colormap_by_name(std::string_view name) {
  const std::string_view wanted = name == "gray" ? std::string_view("grey") : name;
  for (const Named& m : kMaps) {
    if (m.name == wanted) return Colormap(m.name, m.stops);
  }
  std::string known;
  for (const Named& m : kMaps) known += (known.empty() ? "" : ", ") + std::string(m.name);
  if (is_categorical(name)) throw std::invalid_argument("'categorical' is a colour scheme for index fields, not a colour map");
  throw std::invalid_argument("unknown colour map '" + std::string(name) + "' (known: " + known + ", gray, " +
                              std::string(kCategorical) + ")");
}

glm::u8vec3 category_color(std::int64_t k) {
  // tab20's pairs (dark, light) as matplotlib lists them: blue, orange, green, red, purple,
  // brown, pink, grey, olive, cyan.
  static constexpr std::array<glm::u8vec3, 20> kTab20{{
      {31, 119, 180}, {174, 199, 232}, {255, 127, 14}, {255, 187, 120}, {44, 160, 44},
      {152, 223, 138}, {214, 39, 40}, {255, 152, 150}, {148, 103, 189}, {197, 176, 213},
      {140, 86, 75}, {196, 156, 148}, {227, 119, 194}, {247, 182, 210}, {127, 127, 127},
      {199, 199, 199}, {188, 189, 34}, {219, 219, 141}, {23, 190, 207}, {158, 218, 229},
  }};
  const std::int64_t i = ((k - 1) % 20 + 20) % 20;  // 0..19
  // Darks first (tab20's even entries), then lights.
  return kTab20[static_cast<std::size_t>(i < 10 ? 2 * i : 2 * (i - 10) + 1)];
}

std::vector<std::string> colormap_names() {
  std::vector<std::string> names;
  for (const Named& m : kMaps) names.emplace_back(m.name);
  return names;
}

}  // namespace terravol::volume
