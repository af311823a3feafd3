// PNG output of a render window.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

class vtkRenderWindow;

namespace terravol::app::output {

// RGB, or RGBA when channels is 4 (width * height * channels bytes, top row first), encoded
// as PNG with vtkPNGWriter, in memory, at zlib's compression `level` (0 none, 1 fastest .. 9
// smallest; vtkPNGWriter's default 5): the same pixels and level give the same bytes. Throws
// std::invalid_argument when the size does not match, channels is neither 3 nor 4 or level is
// outside 0..9, and std::runtime_error when encoding fails.
std::vector<std::uint8_t> encode_png(std::span<const std::uint8_t> pixels, int width, int height, int channels = 3,
                                     int level = 5);

// The last frame drawn in `window` (render::window_rgb: its back buffer, not re-rendered),
// encoded as PNG (vtkPNGWriter, in memory). Throws std::runtime_error when encoding fails.
std::vector<std::uint8_t> window_png(vtkRenderWindow* window);

// Writes PNG bytes to `path` through a temporary file in the same folder and a rename, so a
// reader never sees half an image. Throws std::runtime_error ("PATH: exists (use --force to
// overwrite)") when path exists and !overwrite, and on I/O errors (write_file_atomically).
void write_png(const std::filesystem::path& path, const std::vector<std::uint8_t>& png, bool overwrite);

}  // namespace terravol::app::output
