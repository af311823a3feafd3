// `terravol export-map --volume V.vdb [--field F] (--agl H | --alt H) [--dem DEM...]
// [--colormap NAME] [--range LO:HI] -o OUT.tif|OUT.kmz`: a volume's values on a surface of
// constant height, as a map for GIS tools. A GeoTIFF holds the values themselves (float32,
// EPSG:4326, io/geotiff_write.h); a KMZ holds them colour-mapped with a legend
// (io/kmz_write.h, app/output/map_images.h). The values are volume/surface_raster.h's.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <set>
#include <string>
#include <vector>

#include "app/cli/commands.h"
#include "app/scene/ground_grid.h"
#include "app/output/map_images.h"
#include "app/output/write_file.h"
#include "io/geotiff_write.h"
#include "io/kmz_write.h"
#include "io/mosaic.h"
#include "volume/plan.h"
#include "volume/readers.h"
#include "volume/surface_raster.h"

namespace terravol::app::cli {

namespace {

struct ExportMapOptions {
  std::filesystem::path volume, output;
  std::string field, frame;
  std::optional<double> agl, alt;
  std::vector<std::filesystem::path> dems;
  std::string colormap, range;
  bool force = false;
};

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

std::string lower_extension(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// "LO:HI", either side empty to keep the default.
std::pair<std::optional<double>, std::optional<double>> parse_range(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos) {
    throw std::runtime_error("--range " + text + ": expected LO:HI, e.g. -140:-60");
  }
  auto side = [&](std::string_view s) -> std::optional<double> {
    if (s.empty()) return std::nullopt;
    double v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) {
      throw std::runtime_error("--range " + text + ": '" + std::string(s) + "' is not a number");
    }
    return v;
  };
  const std::string_view all(text);
  return {side(all.substr(0, colon)), side(all.substr(colon + 1))};
}

// What the lattice's third axis spans, in words, for "the surface lies outside" messages.
std::string height_extent(const volume::Volume& v) {
  const volume::Lattice& l = v.lattice;
  const std::string span = fmt(l.origin[2]) + " .. " + fmt(l.world(2, l.dims[2] - 1)) + " m";
  if (v.frame.kind == volume::FrameKind::kEnu) return "up " + span + " about its ENU origin";
  return (v.frame.height == volume::HeightRef::kGround ? "heights above ground " : "heights above the datum ") + span;
}

void run_export_map(const ExportMapOptions& o) {
  const std::string out = o.output.string();
  const std::string ext = lower_extension(o.output);
  const bool kmz = ext == ".kmz";
  if (!kmz && ext != ".tif" && ext != ".tiff") throw std::runtime_error("-o " + out + ": expected a .tif, .tiff or .kmz file name");
  if (!o.agl == !o.alt) {
    throw std::runtime_error("give the surface: one of --agl H (metres above ground) or --alt H (metres above the datum)");
  }
  if (!kmz && (!o.colormap.empty() || !o.range.empty())) {
    throw std::runtime_error("--colormap and --range colour a .kmz; a GeoTIFF holds the values themselves");
  }
  const bool categorical = volume::is_categorical(o.colormap);
  if (categorical && !o.range.empty()) throw std::runtime_error("--range: a categorical map colours each index, it has no range");
  const volume::Colormap colormap = [&] {
    try {
      return volume::colormap_by_name(o.colormap.empty() || categorical ? "viridis" : o.colormap);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error("--colormap " + o.colormap + ": " + e.what());
    }
  }();
  const auto range = o.range.empty() ? std::pair<std::optional<double>, std::optional<double>>{} : parse_range(o.range);
  if (!o.force && std::filesystem::exists(o.output)) throw std::runtime_error(out + ": exists (use --force to overwrite)");
  const auto folder = o.output.parent_path();
  if (!folder.empty() && !std::filesystem::is_directory(folder)) {
    throw std::runtime_error("-o " + out + ": folder " + folder.string() + " does not exist");
  }
  const volume::SurfaceHeight surface{o.agl ? volume::HeightRef::kGround : volume::HeightRef::kDatum, o.agl ? *o.agl : *o.alt};
  const std::string surface_option = (o.agl ? "--agl " : "--alt ") + fmt(surface.metres);
  if (!std::isfinite(surface.metres)) throw std::runtime_error(surface_option + ": must be finite");

  volume::ReadOptions read;
  read.field = o.field;
  if (!o.frame.empty()) {
    try {
      read.frame = volume::parse_frame(o.frame);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(std::string("--frame ") + e.what());
    }
  }
  const volume::Volume v = volume::read_volume(o.volume, read);
  const std::string source = o.volume.string();
  if (v.frame.kind == volume::FrameKind::kNone) {
    throw std::runtime_error(source + ": the volume does not say where it lies; give --frame (geographic, geographic-agl or enu:LAT,LON,H)");
  }
  io::GeoRaster raster;
  try {
    raster = volume::footprint_raster(v);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(source + ": " + e.what());
  }

  // The ground, only where the surface's height and the volume's are measured differently.
  std::unique_ptr<scene::GroundGrid> ground;
  if (volume::needs_ground(v, surface)) {
    if (o.dems.empty()) {
      throw std::runtime_error(surface_option + ": the volume's " + height_extent(v) +
                               ", so this surface needs the ground under it: give --dem DEM...");
    }
    const io::Mosaic mosaic = io::Mosaic::open(o.dems);
    ground = std::make_unique<scene::GroundGrid>(mosaic, raster.south(), raster.north, raster.west, raster.east());
  }
  const volume::GroundFunction ground_function =
      ground ? volume::GroundFunction([&](double lat, double lon) { return (*ground)(lat, lon); }) : volume::GroundFunction{};
  const std::size_t filled = volume::sample_surface(v, surface, ground_function, raster);
  if (filled == 0) {
    throw std::runtime_error(surface_option + ": the surface lies outside the volume '" + v.name + "' (" + height_extent(v) +
                             "), or meets only points without a value");
  }

  float vmin = std::numeric_limits<float>::infinity(), vmax = -vmin;
  for (const float x : raster.values) {
    if (!std::isfinite(x)) continue;
    vmin = std::min(vmin, x);
    vmax = std::max(vmax, x);
  }
  const std::string units = v.units.empty() ? "" : " (" + v.units + ")";
  const std::string where = fmt(surface.metres) + (o.agl ? " m above ground" : " m above the datum");
  const std::string description = v.name + units + " at " + where + ", from " + o.volume.filename().string();
  std::vector<std::uint8_t> bytes;
  double lo = vmin, hi = vmax;
  if (kmz) {
    lo = range.first.value_or(vmin);
    hi = range.second.value_or(vmax);
    io::KmzMap map;
    map.name = v.name + " at " + where;
    map.description = description + "; colours: " + std::string(colormap.name()) + " over " + fmt(lo) + " .. " + fmt(hi) + units;
    map.north = raster.north;
    map.south = raster.south();
    map.west = raster.west;
    map.east = raster.east();
    if (categorical) {
      // One swatch per category present, named after the transmitter the volume records for it.
      const std::vector<volume::RecordedTransmitter> tx = volume::recorded_transmitters(v);
      std::set<std::int64_t> present;
      for (const float x : raster.values)
        if (std::isfinite(x)) present.insert(std::llround(x));
      std::vector<output::MapCategory> categories;
      for (const std::int64_t k : present) {
        const bool named = k >= 1 && static_cast<std::size_t>(k) <= tx.size();
        categories.push_back({k, named ? tx[static_cast<std::size_t>(k) - 1].name : std::to_string(k)});
      }
      map.description = description + "; colours: one per category (tab20)";
      map.overlay_png = output::category_overlay_png(raster);
      map.legend_png = output::category_legend_png(v.name, where, tx.empty() ? "categories" : "transmitters", categories);
    } else {
      map.overlay_png = output::overlay_png(raster, colormap, lo, hi);
      map.legend_png = output::legend_png(colormap, {v.name + units, where, lo, hi});
    }
    bytes = io::encode_kmz(map);
  } else {
    bytes = io::encode_geotiff(raster, {description, v.units});
  }
  output::write_file_atomically(o.output, bytes, o.force);
  const std::string colours = !kmz         ? ""
                              : categorical ? ", coloured by category"
                                            : ", coloured " + std::string(colormap.name()) + " over " + fmt(lo) + " .. " + fmt(hi);
  std::printf("%s: %d x %d pixels of %.4g\" x %.4g\", %.6f .. %.6f N, %.6f .. %.6f E; %zu with values, %g .. %g%s%s\n",
              out.c_str(), raster.cols, raster.rows, raster.dlon * 3600.0, raster.dlat * 3600.0, raster.south(),
              raster.north, raster.west, raster.east(), filled, vmin, vmax, units.c_str(), colours.c_str());
}

}  // namespace

void add_export_map_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "export-map",
      "Write a volume's values on a surface of constant height as a GeoTIFF (float32, EPSG:4326) or a KMZ "
      "(colour-mapped ground overlay and legend) for GIS tools");
  auto o = std::make_shared<ExportMapOptions>();
  cmd->add_option("--volume", o->volume, "The volume (.vdb, .vti, .vtk)")->required();
  cmd->add_option("--field", o->field, "The grid (.vdb) or array (.vti/.vtk) to map; default: the first");
  cmd->add_option("--frame", o->frame, "Where a volume without frame metadata lies: geographic, geographic-agl, enu:LAT,LON,H");
  cmd->add_option("--agl", o->agl, "The surface: metres above the ground");
  cmd->add_option("--alt", o->alt, "The surface: metres above the vertical datum");
  cmd->add_option("--dem", o->dems,
                  "DEM files or folders (one mosaic): the ground, needed when the surface's height is measured from "
                  "another reference than the volume's (--agl on a volume above the datum, --alt on a terrain-following one)");
  cmd->add_option("--colormap", o->colormap, "KMZ only: the colour map (viridis, plasma, inferno, magma, turbo, coolwarm, jet, grey), or categorical for index fields such as best_server");
  cmd->add_option("--range", o->range, "KMZ only: LO:HI, the values at the colour map's ends; default: the map's minimum and maximum");
  cmd->add_option("-o,--output", o->output, "OUT.tif (or .tiff) or OUT.kmz")->required();
  cmd->add_flag("--force", o->force, "Replace an existing output file");
  cmd->callback([o] { run_export_map(*o); });
}

}  // namespace terravol::app::cli
