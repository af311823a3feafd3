// Drawing the independent reference (reference/check.h) with VTK's depth peeling run to
// exactness: the terrain a render exported (--export-vtp) opaque and depth-tested, the rebuilt
// volume geometry (reference/geometry.h) translucent over it.
#pragma once

#include <vtkImageData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "reference/frame.h"
#include "reference/geometry.h"


namespace terravol::reference {

// What a render drew, from its --export-vtp file (docs/architecture.md, "Outputs").
struct Drawn {
  vtkSmartPointer<vtkPolyData> terrain;  // the triangles whose "level" is >= -1, with "rgba"
  // The terrain's colours as the renderer samples them (texture_terrain): a bilinear texture of
  // the lattice, and texture coordinates on the terrain's points; null until then.
  vtkSmartPointer<vtkImageData> texture;
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

// The window of the lattice a render drew (its --stats "window"): its samples span
// [south, north] x [west, east] degrees in cells x cells cells.
struct WindowLattice {
  int cells = 0;
  double south = 0, north = 0, west = 0, east = 0;
};

// Gives the terrain the renderer's colouring: the renderer draws the lattice colours from one
// bilinear texture (no mipmaps) in which every sample is a texel and every vertex has the
// texture coordinate of its sample's texel centre (docs/architecture.md, "Colours"), not from
// the per-vertex colours. Gouraud-interpolated vertex colours differ from that inside every
// cell, by more than 8/255 on a few tenths of a percent of the pixels of rough terrain near
// the camera, which would hide what the check is for; so the texture is built here from the
// exported colours: each exported terrain point is placed on the lattice (its lattice line from
// x and y through the frame's inverse) and the highest point of each line, the sample itself,
// gives its texel its colour (crack-fill bottoms below it sample the same texel, as in the
// renderer). Needs a --full-res render. Throws
// std::runtime_error when a point is off the lattice lines or a triangle spans more than one
// cell (not --full-res).
void texture_terrain(Drawn& drawn, const Frame& frame, const WindowLattice& window);

// Throws std::runtime_error when no X display can be opened (VTK 9.1 on Debian renders through
// GLX only, and aborts without one). The first successful call keeps its connection open until
// the process ends, so that an Xvfb server does not reset (refusing connections meanwhile) when
// another client, e.g. a render run by run_render, leaves; call it before such runs.
void require_display();

// Draws `drawn.terrain` opaque (its texture when it has one, else its vertex colours; lighting
// off, depth-tested) and `volumes`
// translucent (both faces, lighting off) with vtkRenderer's depth peeling: no limit on peels
// (INT_MAX, not 0: VTK 9.1's dual depth peeling takes 0 literally and peels nothing),
// occlusion ratio 0, alpha bit planes, no multisampling, no FXAA; the exported camera (its
// clipping range too) and background (a VTK gradient when there is a top colour), width x
// height pixels, offscreen. Needs an X display (GLX): throws std::runtime_error without one.
Image draw(const Drawn& drawn, const Mesh& volumes, int width, int height);

}  // namespace terravol::reference
