// Writing output files without losing what was there.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace terravol::app::output {

// Writes bytes to PATH.tmp-PID, then renames it to path. Throws std::runtime_error
// ("PATH: exists (use --force to overwrite)") when path exists and !overwrite, or on I/O errors;
// the temporary file is removed on failure.
void write_file_atomically(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes,
                           bool overwrite);

}  // namespace terravol::app::output
