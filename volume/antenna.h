// Transmitting antenna patterns in SPLAT!'s .az and .el formats (man splat, "ANTENNA RADIATION
// PATTERN PARAMETERS"; SPLAT! 1.4.2's LoadPAT()), and the gain they give in a direction.
//
// Pure functions of text: bad files throw io::FormatError("SOURCE: line N: ..."), one line each.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace terravol::volume {

// One plane of a pattern: normalised field (voltage) values at angles, as the file lists them.
struct PatternCut {
  std::vector<std::pair<double, double>> points;  // (angle in degrees, field in [0, 1]), sorted
                                                  // by angle, one per angle (duplicates averaged)
  std::string source;                             // the file, for messages and attributes
  std::string text;                               // the file as read (splat-volume passes it on)
};

// Parses a .az file: the first line is the pattern's rotation (degrees clockwise from true
// north: where the pattern's 0 degrees points), then lines "AZIMUTH FIELD" with AZIMUTH in
// [0, 360] degrees and FIELD a normalised field value in [0, 1]. Text after ';' is a comment;
// blank lines are skipped. Several values at one azimuth are averaged (as SPLAT! does); a value
// at 360 is used only when there is none at 0 (SPLAT!'s rule). Returns the cut and the rotation.
// Throws io::FormatError("SOURCE: line N: ...") for a missing or non-numeric rotation, a line
// that is not two numbers, an angle or field out of range, or no data line.
std::pair<PatternCut, double> parse_az(std::string_view text, const std::string& source);

// Parses a .el file: the first line is "TILT [TILT_AZIMUTH]", the mechanical beam tilt in
// degrees (downward positive, within [-90, 90]) towards TILT_AZIMUTH (degrees clockwise from
// true north; 0 when absent), then lines "ANGLE FIELD" with ANGLE the depression below the
// horizon in [-10, 90] degrees (negative above the horizon, SPLAT!'s convention) and FIELD in
// [0, 1]. Same rules and errors as parse_az. Returns the cut, the tilt and its azimuth.
struct ElevationFile {
  PatternCut cut;
  double tilt_deg = 0.0, tilt_azimuth_deg = 0.0;
};
ElevationFile parse_el(std::string_view text, const std::string& source);

// A transmitting antenna's pattern as SPLAT! applies it: the relative gain in true azimuth phi
// and elevation theta (positive above the horizon) is
//   G = 20 log10(A(phi - rotation) * E(-theta - tilt * tri(phi - tilt_azimuth)))  dB, <= 0,
// where A and E are the cuts interpolated linearly between their points (A periodic over 360
// degrees; E held at its first and last values beyond them), A = 1 without a .az file and E = 1
// without a .el file, and tri(x) is SPLAT!'s tilt profile, linear in azimuth: 1 at x = 0, 0 at
// +-90, -1 at 180 (the beam dips by the tilt towards tilt_azimuth, rises by it behind). A product
// below 1e-3 counts as 1e-3 (-60 dB): SPLAT! 1.4.2 skips the pattern where it is exactly 0.
// Departures from SPLAT!, which tabulates the pattern at whole degrees of azimuth and 0.1 degree
// of elevation (each 0.1-degree cell the mean of ten 0.01-degree samples from its lower edge up):
// this interpolates at full resolution; above 10 degrees of elevation SPLAT! applies no pattern,
// this holds E's value at -10 degrees of depression.
struct AntennaPattern {
  std::optional<PatternCut> azimuth;    // the .az cut (angles relative to the pattern's 0)
  std::optional<PatternCut> elevation;  // the .el cut (angles of depression)
  double rotation_deg = 0.0;
  double tilt_deg = 0.0, tilt_azimuth_deg = 0.0;

  // G(phi, theta) in dB as above, for any finite angles (phi taken modulo 360).
  double gain_db(double azimuth_deg, double elevation_deg) const;
  // "FILE.az[:FILE.el], rotation R, tilt T towards A" for a volume's attributes.
  std::string describe() const;
};

// Reads a pattern as given on a command line, "FILE.az[:FILE.el]" or ":FILE.el" (elevation
// only), with optional overrides: azimuth replaces the .az file's rotation and turns the tilt's
// direction with it (the whole antenna turns); tilt replaces the .el file's tilt. Throws
// io::FormatError for unreadable or malformed files and std::invalid_argument("...") for a spec
// without a file name, a tilt without a .el file or an azimuth without a .az file, and angles out
// of range (azimuth finite, tilt within [-90, 90]).
AntennaPattern read_antenna_pattern(const std::string& spec, std::optional<double> azimuth_deg,
                                    std::optional<double> tilt_deg);

// The .az and .el texts SPLAT! should read for this pattern: the files as read with their first
// line replaced by the (possibly overridden) rotation, and tilt and tilt azimuth. Empty when
// there is no such cut. SPLAT! rounds the rotation and the tilt azimuth to whole degrees.
std::string splat_az_text(const AntennaPattern& pattern);
std::string splat_el_text(const AntennaPattern& pattern);

}  // namespace terravol::volume
