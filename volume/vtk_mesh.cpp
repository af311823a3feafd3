#include "volume/vtk_mesh.h"

#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkFloatArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>

namespace terravol::volume::detail {

glm::dvec3 centre_of(const Mesh& mesh) {
  glm::dvec3 centre(0.0);
  for (const auto& v : mesh.vertices) centre += v;
  return mesh.vertices.empty() ? centre : centre / static_cast<double>(mesh.vertices.size());
}

vtkSmartPointer<vtkPolyData> to_polydata(const Mesh& mesh, const glm::dvec3& centre, bool colors) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.vertices.size()));
  for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
    const glm::dvec3 p = mesh.vertices[k] - centre;
    points->SetPoint(static_cast<vtkIdType>(k), p.x, p.y, p.z);
  }
  // Cells as one connectivity array with offsets (no per-cell insertion).
  vtkNew<vtkIdTypeArray> offsets, connectivity;
  const std::size_t n = mesh.triangle_count();
  offsets->SetNumberOfValues(static_cast<vtkIdType>(n + 1));
  connectivity->SetNumberOfValues(static_cast<vtkIdType>(3 * n));
  for (std::size_t t = 0; t <= n; ++t) offsets->SetValue(static_cast<vtkIdType>(t), static_cast<vtkIdType>(3 * t));
  for (std::size_t i = 0; i < 3 * n; ++i) connectivity->SetValue(static_cast<vtkIdType>(i), mesh.triangles[i]);
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, connectivity);
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(cells);
  if (colors) {
    vtkNew<vtkFloatArray> rgba;
    rgba->SetNumberOfComponents(4);
    rgba->SetNumberOfTuples(static_cast<vtkIdType>(mesh.vertices.size()));
    for (std::size_t k = 0; k < mesh.colors.size(); ++k) {
      const glm::u8vec4 c = mesh.colors[k];
      const float t[4] = {float(c.r), float(c.g), float(c.b), float(c.a)};
      rgba->SetTypedTuple(static_cast<vtkIdType>(k), t);
    }
    poly->GetPointData()->SetScalars(rgba);
  }
  return poly;
}

Mesh from_polydata(vtkPolyData* poly, const glm::dvec3& centre, std::optional<glm::u8vec4> uniform) {
  Mesh mesh;
  const vtkIdType n_points = poly->GetNumberOfPoints();
  vtkCellArray* polys = poly->GetPolys();
  if (n_points == 0 || polys == nullptr) return mesh;
  vtkDataArray* scalars = poly->GetPointData()->GetScalars();
  if (scalars != nullptr && scalars->GetNumberOfComponents() != 4) scalars = nullptr;
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> remap(static_cast<std::size_t>(n_points), kUnused);
  auto point = [&](vtkIdType id) {  // relative to the centre
    double p[3];
    poly->GetPoint(id, p);
    return glm::dvec3(p[0], p[1], p[2]);
  };
  auto vertex = [&](vtkIdType id) {
    std::uint32_t& r = remap[static_cast<std::size_t>(id)];
    if (r == kUnused) {
      r = static_cast<std::uint32_t>(mesh.vertices.size());
      mesh.vertices.push_back(point(id) + centre);
      glm::u8vec4 c(255);
      if (uniform) {
        c = *uniform;
      } else if (scalars != nullptr) {
        double t[4];
        scalars->GetTuple(id, t);
        for (int i = 0; i < 4; ++i) c[i] = static_cast<std::uint8_t>(std::clamp(std::lround(t[i]), 0L, 255L));
      }
      mesh.colors.push_back(c);
    }
    return r;
  };
  vtkIdType n_ids = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(n_ids, ids);) {
    if (n_ids != 3) continue;
    if (ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2]) continue;
    const glm::dvec3 a = point(ids[0]), b = point(ids[1]), c = point(ids[2]);
    const glm::dvec3 e = glm::cross(b - a, c - a);
    if (e.x == 0.0 && e.y == 0.0 && e.z == 0.0) continue;
    mesh.triangles.insert(mesh.triangles.end(), {vertex(ids[0]), vertex(ids[1]), vertex(ids[2])});
  }
  return mesh;
}

}  // namespace terravol::volume::detail
