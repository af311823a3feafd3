#include "app/output/png_output.h"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <stdexcept>

#include "app/output/write_file.h"
#include "app/render/terrain_renderer.h"

namespace terravol::app::output {

std::vector<std::uint8_t> encode_png(std::span<const std::uint8_t> pixels, int width, int height, int channels, int level) {
  if (level < 0 || level > 9) throw std::invalid_argument("encode_png: compression level " + std::to_string(level) + " outside 0..9");
  const std::size_t row = static_cast<std::size_t>(width) * static_cast<std::size_t>(channels);
  if (width <= 0 || height <= 0 || (channels != 3 && channels != 4) || pixels.size() != row * height) {
    throw std::invalid_argument("encode_png: " + std::to_string(pixels.size()) + " bytes for " + std::to_string(width) +
                                "x" + std::to_string(height) + "x" + std::to_string(channels));
  }
  vtkNew<vtkImageData> image;
  image->SetDimensions(width, height, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, channels);
  auto* dst = static_cast<std::uint8_t*>(image->GetScalarPointer());
  for (int y = 0; y < height; ++y) {  // VTK's rows go bottom up
    std::copy_n(pixels.data() + static_cast<std::size_t>(height - 1 - y) * row, row, dst + static_cast<std::size_t>(y) * row);
  }
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputData(image);
  writer->WriteToMemoryOn();
  writer->SetCompressionLevel(level);
  writer->Write();
  vtkUnsignedCharArray* bytes = writer->GetResult();
  if (bytes == nullptr || bytes->GetNumberOfValues() == 0) throw std::runtime_error("PNG encoding failed");
  const std::uint8_t* p = bytes->GetPointer(0);
  return std::vector<std::uint8_t>(p, p + bytes->GetNumberOfValues());
}

std::vector<std::uint8_t> window_png(vtkRenderWindow* window) {
  const int* size = window->GetSize();
  return encode_png(render::window_rgb(window), size[0], size[1]);
}

void write_png(const std::filesystem::path& path, const std::vector<std::uint8_t>& png, bool overwrite) {
  write_file_atomically(path, png, overwrite);
}

}  // namespace terravol::app::output
