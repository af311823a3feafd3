// Levels of detail of a model (Wiley et al. 1997, section 6: "a set of LOD models"), made by
// VTK, each with its geometric error for the screen-space-error metric.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "volume/geometry.h"

namespace terravol::objects {

enum class LodMethod : std::uint8_t {
  // Vertex clustering (vtkQuadricClustering: each bin's vertex where it minimises the bin's
  // quadric error, P. Lindstrom, SIGGRAPH 2000), the paper's kind of method (it used
  // Schaufler and Stürzlinger's hierarchical clustering): cubic bins sized for the budget.
  kClustering,
  // Edge collapse with quadric error (vtkQuadricDecimation, Garland and Heckbert 1997),
  // colours as an attribute in the error, volume preserved; where it stops more than half as
  // many triangles again above the budget (it keeps open boundaries, and models made of many
  // separate parts or seams have many: the milk truck's decimation stops at 665 of its 3,624
  // triangles), kClustering's result instead.
  kDecimation,
};

struct LodOptions {
  int levels = 5;              // at most this many levels, the full model included (>= 1)
  double ratio = 0.25;         // each level's triangle budget: the previous level's budget times this, (0, 1)
  std::size_t min_triangles = 12;  // no level below this many triangles
  LodMethod method = LodMethod::kDecimation;
};

struct Lod {
  volume::Mesh mesh;  // the model's frame, as the full model
  // Hausdorff distance to the full model (model units): the larger of the two one-sided
  // distances, each measured from points sampled on one surface (every vertex, points along
  // every edge and over every triangle, about 1/50 of the model's bounding-box diagonal apart:
  // vtkPolyDataPointSampler) to the other surface (its closest point: vtkStaticCellLocator),
  // so it may miss a farthest point between samples by up to that spacing. 0 for the full model.
  double hausdorff = 0.0;
  // The screen-space-error metric's error: the largest hausdorff of this level and every finer
  // one, so that a coarser level never claims less error than a finer one (a reduction's
  // Hausdorff distance need not grow with the reduction: the Wuson model's level 4 measures
  // 0.64 against level 3's 0.67).
  double error = 0.0;
};

// The levels of `full`: level 0 is `full` itself (error 0), level k about ratio^k of its
// triangles by `method` (kDecimation's counts are VTK's target reductions, approximate;
// kClustering's the nearest its bin sizes reach). Levels stop early when the next would have
// fewer than min_triangles triangles or would not reduce the previous one. Colours of reduced
// levels: the nearest full-model vertex's (clustering) or interpolated by the decimation.
// Throws std::invalid_argument for an empty mesh or options out of range.
std::vector<Lod> make_lods(const volume::Mesh& full, const LodOptions& options = {});

// The Hausdorff distance between two non-empty meshes as Lod::hausdorff measures it, with samples
// `spacing` apart (> 0; 0: 1/50 of the union's bounding-box diagonal).
double hausdorff_distance(const volume::Mesh& a, const volume::Mesh& b, double spacing = 0.0);

// The model's colour cube (Chamberlain et al. 1995, "clusters of small objects" drawn as one
// coloured box): its axis-aligned bounding box as 12 triangles, each face coloured with the
// area-weighted mean colour (and alpha) of the model's triangles whose normals point most
// nearly that way (a face no triangle faces takes the mean of all). Throws
// std::invalid_argument for an empty mesh.
volume::Mesh color_cube(const volume::Mesh& full);

}  // namespace terravol::objects
