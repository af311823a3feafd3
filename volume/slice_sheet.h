// The exact sheet of a slice before it becomes triangles: one sample per lattice line crossing
// the slice, on the grid of the two lattice axes the lines do not run along. Private to
// volume/: slice() (volume/slice.cpp) draws every cell of it, textured_slice()
// (volume/sheet.cpp) a simplified sheet over it with the colours as a texture.
#pragma once

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "volume/geometry.h"

namespace terravol::volume::detail {

struct SliceSheet {
  int nu = 0, nv = 0;  // samples along the sheet's u and v lattice axes
  int u_axis = 0, v_axis = 1, line_axis = 2;  // lattice axes: kLat (0, 2, 1), kLon (1, 2, 0), kAlt/kAgl (0, 1, 2)
  // Per sample, index v * nu + u (u = lattice index along u_axis, v along v_axis):
  std::vector<glm::dvec3> position;  // the crossing in the scene frame (0 where not crossed)
  std::vector<float> value;          // trilinear value there; NaN where not crossed
  std::vector<std::uint8_t> usable;  // 1: crossed, and the value is not NaN
  std::vector<glm::u8vec4> color;    // the colour-mapped value, alpha = opacity; 0 where not usable

  std::size_t index(int u, int v) const { return static_cast<std::size_t>(v) * static_cast<std::size_t>(nu) + static_cast<std::size_t>(u); }
  // A cell (u, v)..(u + 1, v + 1) is drawn when its four samples are usable.
  bool cell_usable(int u, int v) const {
    const std::size_t a = index(u, v);
    return usable[a] && usable[a + 1] && usable[a + static_cast<std::size_t>(nu)] &&
           usable[a + static_cast<std::size_t>(nu) + 1];
  }
};

// The sheet of `spec` through `volume`, with the contract and the errors of slice()
// (geometry.h): same crossings, values and colours, same exceptions.
SliceSheet slice_sheet(const Volume& volume, const LatticeMapper& mapper, const SliceSpec& spec,
                       const GroundFunction& ground);

}  // namespace terravol::volume::detail
