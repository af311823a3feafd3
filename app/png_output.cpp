#include "app/png_output.h"

#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <stdexcept>

#include "app/write_file.h"

namespace terravol::app {

std::vector<std::uint8_t> window_png(vtkRenderWindow* window) {
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->ShouldRerenderOff();
  grab->Update();
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputConnection(grab->GetOutputPort());
  writer->WriteToMemoryOn();
  writer->Write();
  vtkUnsignedCharArray* bytes = writer->GetResult();
  if (bytes == nullptr || bytes->GetNumberOfValues() == 0) throw std::runtime_error("PNG encoding failed");
  const std::uint8_t* p = bytes->GetPointer(0);
  return std::vector<std::uint8_t>(p, p + bytes->GetNumberOfValues());
}

std::vector<std::uint8_t> window_rgb(vtkRenderWindow* window) {
  int* size = window->GetSize();
  const int w = size[0], h = size[1];
  std::vector<std::uint8_t> out(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  if (out.empty()) return out;
  // The back buffer, bottom row first (OpenGL's order), turned top row first.
  unsigned char* pixels = window->GetPixelData(0, 0, w - 1, h - 1, 0, 0);
  const std::size_t row = static_cast<std::size_t>(w) * 3;
  for (int y = 0; y < h; ++y) {
    std::copy_n(pixels + static_cast<std::size_t>(h - 1 - y) * row, row, out.data() + static_cast<std::size_t>(y) * row);
  }
  delete[] pixels;
  return out;
}

void write_png(const std::filesystem::path& path, const std::vector<std::uint8_t>& png, bool overwrite) {
  write_file_atomically(path, png, overwrite);
}

}  // namespace terravol::app
