#include "app/output/vtp_export.h"

#include <unistd.h>

#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "app/scene/terrain_colors.h"

namespace terravol::app::output {

namespace {

void add_field(vtkFieldData* fd, const char* name, const double* v, int n) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->SetNumberOfValues(n);
  for (int k = 0; k < n; ++k) a->SetValue(k, v[k]);
  fd->AddArray(a);
}

void add_rgb(vtkFieldData* fd, const char* name, const scene::Rgb& c) {
  vtkNew<vtkUnsignedCharArray> a;
  a->SetName(name);
  a->SetNumberOfComponents(3);
  a->SetNumberOfTuples(1);
  for (int k = 0; k < 3; ++k) a->SetValue(k, c[k]);
  fd->AddArray(a);
}

}  // namespace

void export_vtp(const std::filesystem::path& path, vtkPolyData* scene, int lattice_cells, vtkCamera* camera,
                const render::RenderSettings& settings, bool overwrite) {
  if (!overwrite && std::filesystem::exists(path)) {
    throw std::runtime_error(path.string() + ": exists (use --force to overwrite)");
  }
  vtkDataArray* connectivity = scene->GetPolys()->GetConnectivityArray();
  const vtkIdType values = connectivity->GetNumberOfValues();
  const vtkIdType triangles = values / 3;

  // Renumber the points the triangles use, in order of first use.
  std::vector<vtkIdType> new_id(static_cast<std::size_t>(scene->GetNumberOfPoints()), -1);
  std::vector<vtkIdType> old_id;
  vtkNew<vtkIdTypeArray> out_connectivity;
  out_connectivity->SetNumberOfValues(values);
  for (vtkIdType k = 0; k < values; ++k) {
    const auto v = static_cast<vtkIdType>(connectivity->GetTuple1(k));
    vtkIdType& id = new_id[static_cast<std::size_t>(v)];
    if (id < 0) {
      id = static_cast<vtkIdType>(old_id.size());
      old_id.push_back(v);
    }
    out_connectivity->SetValue(k, id);
  }
  vtkNew<vtkIdList> ids;
  ids->SetNumberOfIds(static_cast<vtkIdType>(old_id.size()));
  std::copy(old_id.begin(), old_id.end(), ids->GetPointer(0));

  vtkNew<vtkPolyData> out;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  scene->GetPoints()->GetPoints(ids, points);
  out->SetPoints(points);
  vtkNew<vtkCellArray> polys;
  polys->SetData(3, out_connectivity);
  out->SetPolys(polys);

  if (vtkDataArray* in = scene->GetPointData()->GetArray("rgba")) {
    vtkSmartPointer<vtkDataArray> a = vtkSmartPointer<vtkDataArray>::Take(in->NewInstance());
    a->SetName("rgba");
    a->SetNumberOfComponents(in->GetNumberOfComponents());
    a->SetNumberOfTuples(ids->GetNumberOfIds());
    in->GetTuples(ids, a);
    out->GetPointData()->AddArray(a);
  }
  // The normals, made here from the lattice's points (the renderer holds none).
  const vtkIdType side = lattice_cells + 1, lattice = lattice_cells > 0 ? side * side : 0;
  if (scene->GetNumberOfPoints() < lattice) {
    throw std::invalid_argument("export_vtp: " + std::to_string(scene->GetNumberOfPoints()) + " points for a lattice of " +
                                std::to_string(lattice_cells) + " cells");
  }
  vtkNew<vtkFloatArray> normals;
  normals->SetName("normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(static_cast<vtkIdType>(old_id.size()));
  vtkPoints* at = scene->GetPoints();
  for (std::size_t k = 0; k < old_id.size(); ++k) {
    const vtkIdType v = old_id[k];
    glm::dvec3 n(0.0, 0.0, 1.0);
    if (v < lattice) {
      const auto point = [&](int i, int j) { return at->GetPoint(static_cast<vtkIdType>(j) * side + i); };
      const int i = static_cast<int>(v % side), j = static_cast<int>(v / side);
      n = scene::lattice_normal(
          lattice_cells, i, j, [&](int ii) { return point(ii, j)[0]; }, [&](int jj) { return point(i, jj)[1]; },
          [&](int ii, int jj) { return point(ii, jj)[2]; });
    }
    normals->SetTuple3(static_cast<vtkIdType>(k), n.x, n.y, n.z);
  }
  out->GetPointData()->SetNormals(normals);
  for (const char* name : {"level", "lod_rgba"}) {
    vtkDataArray* in = scene->GetCellData()->GetArray(name);
    if (in == nullptr || in->GetNumberOfTuples() != triangles) continue;
    out->GetCellData()->AddArray(in);
  }

  vtkFieldData* fd = out->GetFieldData();
  add_field(fd, "camera_position", camera->GetPosition(), 3);
  add_field(fd, "camera_focal_point", camera->GetFocalPoint(), 3);
  add_field(fd, "camera_view_up", camera->GetViewUp(), 3);
  const double angle = camera->GetViewAngle();
  add_field(fd, "camera_view_angle", &angle, 1);
  add_field(fd, "camera_clipping_range", camera->GetClippingRange(), 2);
  add_rgb(fd, "background", settings.background);
  if (settings.gradient) add_rgb(fd, "background_top", settings.background_top);

  std::filesystem::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid());
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(out);
  writer->SetFileName(tmp.c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToZLib();
  if (writer->Write() != 1) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(path.string() + ": cannot write");
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace terravol::app::output
