// Reading rendered PNGs in tests and comparing them pixel by pixel (vtkPNGReader).
#pragma once

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <vector>

namespace terravol::test {

using Rgb8 = std::array<std::uint8_t, 3>;

struct Image {
  int width = 0, height = 0;
  std::vector<Rgb8> pixels;         // row 0 at the TOP of the image, as it is seen
  std::vector<std::uint8_t> alpha;  // the same order; 255 where the PNG has no alpha
  const Rgb8& at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

// The output of a PNG reader as RGB and alpha, row 0 at the top (grey expanded).
inline Image image_of(vtkPNGReader* reader) {
  Image img;
  reader->Update();
  vtkImageData* data = reader->GetOutput();
  vtkDataArray* scalars = data->GetPointData()->GetScalars();
  if (scalars == nullptr) return img;
  int dims[3];
  data->GetDimensions(dims);
  img.width = dims[0];
  img.height = dims[1];
  img.pixels.resize(static_cast<std::size_t>(img.width) * img.height);
  img.alpha.assign(img.pixels.size(), 255);
  const int comps = scalars->GetNumberOfComponents();
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const vtkIdType id = static_cast<vtkIdType>(y) * img.width + x;  // VTK's row 0 is the bottom
      Rgb8& p = img.pixels[static_cast<std::size_t>(img.height - 1 - y) * img.width + x];
      for (int k = 0; k < 3; ++k) {
        p[k] = static_cast<std::uint8_t>(scalars->GetComponent(id, comps >= 3 ? k : 0));
      }
      if (comps == 2 || comps == 4) {
        img.alpha[static_cast<std::size_t>(img.height - 1 - y) * img.width + x] =
            static_cast<std::uint8_t>(scalars->GetComponent(id, comps - 1));
      }
    }
  }
  return img;
}

// The PNG at `path`; an empty image (width 0) when the file is missing or not a PNG.
inline Image read_png(const std::filesystem::path& path) {
  vtkNew<vtkPNGReader> reader;
  if (!std::filesystem::exists(path) || !reader->CanReadFile(path.c_str())) return {};
  reader->SetFileName(path.c_str());
  return image_of(reader);
}

// PNG bytes in memory.
inline Image decode_png(const std::vector<std::uint8_t>& bytes) {
  vtkNew<vtkPNGReader> reader;
  reader->SetMemoryBuffer(bytes.data());
  reader->SetMemoryBufferLength(static_cast<vtkIdType>(bytes.size()));
  return image_of(reader);
}

// RGB bytes, width * height * 3, top row first (app::render::window_rgb); an empty image
// (width 0) when the byte count does not match the size.
inline Image image_of_rgb(const std::vector<std::uint8_t>& rgb, int width, int height) {
  Image img;
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<std::size_t>(width) * height * 3) return img;
  img.width = width;
  img.height = height;
  img.pixels.resize(static_cast<std::size_t>(width) * height);
  for (std::size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = {rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]};
  return img;
}

// Whether two colours differ by at most `tolerance` in every channel.
inline bool same_color(const Rgb8& a, const Rgb8& b, int tolerance) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(int(a[k]) - int(b[k])) > tolerance) return false;
  return true;
}

// Share (0..1) of pixels whose colours differ by more than `tolerance` in some channel; 1 when
// the sizes differ or an image is missing (empty), so that a comparison with a failed render
// fails instead of reading out of bounds.
inline double differing_share(const Image& a, const Image& b, int tolerance) {
  if (a.width != b.width || a.height != b.height || a.pixels.empty() || a.pixels.size() != b.pixels.size()) return 1.0;
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) differ += !same_color(a.pixels[i], b.pixels[i], tolerance);
  return a.pixels.empty() ? 0.0 : static_cast<double>(differ) / static_cast<double>(a.pixels.size());
}

// Share (0..1) of pixels of the given colour.
inline double color_share(const Image& img, const Rgb8& color, int tolerance) {
  std::size_t n = 0;
  for (const auto& p : img.pixels) n += same_color(p, color, tolerance);
  return img.pixels.empty() ? 0.0 : static_cast<double>(n) / static_cast<double>(img.pixels.size());
}

// Holes in the terrain: in each column, the background pixels below the topmost pixel that is
// not background (the terrain's horizon line). Returns how many there are; `first` gets the
// first one found (x, y), for messages.
inline std::size_t background_below_horizon(const Image& img, const Rgb8& background, int tolerance,
                                            std::array<int, 2>* first = nullptr) {
  std::size_t holes = 0;
  for (int x = 0; x < img.width; ++x) {
    int y = 0;
    while (y < img.height && same_color(img.at(x, y), background, tolerance)) ++y;
    for (; y < img.height; ++y) {
      if (same_color(img.at(x, y), background, tolerance)) {
        if (holes == 0 && first != nullptr) *first = {x, y};
        ++holes;
      }
    }
  }
  return holes;
}

}  // namespace terravol::test
