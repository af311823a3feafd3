// `terravol sample-dem`: writes the project's own small DEM (data/dem/N45E006.hgt), or a
// seamless mosaic of such tiles (app/output/sample_dem.h).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <utility>

#include "app/cli/commands.h"
#include "app/output/sample_dem.h"

namespace terravol::app::cli {

void add_sample_dem_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "sample-dem", "Write the bundled synthetic DEM (an SRTM3 tile, N45E006.hgt) into a folder");
  auto dir = std::make_shared<std::filesystem::path>("data/dem");
  auto force = std::make_shared<bool>(false);
  auto tiles = std::make_shared<std::pair<int, int>>(1, 1);
  cmd->add_option("-o,--output-dir", *dir, "Folder to write N45E006.hgt into")->capture_default_str();
  cmd->add_flag("--force", *force, "Overwrite an existing file");
  cmd->add_option("--tiles", *tiles, "Write a seamless mosaic of ROWSxCOLS tiles from N45E006 north and east (at most 8x8)")
      ->delimiter('x')
      ->check(CLI::Range(1, 8));
  cmd->callback([dir, force, tiles] {
    for (const auto& path : output::write_sample_dem(*dir, tiles->first, tiles->second, *force))
      std::printf("wrote %s\n", path.string().c_str());
  });
}

}  // namespace terravol::app::cli
