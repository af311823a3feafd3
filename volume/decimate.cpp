// Decimation of volume meshes: VTK's quadric decimation (M. Garland and P. S. Heckbert,
// "Surface simplification using quadric error metrics", SIGGRAPH 1997), colours carried as a
// point attribute.
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkQuadricDecimation.h>

#include "volume/geometry.h"
#include "volume/vtk_mesh.h"

namespace terravol::volume {

Mesh decimate(const Mesh& mesh, std::size_t max_triangles) {
  const std::size_t n = mesh.triangle_count();
  if (n <= max_triangles || max_triangles == 0) return mesh;
  const glm::dvec3 centre = detail::centre_of(mesh);
  const auto poly = detail::to_polydata(mesh, centre, /*colors=*/true);
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
  return detail::from_polydata(decimation->GetOutput(), centre);
}

}  // namespace terravol::volume
