#include "objects/shading.h"

#include "objects/polydata.h"

#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyDataNormals.h>
#include <vtkUnsignedCharArray.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace terravol::objects {

namespace {

constexpr double kFeatureAngleDeg = 40.0;  // split vertices where faces meet more sharply
constexpr double kMostLight = 1.3;          // the terrain's cap (shade_terrain)

std::uint8_t scaled(std::uint8_t c, double s) {
  return static_cast<std::uint8_t>(std::min(std::lround(c * s), 255L));
}

}  // namespace

volume::Mesh sunlit(const volume::Mesh& mesh, const Sunlight& sun) {
  if (!(sun.elevation_deg > 0.0 && sun.elevation_deg <= 90.0)) {
    throw std::invalid_argument("sunlit: the sun's elevation must lie in (0, 90] degrees");
  }
  if (!(sun.ambient >= 0.0 && sun.ambient <= 1.0)) throw std::invalid_argument("sunlit: ambient must lie in [0, 1]");
  if (mesh.empty()) return mesh;

  vtkSmartPointer<vtkPolyData> poly = detail::polydata_of(mesh);
  vtkNew<vtkUnsignedCharArray> rgba;
  rgba->SetName("rgba");
  rgba->SetNumberOfComponents(4);
  rgba->SetNumberOfTuples(static_cast<vtkIdType>(mesh.colors.size()));
  std::copy_n(&mesh.colors[0][0], 4 * mesh.colors.size(), rgba->GetPointer(0));
  poly->GetPointData()->AddArray(rgba);

  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(poly);
  normals->SetFeatureAngle(kFeatureAngleDeg);
  normals->SplittingOn();
  normals->ConsistencyOff();  // keep each triangle's winding and the order of the triangles
  normals->AutoOrientNormalsOff();
  normals->ComputePointNormalsOn();
  normals->ComputeCellNormalsOff();
  normals->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  normals->Update();
  vtkPolyData* out = normals->GetOutput();

  const double az = sun.azimuth_deg * M_PI / 180.0, el = sun.elevation_deg * M_PI / 180.0;
  const glm::dvec3 towards(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
  const double flat = std::max(std::sin(el), 1e-3);
  vtkDataArray* n = out->GetPointData()->GetNormals();
  auto* colours = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("rgba"));
  if (n == nullptr || colours == nullptr) throw std::logic_error("sunlit: vtkPolyDataNormals gave no normals or colours");

  volume::Mesh lit;
  const vtkIdType count = out->GetNumberOfPoints();
  lit.vertices.resize(static_cast<std::size_t>(count));
  lit.colors.resize(static_cast<std::size_t>(count));
  for (vtkIdType v = 0; v < count; ++v) {
    double p[3], d[3];
    out->GetPoint(v, p);
    n->GetTuple(v, d);
    lit.vertices[static_cast<std::size_t>(v)] = glm::dvec3(p[0], p[1], p[2]);
    const double s =
        std::min(sun.ambient + (1.0 - sun.ambient) * std::abs(glm::dot(glm::dvec3(d[0], d[1], d[2]), towards)) / flat, kMostLight);
    const unsigned char* c = colours->GetPointer(4 * v);
    lit.colors[static_cast<std::size_t>(v)] = glm::u8vec4(scaled(c[0], s), scaled(c[1], s), scaled(c[2], s), c[3]);
  }
  lit.triangles.reserve(mesh.triangles.size());
  vtkCellArray* tris = out->GetPolys();
  vtkIdType np = 0;
  const vtkIdType* ids = nullptr;
  for (tris->InitTraversal(); tris->GetNextCell(np, ids);) {
    if (np != 3) throw std::logic_error("sunlit: vtkPolyDataNormals gave a cell that is not a triangle");
    for (vtkIdType k = 0; k < 3; ++k) lit.triangles.push_back(static_cast<std::uint32_t>(ids[k]));
  }
  if (lit.triangles.size() != mesh.triangles.size()) throw std::logic_error("sunlit: vtkPolyDataNormals changed the triangles");
  return lit;
}

}  // namespace terravol::objects
