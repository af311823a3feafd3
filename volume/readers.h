// Reading scalar volumes: OpenVDB .vdb, VTK XML image data .vti, legacy VTK .vtk
// STRUCTURED_POINTS. Readers are functions of the file's bytes (so tests can cut and corrupt
// them in memory); read_volume() reads a file and dispatches on its extension.
//
// Every reader returns a Volume with spacing > 0 on each axis (a negative spacing is undone by
// reversing that axis), values converted to float, and the frame from the file's metadata
// (volume.h, keys::*) unless ReadOptions::frame overrides it; kNone when neither says.
// Bad input (missing, truncated, corrupt, wrong type, no scalars, several components, absurd
// or empty dimensions, rotated transforms) throws io::FormatError("SOURCE: what is wrong");
// nothing is printed. OpenVDB's and VTK's readers crash on some corrupt files, so each parse
// runs in a forked child process (isolated.h; about 5 ms): a crash or a hang becomes a
// FormatError too. Thread-safe; reads through the same library are serialised.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "volume/volume.h"

namespace terravol::volume {

struct ReadOptions {
  // .vdb: the grid's name; empty: the first float grid in the file.
  // .vti/.vtk: the point-data array's name; empty: the active scalars, else the first array
  // with one component.
  std::string field;
  std::optional<VolumeFrame> frame;  // overrides the file's frame metadata
  std::optional<std::string> units;  // overrides the file's units
};

enum class VolumeFormat { kVdb, kVti, kLegacyVtk };

// From the extension (case-insensitive): .vdb, .vti, .vtk. nullopt when unknown.
std::optional<VolumeFormat> volume_format_from_name(const std::filesystem::path& path);

// Reads a whole file (at most 1 GiB) and parses it. Throws io::FormatError("PATH: ...") for a
// missing or unreadable file, an unknown extension, and whatever the parser rejects.
Volume read_volume(const std::filesystem::path& path, const ReadOptions& options = {});

Volume parse_vdb(std::string_view bytes, const std::string& source, const ReadOptions& options = {});
Volume parse_vti(std::string_view bytes, const std::string& source, const ReadOptions& options = {});
Volume parse_legacy_vtk(std::string_view bytes, const std::string& source, const ReadOptions& options = {});

// Names of the grids of a .vdb file held in memory and their value types ("float", "vec3s",
// ...), in file order. Throws io::FormatError.
struct GridInfo {
  std::string name, type;
};
std::vector<GridInfo> vdb_grids(std::string_view bytes, const std::string& source);

}  // namespace terravol::volume
