// The colour-cube octree against the independent ray marcher (reference/density.h), in
// software: the refined boxes blended as GL blends them (density_test_util.h), the same view
// marched through the lattice in 20 m steps. The figures are the GL renders' (the
// render tests and `terravol bench --suites density`); these check the approximation itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>

#include "density/octree.h"
#include "density_test_util.h"
#include "io/scene_frame.h"
#include "reference/density.h"
#include "reference/frame.h"

namespace terravol::density {
namespace {

reference::FootprintError compare(const std::vector<glm::vec4>& ours, const reference::MarchedImage& marched) {
  return reference::footprint_error(marched, [&](std::size_t p) {
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(static_cast<double>(ours[p][c]) - marched.rgba[p][c]) * 255.0);
    return worst;
  });
}

TEST(DensityReference, ColourCubesAgreeWithTheRayMarcherFromNearAndFar) {
  const io::SceneFrame frame(45.0, 6.0);
  const reference::Frame ref_frame(45.0, 6.0);
  const volume::Volume v = test::path_loss_volume(41, 33, 13, false);
  const DensitySpec spec = parse_density("range=80:150,colormap=viridis,opacity=0.6,ramp=down");
  const ColorCubeOctree over(v, frame, {}, spec), cover(v, frame, {}, spec, BuildOptions{Compositing::kCoverage});
  const reference::DensityField field(v, ref_frame, {});
  const reference::DensityTransfer transfer{spec.lo, spec.hi, spec.colormap, spec.sigma_per_km, "down"};
  const BoxGrid& g = over.grid();
  const glm::dvec3 extent = g.size * glm::dvec3(g.boxes[0], g.boxes[1], g.boxes[2]);
  const glm::dvec3 centre = g.origin + 0.5 * extent;
  const double radius = 0.5 * glm::length(extent);
  const glm::dvec3 dir = glm::normalize(glm::dvec3(-0.55, -0.7, 0.45));
  for (const double epsilon : {1.0, 4.0})
  for (const double d : {1.75, 3.5, 7.0, 14.0}) {
    mrbsp::Camera c;
    c.eye = centre + d * radius * dir;
    c.forward = -dir;
    c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
    c.width = 480;
    c.height = 270;
    c.fov_y_deg = 45.0;
    reference::MarchCamera mc{c.eye, c.forward, c.up, c.fov_y_deg, c.width, c.height};
    const reference::MarchedImage marched = reference::march_density(field, transfer, mc, 20.0, [](double, double) {
      return -std::numeric_limits<double>::infinity();
    });
    reference::FootprintError e[2];
    for (int variant = 0; variant < 2; ++variant) {
      std::vector<mrbsp::ColorBox> boxes;
      RefineStats stats;
      (variant == 0 ? over : cover).refine(c, RefineOptions{epsilon, false, true}, boxes, stats);
      e[variant] = compare(test::composite_boxes(boxes, c.eye, c.forward, c.up, c.fov_y_deg, c.width, c.height), marched);
      if (variant == 0) {
        std::printf("epsilon %g, %.2f radii: boxes per level", epsilon, d);
        for (std::size_t l = 0; l < stats.per_level.size(); ++l) std::printf(" %zu", stats.per_level[l]);
        std::printf("\n");
      }
    }
    EXPECT_GT(e[0].pixels, 500u);
    if (epsilon == 1.0) {  // the targets at the default epsilon: mean <= 2/255, 99th percentile <= 16/255
      EXPECT_LE(e[0].mean, 2.0) << d << " radii";
      EXPECT_LE(e[0].p99, 16.0) << d << " radii";
      // With the commands' error tolerance (1/255; cells up to 32 px): the same targets.
      RefineOptions tolerant{epsilon, false, true};
      tolerant.error_tolerance = 1.0 / 255.0;
      std::vector<mrbsp::ColorBox> boxes;
      RefineStats stats;
      over.refine(c, tolerant, boxes, stats);
      const reference::FootprintError t = compare(test::composite_boxes(boxes, c.eye, c.forward, c.up, c.fov_y_deg, c.width, c.height), marched);
      EXPECT_LE(t.mean, 2.0) << d << " radii, tolerance 1";
      EXPECT_LE(t.p99, 16.0) << d << " radii, tolerance 1";
      std::printf("%.2f radii, tolerance 1/255: %zu boxes, mean %.2f p99 %.1f\n", d, boxes.size(), t.mean, t.p99);
    } else {  // coarse cells drawn: the default (1996's over) is the closer one
      EXPECT_LE(e[0].mean, e[1].mean) << d << " radii";
      EXPECT_LE(e[0].mean, 4.5) << d << " radii";
    }
    std::printf("%.2f radii: over mean %.2f p99 %.1f, coverage mean %.2f p99 %.1f (1/255, %zu pixels)\n", d, e[0].mean, e[0].p99,
                e[1].mean, e[1].p99, e[0].pixels);
  }
}

}  // namespace
}  // namespace terravol::density
