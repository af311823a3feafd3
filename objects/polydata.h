// A Mesh as vtkPolyData for VTK's filters (the Hausdorff sampling of lod.cpp, the normals of
// shading.cpp). Private to objects/.
#pragma once

#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include "volume/geometry.h"

namespace terravol::objects::detail {

// The triangles as vtkPolyData: points in double precision, one triangle cell per triangle,
// in order; no point data.
vtkSmartPointer<vtkPolyData> polydata_of(const volume::Mesh& m);

}  // namespace terravol::objects::detail
