// Where the frames of `terravol fly` go: an H.264 video through ffmpeg, or a folder of numbered
// PNG files; and the small pieces around them (the progress line, resuming a PNG export, box
// downsampling for supersampled frames). Nothing here renders.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace terravol::app::output {

// Takes frames in order; finish() completes the output. A sink destroyed without finish()
// removes what is incomplete (the video's temporary file; PNG frames already written stay,
// each complete, for --resume).
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // Frame `index` (0-based from the path's start): rgb holds width * height * 3 bytes, top row
  // first. Throws std::runtime_error (one line, naming the output) on I/O errors.
  virtual void write(long index, std::span<const std::uint8_t> rgb) = 0;
  virtual void finish() = 0;
};

// H.264 in an MP4 (or .mkv, .mov) container. Runs `ffmpeg -f rawvideo -pix_fmt rgb24 -s WxH -r
// FPS -i - -c:v libx264 -crf CRF -pix_fmt yuv420p TMP` (found on PATH, in its own process group
// so that Ctrl-C reaches only terravol), TMP being OUTPUT's name with ".tmp-PID" before the
// extension in the same folder, and feeds it raw frames through a pipe. finish() waits for
// ffmpeg and renames TMP to the output. Preconditions: width and height even and positive, fps
// > 0, crf in [0, 51]. Throws std::runtime_error when the output exists and !overwrite, ffmpeg
// cannot be started, or exits with an error (with its last line of stderr).
class VideoSink : public FrameSink {
 public:
  VideoSink(const std::filesystem::path& output, int width, int height, double fps, int crf, bool overwrite);
  ~VideoSink() override;
  VideoSink(const VideoSink&) = delete;
  VideoSink& operator=(const VideoSink&) = delete;
  void write(long index, std::span<const std::uint8_t> rgb) override;
  void finish() override;
  const std::filesystem::path& temporary() const { return tmp_; }

 private:
  [[noreturn]] void fail(const std::string& what);
  void stop_ffmpeg();
  std::filesystem::path output_, tmp_, log_;
  std::size_t frame_bytes_;
  bool overwrite_;
  int pipe_ = -1;
  int pid_ = -1;
  bool finished_ = false;
};

// A folder of PNG files named frame_name(index, digits), each written through a temporary
// file and a rename (a reader or a resumed export never sees half a frame), at zlib
// compression `level` (encode_png). The folder is created when missing. Existing frames are
// replaced (the caller decides; see existing_frames).
class PngSequenceSink : public FrameSink {
 public:
  PngSequenceSink(const std::filesystem::path& folder, int width, int height, int digits, int level = 5);
  void write(long index, std::span<const std::uint8_t> rgb) override;
  void finish() override {}

 private:
  std::filesystem::path folder_;
  int width_, height_, digits_, level_;
};

// "frame_000042.png" with `digits` digits (at least as many as index needs).
std::string frame_name(long index, int digits);
// Digits for the names of frames 0 .. last_index: at least 6.
int frame_digits(long last_index);
// Frames of [first, last] present in `folder` (regular files named frame_name(i, digits)).
long existing_frames(const std::filesystem::path& folder, long first, long last, int digits);
// The first frame of [first, last] missing from `folder`; nullopt when all are there.
std::optional<long> first_missing_frame(const std::filesystem::path& folder, long first, long last, int digits);


// Averages each factor x factor block of an RGB image (width * factor by height * factor
// pixels) into one pixel, rounding to nearest: supersampling's box filter. factor 1 copies.
// Preconditions: factor >= 1, rgb.size() == width * factor * height * factor * 3.
std::vector<std::uint8_t> downsample_box(std::span<const std::uint8_t> rgb, int width, int height, int factor);

// The executable `name` on $PATH (or name itself when it holds a '/'); nullopt when none.
std::optional<std::filesystem::path> find_program(const std::string& name);

// One progress line: "[#####-----]  120/400 frames  25.3 fps  0:11 left" (bar_width marks);
// fps over `elapsed_s` for `done_now` frames rendered in this run; "--:--" while unknown.
std::string progress_line(long done, long total, long done_now, double elapsed_s, int bar_width = 30);

// The progress bar on a stream (stderr): redrawn in place with '\r' at most every 0.2 s on a
// terminal; elsewhere (a log, a test) one line at every 10% and at the end.
class Progress {
 public:
  Progress(std::FILE* out, long total, long already_done);
  void update(long done);  // frames done so far, already_done included
  void finish();           // the last line and a newline
 private:
  std::FILE* out_;
  long total_, already_;
  bool tty_;
  double start_;
  double last_draw_ = -1.0;
  long last_decile_ = -1;
  long done_ = 0;
};

}  // namespace terravol::app::output
