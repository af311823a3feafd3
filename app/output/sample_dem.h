// The project's own synthetic terrain (`terravol sample-dem`): deterministic SRTM3 tiles of
// ridged mountains, the same bytes on every run and machine.
#pragma once

#include <filesystem>
#include <vector>

namespace terravol::app::output {

// Writes a seamless mosaic of rows x cols SRTM3 tiles into `dir` (created if needed), from
// N45E006 (the bundled data/dem/N45E006.hgt, byte for byte) northward and eastward; neighbours
// share their edge samples. Returns the files written. Throws std::invalid_argument unless
// 1 <= rows, cols <= 8, and std::runtime_error when a file exists and !force.
std::vector<std::filesystem::path> write_sample_dem(const std::filesystem::path& dir, int rows, int cols, bool force);

}  // namespace terravol::app::output
