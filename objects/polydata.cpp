#include "objects/polydata.h"

#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>

namespace terravol::objects::detail {

vtkSmartPointer<vtkPolyData> polydata_of(const volume::Mesh& m) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(m.vertices.size()));
  for (std::size_t k = 0; k < m.vertices.size(); ++k) {
    points->SetPoint(static_cast<vtkIdType>(k), m.vertices[k].x, m.vertices[k].y, m.vertices[k].z);
  }
  vtkNew<vtkCellArray> cells;
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    const vtkIdType ids[3] = {m.triangles[t], m.triangles[t + 1], m.triangles[t + 2]};
    cells->InsertNextCell(3, ids);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(cells);
  return poly;
}

}  // namespace terravol::objects::detail
