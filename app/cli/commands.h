// The subcommands of terravol. Each add_* registers its options and callback on the app;
// callbacks throw (FormatError, std::exception) and main() turns that into a one-line
// message and exit status 1.
#pragma once

#include <CLI/CLI.hpp>

namespace terravol::app::cli {

void add_info_command(CLI::App& app);        // terravol info PATH... [--json]
void add_sample_dem_command(CLI::App& app);  // terravol sample-dem -o DIR
void add_render_command(CLI::App& app);      // terravol render DEM... --camera ... -o PNG
void add_view_command(CLI::App& app);        // terravol view DEM... (interactive)
void add_rf_command(CLI::App& app);          // terravol rf --tx ... --dem DEM... -o out.vdb
void add_fly_command(CLI::App& app);         // terravol fly PATH.json -o out.mp4|frames/
void add_splat_command(CLI::App& app);       // terravol splat-volume --tx ... --sdf DIR -o out.vdb
void add_compare_command(CLI::App& app);     // terravol compare-volumes A.vdb B.vdb
void add_image_diff_command(CLI::App& app);   // terravol compare-images A.png B.png
void add_export_map_command(CLI::App& app);  // terravol export-map --volume V.vdb --agl H -o OUT.tif|.kmz
void add_profile_command(CLI::App& app);      // terravol profile --from ... --to ... --dem DEM...
void add_query_command(CLI::App& app);        // terravol query --volume V.vdb --dem DEM... --at ...

}  // namespace terravol::app::cli
