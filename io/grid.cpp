#include "io/grid.h"

#include <algorithm>

namespace terravol::io {

void Grid::allocate(int n_rows, int n_cols) {
  rows = n_rows;
  cols = n_cols;
  heights.assign(size(), 0.0f);
  mask.assign(size(), Sample::kValid);
}

std::size_t count(const Grid& grid, Sample what) {
  return static_cast<std::size_t>(std::count(grid.mask.begin(), grid.mask.end(), what));
}

HeightRange height_range(const Grid& grid) {
  HeightRange r;
  for (std::size_t i = 0; i < grid.heights.size(); ++i) {
    if (grid.mask[i] != Sample::kValid) continue;
    const float h = grid.heights[i];
    if (!r.any) {
      r.min = r.max = h;
      r.any = true;
    } else {
      r.min = std::min(r.min, h);
      r.max = std::max(r.max, h);
    }
  }
  return r;
}

}  // namespace terravol::io
