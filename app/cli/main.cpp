// terravol: the command line. Library code throws; only this file decides to exit.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

#include "app/cli/commands.h"
#include "app/cli/mpi_session.h"
#include "bench/bench_command.h"
#include "io/error.h"

int main(int argc, char** argv) {
  CLI::App app{
      "Terravol: terrain (SRTM, DTED, USGS DEM, ESRI ASCII, GeoTIFF, SPLAT! SDF) and RF "
      "propagation volumes, drawn through a Multiresolution BSP tree."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "terravol 0.1");
  terravol::app::cli::add_info_command(app);
  terravol::app::cli::add_sample_dem_command(app);
  terravol::app::cli::add_render_command(app);
  terravol::app::cli::add_view_command(app);
  terravol::app::cli::add_rf_command(app);
  terravol::app::cli::add_fly_command(app);
  terravol::app::cli::add_splat_command(app);
  terravol::app::cli::add_compare_command(app);
  terravol::app::cli::add_image_diff_command(app);
  terravol::app::cli::add_export_map_command(app);
  terravol::app::cli::add_profile_command(app);
  terravol::app::cli::add_query_command(app);
  terravol::bench::add_bench_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version as CLI11 prints them; a bad command line in one line, status 1.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    std::fprintf(stderr, "terravol: %s\n", e.what());
    return 1;
  } catch (const terravol::app::cli::QuietFailure&) {
    return 1;  // another MPI rank printed why
  } catch (const terravol::io::FormatError& e) {
    std::fprintf(stderr, "terravol: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "terravol: %s\n", e.what());
    return 1;
  }
  return 0;
}
