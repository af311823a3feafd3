// `terravol compare-volumes A B [--field NAME]`: B resampled to A's lattice points
// (volume/compare.h), per layer of A: points, Pearson correlation, median difference (B - A)
// and median absolute difference.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "app/cli/commands.h"
#include "volume/compare.h"
#include "volume/readers.h"

namespace terravol::app::cli {

namespace {

struct CompareOptions {
  std::filesystem::path a, b;
  std::string field = "path_loss_db", field_b;
};

std::string describe(const volume::Volume& v) {
  const auto& l = v.lattice;
  char b[200];
  std::snprintf(b, sizeof b, "%s%s%s, %d x %d x %d points, spacing %g\" x %g\" x %g",
                v.name.c_str(), v.units.empty() ? "" : " in ", v.units.c_str(), l.dims[0],
                l.dims[1], l.dims[2], l.spacing[0] * 3600.0, l.spacing[1] * 3600.0, l.spacing[2]);
  return b;
}

void print_row(const char* label, const volume::LayerComparison& c) {
  std::printf("%10s %9zu %8.3f %9.2f %9.2f %9.2f %9.2f\n", label, c.points, c.pearson,
              c.median_difference, c.median_abs_difference, c.median_a, c.median_b);
}

void run_compare(const CompareOptions& o) {
  volume::ReadOptions ra, rb;
  ra.field = o.field;
  rb.field = o.field_b.empty() ? o.field : o.field_b;
  const volume::Volume a = volume::read_volume(o.a, ra);
  const volume::Volume b = volume::read_volume(o.b, rb);
  volume::Comparison c;
  try {
    c = volume::compare_volumes(a, b);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(o.a.string() + ", " + o.b.string() + ": " + e.what());
  }
  if (c.all.points == 0) {
    throw std::runtime_error(
        o.a.string() + ", " + o.b.string() +
        ": no lattice point of A has a value in B (the volumes do not overlap)");
  }
  const bool geographic = a.frame.kind == volume::FrameKind::kGeographic;
  const char* height = !geographic                                    ? "w2"
                       : a.frame.height == volume::HeightRef::kGround ? "agl_m"
                                                                      : "height_m";
  std::printf("A: %s (%s)\n", o.a.string().c_str(), describe(a).c_str());
  std::printf("B: %s (%s), resampled to A's points (trilinear)\n", o.b.string().c_str(),
              describe(b).c_str());
  std::printf("%10s %9s %8s %9s %9s %9s %9s\n", height, "points", "pearson", "med(B-A)", "med|B-A|",
              "med A", "med B");
  for (const auto& layer : c.layers) {
    char label[32];
    std::snprintf(label, sizeof label, "%g", layer.w2);
    print_row(label, layer);
  }
  print_row("all", c.all);
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "compare-volumes",
      "Compare volume B with volume A on A's lattice points (B resampled trilinearly where both "
      "have values): per "
      "layer of A, points, Pearson correlation, median and median absolute difference");
  auto o = std::make_shared<CompareOptions>();
  cmd->add_option("A", o->a, "The reference volume (.vdb, .vti, .vtk)")->required();
  cmd->add_option("B", o->b, "The volume compared with it")->required();
  cmd->add_option("--field", o->field, "The grid or array to compare")->capture_default_str();
  cmd->add_option("--field-b", o->field_b, "B's grid or array, when it differs from --field");
  cmd->callback([o] { run_compare(*o); });
}

}  // namespace terravol::app::cli
