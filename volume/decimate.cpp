// Decimation of volume meshes before they are merged into the terrain tree: VTK's quadric
// decimation (Garland and Heckbert 1997), colours carried as a point attribute.
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkQuadricDecimation.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "volume/geometry.h"

namespace terravol::volume {

Mesh decimate(const Mesh& mesh, std::size_t max_triangles) {
  const std::size_t n = mesh.triangle_count();
  if (n <= max_triangles || max_triangles == 0) return mesh;
  // VTK works in doubles about the mesh's centre: the scene frame's metres are large numbers
  // far from its origin, and the quadrics are squared.
  glm::dvec3 centre(0.0);
  for (const auto& v : mesh.vertices) centre += v;
  centre /= static_cast<double>(mesh.vertices.size());
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.vertices.size()));
  vtkNew<vtkFloatArray> rgba;
  rgba->SetNumberOfComponents(4);
  rgba->SetNumberOfTuples(static_cast<vtkIdType>(mesh.vertices.size()));
  for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
    const glm::dvec3 p = mesh.vertices[k] - centre;
    points->SetPoint(static_cast<vtkIdType>(k), p.x, p.y, p.z);
    const glm::u8vec4 c = mesh.colors[k];
    const float t[4] = {float(c.r), float(c.g), float(c.b), float(c.a)};
    rgba->SetTypedTuple(static_cast<vtkIdType>(k), t);
  }
  vtkNew<vtkCellArray> cells;
  for (std::size_t t = 0; t < n; ++t) {
    const vtkIdType ids[3] = {mesh.triangles[3 * t], mesh.triangles[3 * t + 1], mesh.triangles[3 * t + 2]};
    cells->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetPolys(cells);
  poly->GetPointData()->SetScalars(rgba);

  vtkNew<vtkQuadricDecimation> decimation;
  decimation->SetInputData(poly);
  decimation->SetTargetReduction(1.0 - static_cast<double>(max_triangles) / static_cast<double>(n));
  decimation->AttributeErrorMetricOn();  // colours vary across slices: keep their gradients
  decimation->ScalarsAttributeOn();
  decimation->VectorsAttributeOff();
  decimation->NormalsAttributeOff();
  decimation->TCoordsAttributeOff();
  decimation->TensorsAttributeOff();
  decimation->VolumePreservationOn();
  decimation->Update();
  vtkPolyData* out = decimation->GetOutput();

  Mesh result;
  vtkDataArray* colors = out->GetPointData()->GetScalars();
  result.vertices.resize(static_cast<std::size_t>(out->GetNumberOfPoints()));
  result.colors.resize(result.vertices.size());
  for (vtkIdType k = 0; k < out->GetNumberOfPoints(); ++k) {
    double p[3];
    out->GetPoint(k, p);
    result.vertices[static_cast<std::size_t>(k)] = glm::dvec3(p[0], p[1], p[2]) + centre;
    double c[4] = {255, 255, 255, 255};
    if (colors != nullptr && colors->GetNumberOfComponents() == 4) colors->GetTuple(k, c);
    for (int i = 0; i < 4; ++i) {
      result.colors[static_cast<std::size_t>(k)][i] = static_cast<std::uint8_t>(std::clamp(std::lround(c[i]), 0L, 255L));
    }
  }
  // Keep the Mesh invariants: no zero-area triangle, every vertex used.
  std::vector<std::uint32_t> kept;
  vtkCellArray* polys = out->GetPolys();
  vtkNew<vtkIdList> ids;
  for (polys->InitTraversal(); polys->GetNextCell(ids);) {
    if (ids->GetNumberOfIds() != 3) continue;
    const auto a = static_cast<std::uint32_t>(ids->GetId(0)), b = static_cast<std::uint32_t>(ids->GetId(1)),
               c = static_cast<std::uint32_t>(ids->GetId(2));
    const glm::dvec3 e = glm::cross(result.vertices[b] - result.vertices[a], result.vertices[c] - result.vertices[a]);
    if (a == b || b == c || a == c || glm::dot(e, e) == 0.0) continue;
    kept.insert(kept.end(), {a, b, c});
  }
  std::vector<std::uint32_t> remap(result.vertices.size(), UINT32_MAX);
  Mesh compact;
  for (std::uint32_t& i : kept) {
    if (remap[i] == UINT32_MAX) {
      remap[i] = static_cast<std::uint32_t>(compact.vertices.size());
      compact.vertices.push_back(result.vertices[i]);
      compact.colors.push_back(result.colors[i]);
    }
    i = remap[i];
  }
  compact.triangles = std::move(kept);
  return compact;
}

}  // namespace terravol::volume
