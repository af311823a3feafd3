// `terravol compare-images A.png B.png [--tolerance N]`: the share of pixels whose colour
// differs by more than N/255 in some channel, and the largest difference (the exactness
// figures of docs/exactness.md compare renders this way).
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "app/cli/commands.h"

namespace terravol::app::cli {

namespace {

struct Rgb8Image {
  int width = 0, height = 0, components = 0;
  const unsigned char* data = nullptr;
  vtkNew<vtkPNGReader> reader;
};

void read(const std::filesystem::path& path, Rgb8Image& image) {
  if (!std::filesystem::is_regular_file(path)) throw std::runtime_error(path.string() + ": no such file");
  image.reader->SetFileName(path.c_str());
  if (image.reader->CanReadFile(path.c_str()) == 0) throw std::runtime_error(path.string() + ": not a PNG file");
  image.reader->Update();
  vtkImageData* img = image.reader->GetOutput();
  auto* scalars = vtkUnsignedCharArray::SafeDownCast(img->GetPointData()->GetScalars());
  if (scalars == nullptr) throw std::runtime_error(path.string() + ": not an 8-bit PNG");
  const int* dims = img->GetDimensions();
  image.width = dims[0];
  image.height = dims[1];
  image.components = scalars->GetNumberOfComponents();
  image.data = scalars->GetPointer(0);
}

}  // namespace

void add_image_diff_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("compare-images", "Share of pixels that differ between two PNG images of one size");
  struct Options {
    std::filesystem::path a, b;
    int tolerance = 3;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("a", o->a, "PNG image (the reference)")->required();
  cmd->add_option("b", o->b, "PNG image of the same size")->required();
  cmd->add_option("--tolerance", o->tolerance, "Differences up to N/255 in every channel count as equal")
      ->capture_default_str()
      ->check(CLI::Range(0, 255));
  cmd->callback([o] {
    Rgb8Image a, b;
    read(o->a, a);
    read(o->b, b);
    if (a.width != b.width || a.height != b.height) {
      throw std::runtime_error(o->b.string() + ": " + std::to_string(b.width) + "x" + std::to_string(b.height) +
                               ", but " + o->a.string() + " is " + std::to_string(a.width) + "x" +
                               std::to_string(a.height));
    }
    const std::size_t pixels = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
    std::size_t differ = 0;
    int largest = 0;
    for (std::size_t p = 0; p < pixels; ++p) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) {
        const int ca = a.data[p * a.components + static_cast<std::size_t>(std::min(c, a.components - 1))];
        const int cb = b.data[p * b.components + static_cast<std::size_t>(std::min(c, b.components - 1))];
        worst = std::max(worst, std::abs(ca - cb));
      }
      differ += worst > o->tolerance;
      largest = std::max(largest, worst);
    }
    std::printf("%zu of %zu pixels (%.4f%%) differ by more than %d/255; within: %.4f%%; largest difference %d/255\n",
                differ, pixels, 100.0 * static_cast<double>(differ) / static_cast<double>(pixels), o->tolerance,
                100.0 - 100.0 * static_cast<double>(differ) / static_cast<double>(pixels), largest);
  });
}

}  // namespace terravol::app::cli
