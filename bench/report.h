// The report of a benchmark run: Markdown with PNG plots, from the JSON the suites return
// (bench/suites.h). docs/benchmarks.md is the latest full report, committed.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace terravol::bench {

// Writes `dir`/report.md and its plots (`dir`/plot-*.png, linked by file name) from `results`:
// {"machine": {...}, "date": ..., "quick": bool, "terrain": [...], "translucency": [...],
// "scaling": [...], "build": [...], "exactness": [...]}; absent suites are left out. Throws std::runtime_error when a
// file cannot be written.
void write_report(const nlohmann::json& results, const std::filesystem::path& dir);

// The headline figures, a few lines of text: full-res / MRBSP frame time at 1 px per terrain,
// the translucency ratios and errors, the scaling ratio between the largest and smallest
// terrain, slide / build, and depth-peeled full-resolution VTK / Terravol.
std::string headline(const nlohmann::json& results);

}  // namespace terravol::bench
