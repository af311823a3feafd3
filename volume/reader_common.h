// What the readers share: checking a lattice, putting spacing > 0, and the frame metadata.
// Private to volume/ (not included by other modules).
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "volume/readers.h"
#include "volume/volume.h"

namespace terravol::volume::detail {

// Text from a file, fit for a one-line message: control characters become '?', and more than
// `max` characters end in "...".
std::string printable(std::string_view text, std::size_t max = 80);

// Throws FormatError unless every dim >= 1, the product is at most kMaxPoints and at most
// max_points (what the input's size can hold).
void check_dims(const std::array<long long, 3>& dims, std::size_t max_points, const std::string& source);

// Throws FormatError unless origin and spacing are finite and spacing != 0.
void check_geometry(const Lattice& lattice, const std::string& source);

// Makes every spacing positive by reversing the axes whose spacing is negative.
void normalise_axes(Volume& volume);

// The frame metadata as a file holds it (volume.h, keys::*).
struct FileMetadata {
  std::optional<std::string> frame, height, units;
  std::optional<std::array<double, 3>> origin;  // lat, lon, h
  std::map<std::string, std::string> attributes;  // without the prefix
};

// Sets volume.frame, units and attributes from the metadata, then the options' overrides,
// and checks that a geographic lattice's latitudes lie in [-90, 90]. Throws FormatError for
// unknown frame or height names and an ENU frame without its origin.
void apply_metadata(Volume& volume, const FileMetadata& metadata, const ReadOptions& options,
                    const std::string& source);

// A Volume as bytes and back, to carry it out of an isolated child process (isolated.h).
// deserialize_volume throws io::FormatError(source, ...) on bytes serialize_volume did not make.
std::string serialize_volume(const Volume& volume);
Volume deserialize_volume(std::string_view bytes, const std::string& source);

}  // namespace terravol::volume::detail
