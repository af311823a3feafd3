#include "io/void_fill.h"

#include <cstdint>
#include <vector>

namespace terravol::io {

std::size_t fill_voids(Grid& grid, int iterations) {
  const int rows = grid.rows, cols = grid.cols;
  std::vector<std::uint32_t> todo;  // indices of samples to fill
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (grid.mask[i] != Sample::kValid) todo.push_back(static_cast<std::uint32_t>(i));
  }
  if (todo.empty()) return 0;
  if (todo.size() == grid.size()) {
    for (float& h : grid.heights) h = 0.0f;
    return todo.size();
  }

  // known[i]: the sample has a height (valid, or filled in an earlier BFS layer).
  std::vector<std::uint8_t> known(grid.size());
  for (std::size_t i = 0; i < grid.size(); ++i) known[i] = grid.mask[i] == Sample::kValid;

  constexpr int kDr[4] = {-1, 1, 0, 0};
  constexpr int kDc[4] = {0, 0, -1, 1};
  auto neighbour_mean = [&](std::uint32_t i, bool only_known, float& out) {
    const int r = static_cast<int>(i / cols), c = static_cast<int>(i % cols);
    float sum = 0.0f;
    int n = 0;
    for (int k = 0; k < 4; ++k) {
      const int rr = r + kDr[k], cc = c + kDc[k];
      if (rr < 0 || rr >= rows || cc < 0 || cc >= cols) continue;
      const std::size_t j = grid.index(rr, cc);
      if (only_known && !known[j]) continue;
      sum += grid.heights[j];
      ++n;
    }
    if (n > 0) out = sum / static_cast<float>(n);
    return n > 0;
  };

  // Breadth-first layers from the rim inward: each layer takes the mean of known neighbours.
  std::vector<std::uint32_t> layer, next, pending = todo;
  while (!pending.empty()) {
    layer.clear();
    next.clear();
    for (std::uint32_t i : pending) {
      float h = 0.0f;
      if (neighbour_mean(i, true, h)) {
        grid.heights[i] = h;
        layer.push_back(i);
      } else {
        next.push_back(i);
      }
    }
    for (std::uint32_t i : layer) known[i] = 1;
    pending.swap(next);
  }

  // Gauss-Seidel relaxation towards the harmonic interpolant; valid samples stay fixed.
  for (int it = 0; it < iterations; ++it) {
    for (std::uint32_t i : todo) {
      float h = 0.0f;
      if (neighbour_mean(i, false, h)) grid.heights[i] = h;
    }
  }
  return todo.size();
}

}  // namespace terravol::io
