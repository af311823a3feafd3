// Writing output files without losing what was there.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace terravol::app::output {

// Writes bytes to PATH.tmp-PID, then renames it to path. Throws std::runtime_error
// ("PATH: exists (use --force to overwrite)") when path exists and !overwrite, or on I/O errors;
// the temporary file is removed on failure.
void write_file_atomically(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes,
                           bool overwrite);

// Checks an output path given as `option` before any work is done: its extension is `extension`
// (case-insensitive; not checked when empty), it does not exist unless `overwrite`, and its
// folder exists. Throws std::runtime_error "OPTION PATH: expected a EXT file name", "PATH: exists
// (use --force to overwrite)" or "OPTION PATH: folder F does not exist".
void check_output_path(const std::filesystem::path& path, const std::string& option, const std::string& extension,
                       bool overwrite);

}  // namespace terravol::app::output
