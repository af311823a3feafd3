// Meshes to and from vtkPolyData for VTK's mesh filters (decimation, clustering). Private to
// volume/.
#pragma once

#include <vtkSmartPointer.h>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <optional>

#include "volume/geometry.h"

class vtkPolyData;

namespace terravol::volume::detail {

// The mean of the vertices: VTK's filters work about it, since scene-frame metres are large
// numbers far from the frame's origin and quadrics square them.
glm::dvec3 centre_of(const Mesh& mesh);

// The triangles as vtkPolyData, points (double) relative to `centre`, and, with `colors`, the
// vertex colours as 4-component float point scalars (0..255).
vtkSmartPointer<vtkPolyData> to_polydata(const Mesh& mesh, const glm::dvec3& centre, bool colors);

// Back to a Mesh keeping the Mesh invariants: triangles only, those with a repeated vertex or
// zero area dropped, unused points dropped. Colours: `uniform` when given, else the point
// scalars (4 components, rounded and clamped to 0..255), else opaque white.
Mesh from_polydata(vtkPolyData* poly, const glm::dvec3& centre, std::optional<glm::u8vec4> uniform = {});

}  // namespace terravol::volume::detail
