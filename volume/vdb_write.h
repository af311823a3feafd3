// Writing volumes as OpenVDB files that parse_vdb (readers.h) reads back exactly.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "volume/volume.h"

namespace terravol::volume {

// The bytes of a .vdb file holding one float grid per volume, in the given order: the grid is
// named Volume::name; every lattice point is an active voxel at index (i, j, k) (so the file
// is dense, Blosc-compressed); the transform is a ScaleTranslateMap with scale = spacing and
// translation = origin, so index (i, j, k) maps to exactly the lattice's world coordinates;
// the background is Volume::background; the frame, units and attributes are grid metadata
// (volume.h, keys::*). Precondition: names are non-empty and distinct, values.size() ==
// lattice.size(); throws std::invalid_argument otherwise.
std::string encode_vdb(const std::vector<const Volume*>& volumes);

// Writes encode_vdb(volumes) to PATH.tmp-PID in the same folder, then renames it to path.
// Throws std::runtime_error("PATH: exists (use --force to overwrite)") when path exists and
// !overwrite, or "PATH: cannot write" on I/O errors (the temporary file is removed).
void write_vdb(const std::filesystem::path& path, const std::vector<const Volume*>& volumes, bool overwrite);

}  // namespace terravol::volume
