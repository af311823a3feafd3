// The pieces of `terravol fly` output that need no renderer: frame names, resuming, the box
// filter, the progress line, and the video sink's temporary file.
#include "app/output/frame_sink.h"
#include "app/output/png_output.h"

#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <algorithm>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "temp_dir.h"

namespace terravol::app::output {
namespace {

TEST(FrameSink, FrameNamesAreZeroPaddedAndSortInOrder) {
  EXPECT_EQ(frame_name(42, 6), "frame_000042.png");
  EXPECT_EQ(frame_digits(99), 6);
  EXPECT_EQ(frame_digits(1234567), 7);
  EXPECT_LT(frame_name(9, 6), frame_name(10, 6));
}

TEST(FrameSink, FirstMissingFrameSkipsThoseWritten) {
  test::TempDir dir;
  for (long i : {3L, 4L, 5L, 7L}) std::ofstream(dir.path() / frame_name(i, 6)) << "x";
  EXPECT_EQ(first_missing_frame(dir.path(), 3, 8, 6), 6);
  EXPECT_EQ(first_missing_frame(dir.path(), 0, 8, 6), 0);
  EXPECT_EQ(first_missing_frame(dir.path(), 3, 5, 6), std::nullopt);
  EXPECT_EQ(existing_frames(dir.path(), 0, 8, 6), 4);
  EXPECT_EQ(existing_frames(dir.path(), 6, 6, 6), 0);
}

TEST(FrameSink, BoxFilterAveragesEachBlockRoundingToNearest) {
  // 4 x 2 pixels to 2 x 1: blocks of 2 x 2.
  const std::vector<std::uint8_t> big = {
      0, 0, 0,  1, 2, 3,  10, 10, 10,  20, 20, 20,   // top row
      1, 2, 3,  2, 2, 2,  30, 30, 30,  255, 0, 1};   // bottom row
  const std::vector<std::uint8_t> small = downsample_box(big, 2, 1, 2);
  const std::vector<std::uint8_t> expected = {1, 2, 2, 79, 15, 15};  // (4,6,8)/4 rounds to (1,2,2)
  EXPECT_EQ(small, expected);
  EXPECT_EQ(downsample_box(big, 4, 2, 1), big);
  EXPECT_THROW(downsample_box(big, 3, 1, 2), std::invalid_argument);
}

TEST(FrameSink, BoxFilterOfAUniformImageIsUniform) {
  std::mt19937 rng(99);
  for (int trial = 0; trial < 20; ++trial) {
    const int f = 1 + static_cast<int>(rng() % 4), w = 1 + static_cast<int>(rng() % 9), h = 1 + static_cast<int>(rng() % 9);
    const std::uint8_t c[3] = {static_cast<std::uint8_t>(rng()), static_cast<std::uint8_t>(rng()), static_cast<std::uint8_t>(rng())};
    std::vector<std::uint8_t> big;
    for (int i = 0; i < w * f * h * f; ++i) big.insert(big.end(), c, c + 3);
    const auto small = downsample_box(big, w, h, f);
    ASSERT_EQ(small.size(), static_cast<std::size_t>(w * h * 3));
    for (int i = 0; i < w * h; ++i) {
      for (int k = 0; k < 3; ++k) ASSERT_EQ(small[static_cast<std::size_t>(i * 3 + k)], c[k]);
    }
  }
}

TEST(FrameSink, ProgressLineShowsFramesRateAndTimeLeft) {
  EXPECT_EQ(progress_line(50, 200, 50, 10.0, 10), "[##--------]  50/200 frames    5.0 fps  0:30 left");
  EXPECT_EQ(progress_line(0, 200, 0, 0.0, 4), "[----]   0/200 frames    --- fps  --:-- left");
  // A resumed run: the rate counts this run's frames only.
  EXPECT_EQ(progress_line(150, 200, 10, 2.0, 4), "[###-] 150/200 frames    5.0 fps  0:10 left");
}

TEST(FrameSink, PngRoundTripKeepsPixelsAndIsDeterministic) {
  std::vector<std::uint8_t> rgb(5 * 3 * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>(i * 7);
  const auto a = encode_png(rgb, 5, 3), b = encode_png(rgb, 5, 3);
  EXPECT_EQ(a, b);
  ASSERT_GT(a.size(), 8u);
  EXPECT_EQ(a[1], 'P');
  EXPECT_THROW(encode_png(rgb, 4, 3), std::invalid_argument);
}

// Every zlib level decodes (vtkPNGReader, not our encoder) to the same pixels; level 0 stores
// them, 9 is the smallest.
TEST(FrameSink, PngLevelsTradeSizeAndKeepPixels) {
  const int w = 64, h = 48;
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(w * h * 3));
  std::mt19937 rng(7);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>((i / 3) % 97 + (rng() % 4));
  std::vector<std::size_t> sizes;
  for (int level : {0, 1, 9}) {
    const std::vector<std::uint8_t> png = encode_png(rgb, w, h, 3, level);
    sizes.push_back(png.size());
    vtkNew<vtkPNGReader> reader;
    reader->SetMemoryBuffer(png.data());
    reader->SetMemoryBufferLength(png.size());
    reader->Update();
    vtkImageData* image = reader->GetOutput();
    ASSERT_EQ(image->GetNumberOfScalarComponents(), 3) << level;
    const auto* decoded = static_cast<const std::uint8_t*>(image->GetScalarPointer());
    for (int y = 0; y < h; ++y) {  // VTK's rows go bottom up
      ASSERT_TRUE(std::equal(decoded + static_cast<std::size_t>(y * w * 3), decoded + static_cast<std::size_t>((y + 1) * w * 3),
                             rgb.begin() + (h - 1 - y) * w * 3))
          << "level " << level << ", row " << y;
    }
  }
  EXPECT_GT(sizes[0], sizes[1]);
  EXPECT_GE(sizes[1], sizes[2]);
  EXPECT_THROW(encode_png(rgb, w, h, 3, 10), std::invalid_argument);
  EXPECT_THROW(encode_png(rgb, w, h, 3, -1), std::invalid_argument);
}

TEST(FrameSink, AbandonedVideoLeavesNoFile) {
  if (!find_program("ffmpeg")) GTEST_SKIP() << "ffmpeg not found on PATH";
  test::TempDir dir;
  const auto out = dir.path() / "clip.mp4";
  std::filesystem::path tmp;
  {
    VideoSink sink(out, 16, 8, 10.0, 30, false);
    tmp = sink.temporary();
    EXPECT_EQ(tmp.parent_path(), dir.path());
    EXPECT_EQ(tmp.extension(), ".mp4");
    const std::vector<std::uint8_t> frame(16 * 8 * 3, 128);
    sink.write(0, frame);
  }  // destroyed without finish(): an interrupted export
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(tmp));
}

TEST(FrameSink, FinishedVideoReplacesOnlyWithOverwrite) {
  if (!find_program("ffmpeg")) GTEST_SKIP() << "ffmpeg not found on PATH";
  test::TempDir dir;
  const auto out = dir.path() / "clip.mp4";
  std::ofstream(out) << "mine";
  EXPECT_THROW(VideoSink(out, 16, 8, 10.0, 30, false), std::runtime_error);
  VideoSink sink(out, 16, 8, 10.0, 30, true);
  const std::vector<std::uint8_t> frame(16 * 8 * 3, 200);
  for (int i = 0; i < 3; ++i) sink.write(i, frame);
  sink.finish();
  EXPECT_GT(std::filesystem::file_size(out), 100u);
  EXPECT_FALSE(std::filesystem::exists(sink.temporary()));
}

}  // namespace
}  // namespace terravol::app::output
