// `terravol info PATH...`: what each DEM holds, and the mosaic they form.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/cli/commands.h"
#include "io/compressed.h"
#include "io/dem_file.h"
#include "io/error.h"
#include "io/geographic.h"
#include "io/mosaic.h"
#include "io/void_fill.h"

namespace terravol::app::cli {

namespace {

using nlohmann::ordered_json;

struct Bounds {
  double south, north, west, east;  // degrees, of the sample points
};

Bounds bounds_of(const io::Georef& g, int rows, int cols) {
  return {g.y0 - (rows - 1) * g.dy, g.y0, g.x0, g.x0 + (cols - 1) * g.dx};
}

std::string format_name(const std::string& f) {
  if (f == "srtm") return "SRTM .hgt";
  if (f == "dted") return "DTED";
  if (f == "usgs-dem") return "USGS ASCII DEM";
  if (f == "esri-ascii") return "ESRI ASCII grid";
  if (f == "geotiff") return "GeoTIFF";
  if (f == "sdf") return "SPLAT! SDF";
  return f;
}

std::string lat_str(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6f %c", std::abs(v), v < 0 ? 'S' : 'N');
  return b;
}
std::string lon_str(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6f %c", std::abs(v), v < 0 ? 'W' : 'E');
  return b;
}

// Everything info says about one source.
ordered_json describe(const std::filesystem::path& path, const io::ReadOptions& options) {
  io::Grid native = io::read_dem(path, options);
  const std::size_t voids = io::count(native, io::Sample::kVoid);
  const std::size_t outside = io::count(native, io::Sample::kOutside);
  const auto range = io::height_range(native);
  ordered_json j;
  j["path"] = path.string();
  j["format"] = native.format;
  j["compression"] = io::compression_label(io::compression_from_name(path.filename().string()));
  j["rows"] = native.rows;
  j["cols"] = native.cols;
  j["valid_samples"] = io::count(native, io::Sample::kValid);
  j["vertical_datum"] = native.vertical_datum;
  if (native.georef.crs == io::Crs::kUtm) {
    const auto& g = native.georef;
    ordered_json p;
    p["crs"] = "utm";
    p["zone"] = g.utm_zone;
    p["hemisphere"] = g.utm_north ? "N" : "S";
    p["epsg"] = (g.utm_north ? 32600 : 32700) + g.utm_zone;
    p["spacing_m"] = {g.dx, g.dy};
    p["easting"] = {g.x0, g.x0 + (native.cols - 1) * g.dx};
    p["northing"] = {g.y0 - (native.rows - 1) * g.dy, g.y0};
    p["outside_samples"] = outside;
    j["projection"] = p;
  }
  const bool projected = native.georef.crs != io::Crs::kGeographic;
  io::Grid geo = projected ? io::to_geographic(native, path.string()) : std::move(native);
  if (projected) {
    j["geographic_rows"] = geo.rows;
    j["geographic_cols"] = geo.cols;
  }
  const Bounds b = bounds_of(geo.georef, geo.rows, geo.cols);
  j["south"] = b.south;
  j["north"] = b.north;
  j["west"] = b.west;
  j["east"] = b.east;
  j["min_elevation"] = range.min;
  j["max_elevation"] = range.max;
  j["voids"] = voids;
  j["spacing_arcsec"] = {geo.georef.dx * 3600.0, geo.georef.dy * 3600.0};
  j["checksum_errors"] = geo.checksum_errors;
  j["filled"] = io::fill_voids(geo);
  j["notes"] = geo.notes;
  return j;
}

void print_text(const ordered_json& j, const std::string& title) {
  std::printf("%s\n", title.c_str());
  std::printf("  format          %s", format_name(j["format"].get<std::string>()).c_str());
  if (j.contains("compression") && j["compression"] != "uncompressed")
    std::printf(", %s-compressed", j["compression"].get<std::string>().c_str());
  std::printf("\n");
  std::printf("  grid            %d rows x %d cols\n", j["rows"].get<int>(), j["cols"].get<int>());
  if (j.contains("projection")) {
    const auto& p = j["projection"];
    std::printf("  projection      UTM zone %d%s (EPSG:%d), %.6g x %.6g m spacing\n", p["zone"].get<int>(),
                p["hemisphere"].get<std::string>().c_str(), p["epsg"].get<int>(), p["spacing_m"][0].get<double>(),
                p["spacing_m"][1].get<double>());
    std::printf("  projected       easting %.1f .. %.1f m, northing %.1f .. %.1f m\n", p["easting"][0].get<double>(),
                p["easting"][1].get<double>(), p["northing"][0].get<double>(), p["northing"][1].get<double>());
    std::printf("  as geographic   %d rows x %d cols\n", j["geographic_rows"].get<int>(),
                j["geographic_cols"].get<int>());
  }
  std::printf("  spacing         %.4g\" x %.4g\" (lon x lat)\n", j["spacing_arcsec"][0].get<double>(),
              j["spacing_arcsec"][1].get<double>());
  std::printf("  bounds          %s .. %s, %s .. %s\n", lat_str(j["south"]).c_str(), lat_str(j["north"]).c_str(),
              lon_str(j["west"]).c_str(), lon_str(j["east"]).c_str());
  std::printf("  elevation       %g .. %g m\n", j["min_elevation"].get<double>(), j["max_elevation"].get<double>());
  std::printf("  voids           %zu (%zu samples filled for rendering)\n", j["voids"].get<std::size_t>(),
              j["filled"].get<std::size_t>());
  if (j.contains("gap_samples")) {
    std::printf("  gaps            %zu samples in %zu rectangles no tile covers\n", j["gap_samples"].get<std::size_t>(),
                j["gaps"].size());
    for (const auto& g : j["gaps"]) {
      std::printf("                  %s .. %s, %s .. %s\n", lat_str(g["south"]).c_str(), lat_str(g["north"]).c_str(),
                  lon_str(g["west"]).c_str(), lon_str(g["east"]).c_str());
    }
  }
  if (j.contains("checksum_errors") && j["checksum_errors"].get<std::size_t>() > 0)
    std::printf("  checksum errors %zu records (data kept)\n", j["checksum_errors"].get<std::size_t>());
  std::printf("  vertical datum  %s\n", j["vertical_datum"].get<std::string>().c_str());
  if (j.contains("notes"))
    for (const auto& n : j["notes"]) std::printf("  note            %s\n", n.get<std::string>().c_str());
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Describe DEM files and the mosaic they form");
  auto paths = std::make_shared<std::vector<std::filesystem::path>>();
  auto json = std::make_shared<bool>(false);
  auto crs = std::make_shared<std::string>();
  cmd->add_option("paths", *paths, "DEM files or folders of tiles (a folder is one mosaic)")->required();
  cmd->add_flag("--json", *json, "Print one JSON object instead of text");
  cmd->add_option("--crs", *crs, "Projection of ESRI ASCII grids without a .prj, e.g. utm:10N");
  cmd->callback([paths, json, crs] {
    io::ReadOptions options;
    if (!crs->empty()) {
      options.utm = io::parse_utm_zone(*crs);
      if (!options.utm) throw std::runtime_error("--crs " + *crs + ": expected utm:ZONE followed by N or S, e.g. utm:10N");
    }
    // Each input: a file, or a folder whose files are its tiles.
    ordered_json tiles = ordered_json::array();
    std::vector<std::filesystem::path> files;
    for (const auto& p : *paths) {
      std::error_code ec;
      if (std::filesystem::is_directory(p, ec)) {
        const io::Mosaic folder = io::Mosaic::open({p}, options, 1);
        for (const auto& t : folder.tiles()) files.push_back(t.path);
      } else {
        files.push_back(p);
      }
    }
    for (const auto& f : files) tiles.push_back(describe(f, options));

    ordered_json top;
    std::optional<io::Mosaic> mosaic;
    std::string mosaic_error;
    try {
      mosaic = io::Mosaic::open(files, options, 1);
    } catch (const io::FormatError& e) {
      mosaic_error = e.what();
    }
    if (mosaic) {
      std::string format = tiles[0]["format"];
      std::string datum = tiles[0]["vertical_datum"];
      double lo = tiles[0]["min_elevation"], hi = tiles[0]["max_elevation"];
      std::size_t voids = 0, filled = 0;
      for (const auto& t : tiles) {
        if (t["format"] != format) format = "mixed";
        if (t["vertical_datum"] != datum) datum = "mixed";
        lo = std::min(lo, t["min_elevation"].get<double>());
        hi = std::max(hi, t["max_elevation"].get<double>());
        voids += t["voids"].get<std::size_t>();
        filled += t["filled"].get<std::size_t>();
      }
      const Bounds b = bounds_of(mosaic->georef(), mosaic->rows(), mosaic->cols());
      top["format"] = format;
      top["rows"] = mosaic->rows();
      top["cols"] = mosaic->cols();
      top["south"] = b.south;
      top["north"] = b.north;
      top["west"] = b.west;
      top["east"] = b.east;
      top["min_elevation"] = lo;
      top["max_elevation"] = hi;
      top["voids"] = voids;
      top["filled"] = filled;
      top["spacing_arcsec"] = {mosaic->georef().dx * 3600.0, mosaic->georef().dy * 3600.0};
      top["vertical_datum"] = datum;
      top["gap_samples"] = mosaic->gap_samples();
      top["gaps"] = ordered_json::array();
      for (const auto& g : mosaic->gaps()) {
        top["gaps"].push_back({{"south", g.south}, {"north", g.north}, {"west", g.west}, {"east", g.east}, {"rows", g.rows}, {"cols", g.cols}});
      }
    } else {
      top["mosaic_error"] = mosaic_error;
    }
    top["tiles"] = tiles;

    if (*json) {
      std::printf("%s\n", top.dump(2).c_str());
      return;
    }
    for (const auto& t : tiles) print_text(t, t["path"].get<std::string>());
    if (tiles.size() > 1) {
      std::printf("\n");
      if (mosaic) {
        print_text(top, "mosaic of " + std::to_string(tiles.size()) + " tiles");
      } else {
        std::printf("mosaic: none (%s)\n", mosaic_error.c_str());
      }
    }
  });
}

}  // namespace terravol::app::cli
