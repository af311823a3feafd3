#include "app/png_output.h"

#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

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

void write_png(const std::filesystem::path& path, const std::vector<std::uint8_t>& png, bool overwrite) {
  write_file_atomically(path, png, overwrite);
}

}  // namespace terravol::app
