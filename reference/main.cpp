// terravol_reference: the independent reference image of one render (reference/check.h), for a
// person checking a view by hand. Run the real command first, then this one:
//   terravol render --scene S.json --full-res --surface-triangles 0 --haze 0 --no-markers
//       --export-vtp drawn.vtp --stats stats.json -o ours.png [--camera ...] [--background R,G,B]
//   terravol_reference --scene S.json --drawn drawn.vtp --stats stats.json -o reference.png
//       --against ours.png --diff difference.png
// prints the share of pixels within 8/255 and 3/255 of the reference.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <filesystem>

#include "reference/check.h"

int main(int argc, char** argv) {
  namespace ref = terravol::reference;
  CLI::App app{"The independent reference image of a terravol render (issue 11): the exported terrain, the "
               "volumes and objects rebuilt from their files, VTK depth peeling without a peel limit"};
  std::filesystem::path scene, drawn, stats, output, against, diff;
  bool force = false;
  app.add_option("--scene", scene, "The scene file the render drew")->required();
  app.add_option("--drawn", drawn, "The render's --export-vtp file")->required();
  app.add_option("--stats", stats, "The render's --stats file")->required();
  app.add_option("-o,--output", output, "PNG of the reference to write");
  app.add_option("--against", against, "The render's PNG: print how many pixels agree with the reference");
  app.add_option("--diff", diff, "With --against: PNG of the pixels more than 8/255 off (red)");
  app.add_flag("--force", force, "Replace existing output files");
  try {
    app.parse(argc, argv);
    for (const auto* p : {&output, &diff})
      if (!p->empty() && !force && std::filesystem::exists(*p))
        throw std::runtime_error(p->string() + ": exists (use --force to overwrite)");
    if (!diff.empty() && against.empty()) throw std::runtime_error("--diff needs --against");
    ref::require_display();
    const ref::Reference r = ref::reference_image(scene, drawn, stats);
    std::printf("reference: %zu terrain and %zu crack-fill triangles exported, %zu volume and %zu object triangles "
                "rebuilt (%zu merged pieces were drawn); %.0f ms to rebuild, %.0f ms to draw\n",
                r.drawn.terrain_triangles, r.drawn.skirt_triangles, r.volume_triangles, r.object_triangles,
                r.drawn.merged_triangles, r.geometry_ms, r.draw_ms);
    if (!output.empty()) ref::write_png(output, r.image);
    if (!against.empty()) {
      const ref::Image ours = ref::read_png(against);
      std::printf("%s: %.4f%% of pixels within 8/255 of the reference, %.4f%% within 3/255\n", against.c_str(),
                  100.0 * ref::share_within(r.image, ours, 8), 100.0 * ref::share_within(r.image, ours, 3));
      if (!diff.empty()) ref::write_png(diff, ref::difference_image(r.image, ours, 8));
    }
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "terravol_reference: %s\n", e.what());
    return 1;
  }
  return 0;
}
