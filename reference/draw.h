// Drawing the independent reference (reference/check.h) with VTK's depth peeling run to
// exactness: the terrain a render exported (--export-vtp) opaque and depth-tested, the rebuilt
// volume geometry (reference/geometry.h) translucent over it.
#pragma once

#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "reference/geometry.h"


namespace terravol::reference {

// What a render drew, from its --export-vtp file (docs/architecture.md, "Outputs").
struct Drawn {
  vtkSmartPointer<vtkPolyData> terrain;  // the triangles whose "level" is >= -1, with "rgba"
  std::size_t terrain_triangles = 0, skirt_triangles = 0, merged_triangles = 0;
  std::array<double, 3> position{}, focal_point{}, view_up{};  // scene frame, metres
  double view_angle = 45;                                      // vertical, degrees
  std::array<double, 2> clipping_range{};                      // metres
  std::array<std::uint8_t, 3> background{};                    // uniform, or the gradient's bottom
  std::optional<std::array<std::uint8_t, 3>> background_top;   // a gradient sky
};

// Throws std::runtime_error("PATH: what is wrong") when the file cannot be read or lacks the
// camera, the background, the "level" cell data or the "rgba" point data.
Drawn read_drawn(const std::filesystem::path& vtp);

// An RGB image, top row first, 3 bytes a pixel.
struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
};

// Throws std::runtime_error when no X display can be opened (VTK 9.1 on Debian renders through
// GLX only, and aborts without one). The first successful call keeps its connection open until
// the process ends, so that an Xvfb server does not reset (refusing connections meanwhile) when
// another client, e.g. a render run by run_render, leaves; call it before such runs.
void require_display();

// Draws `drawn.terrain` opaque (colours as they are, lighting off, depth-tested) and `volumes`
// translucent (both faces, lighting off) with vtkRenderer's depth peeling: no limit on peels
// (INT_MAX, not 0: VTK 9.1's dual depth peeling takes 0 literally and peels nothing),
// occlusion ratio 0, alpha bit planes, no multisampling, no FXAA; the exported camera (its
// clipping range too) and background (a VTK gradient when there is a top colour), width x
// height pixels, offscreen. Needs an X display (GLX): throws std::runtime_error without one.
Image draw(const Drawn& drawn, const Mesh& volumes, int width, int height);

}  // namespace terravol::reference
