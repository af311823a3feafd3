#include "app/output/frame_sink.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "app/output/png_output.h"

extern char** environ;

namespace terravol::app::output {

namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The last non-empty line of a small text file (ffmpeg's stderr), or "".
std::string last_line(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty() && line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return last;
}

}  // namespace

VideoSink::VideoSink(const std::filesystem::path& output, int width, int height, double fps, int crf, bool overwrite)
    : output_(output), frame_bytes_(static_cast<std::size_t>(width) * height * 3), overwrite_(overwrite) {
  if (width <= 0 || height <= 0 || width % 2 != 0 || height % 2 != 0) {
    throw std::invalid_argument("VideoSink: size " + std::to_string(width) + "x" + std::to_string(height) +
                                " is not even and positive");
  }
  if (!overwrite && std::filesystem::exists(output)) {
    throw std::runtime_error(output.string() + ": exists (use --force to overwrite)");
  }
  const auto ffmpeg = find_program("ffmpeg");
  if (!ffmpeg) throw std::runtime_error("ffmpeg not found on PATH (needed for video output; use -o FOLDER/ for PNG frames)");
  const std::string pid = std::to_string(::getpid());
  tmp_ = output.parent_path() / (output.stem().string() + ".tmp-" + pid + output.extension().string());
  log_ = std::filesystem::temp_directory_path() / ("terravol-ffmpeg-" + pid + ".log");

  char size[32], rate[32];
  std::snprintf(size, sizeof size, "%dx%d", width, height);
  std::snprintf(rate, sizeof rate, "%.6g", fps);
  const std::string crf_text = std::to_string(crf);
  const std::string program = ffmpeg->string(), tmp = tmp_.string(), log = log_.string();
  std::vector<const char*> argv = {program.c_str(), "-hide_banner", "-loglevel", "error", "-nostdin", "-y",
                                   "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", size, "-r", rate, "-i", "-",
                                   "-c:v", "libx264", "-crf", crf_text.c_str(), "-pix_fmt", "yuv420p",
                                   tmp.c_str(), nullptr};

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot make a pipe to ffmpeg: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF);
  posix_spawnattr_setpgroup(&attr, 0);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  pid_t pid_child = -1;
  const int rc = posix_spawn(&pid_child, program.c_str(), &actions, &attr, const_cast<char* const*>(argv.data()), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  ::close(fds[0]);
  if (rc != 0) {
    ::close(fds[1]);
    throw std::runtime_error(program + ": cannot start (" + std::strerror(rc) + ")");
  }
  pid_ = pid_child;
  pipe_ = fds[1];
  // A dead ffmpeg must show as EPIPE from write(), not kill terravol.
  ::signal(SIGPIPE, SIG_IGN);
}

VideoSink::~VideoSink() {
  if (!finished_) {
    if (pid_ > 0) ::kill(pid_, SIGKILL);
    stop_ffmpeg();
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
  std::error_code ec;
  std::filesystem::remove(log_, ec);
}

void VideoSink::stop_ffmpeg() {
  if (pipe_ >= 0) ::close(pipe_);
  pipe_ = -1;
  if (pid_ > 0) {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  pid_ = -1;
}

void VideoSink::fail(const std::string& what) {
  if (pid_ > 0) ::kill(pid_, SIGKILL);
  stop_ffmpeg();
  std::error_code ec;
  std::filesystem::remove(tmp_, ec);
  finished_ = true;  // nothing left for the destructor
  const std::string detail = last_line(log_);
  throw std::runtime_error(output_.string() + ": " + what + (detail.empty() ? "" : ": " + detail));
}

void VideoSink::write(long index, std::span<const std::uint8_t> rgb) {
  if (rgb.size() != frame_bytes_) {
    throw std::invalid_argument("VideoSink::write: frame " + std::to_string(index) + " has " +
                                std::to_string(rgb.size()) + " bytes, expected " + std::to_string(frame_bytes_));
  }
  if (pipe_ < 0) throw std::logic_error("VideoSink::write after finish");
  const std::uint8_t* p = rgb.data();
  std::size_t left = rgb.size();
  while (left > 0) {
    const ssize_t n = ::write(pipe_, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("ffmpeg stopped taking frames at frame " + std::to_string(index));
    p += n;
    left -= static_cast<std::size_t>(n);
  }
}

void VideoSink::finish() {
  if (finished_) return;
  ::close(pipe_);
  pipe_ = -1;
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    fail(WIFEXITED(status) ? "ffmpeg failed (exit status " + std::to_string(WEXITSTATUS(status)) + ")"
                           : "ffmpeg was killed (signal " + std::to_string(WTERMSIG(status)) + ")");
  }
  if (!overwrite_ && std::filesystem::exists(output_)) fail("appeared while encoding; not overwritten");
  std::error_code ec;
  std::filesystem::rename(tmp_, output_, ec);
  if (ec) fail("cannot rename " + tmp_.string() + " to it (" + ec.message() + ")");
  finished_ = true;
}

PngSequenceSink::PngSequenceSink(const std::filesystem::path& folder, int width, int height, int digits, int level)
    : folder_(folder), width_(width), height_(height), digits_(digits), level_(level) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec || !std::filesystem::is_directory(folder)) {
    throw std::runtime_error(folder.string() + ": cannot make the folder (" + ec.message() + ")");
  }
}

void PngSequenceSink::write(long index, std::span<const std::uint8_t> rgb) {
  write_png(folder_ / frame_name(index, digits_), encode_png(rgb, width_, height_, 3, level_), true);
}

std::string frame_name(long index, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "frame_%0*ld.png", digits, index);
  return b;
}

int frame_digits(long last_index) {
  int d = 1;
  for (long v = std::max(last_index, 0L); v >= 10; v /= 10) ++d;
  return std::max(d, 6);
}

long existing_frames(const std::filesystem::path& folder, long first, long last, int digits) {
  long n = 0;
  for (long i = first; i <= last; ++i) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(folder / frame_name(i, digits), ec)) ++n;
  }
  return n;
}

std::optional<long> first_missing_frame(const std::filesystem::path& folder, long first, long last, int digits) {
  for (long i = first; i <= last; ++i) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(folder / frame_name(i, digits), ec)) return i;
  }
  return std::nullopt;
}

std::vector<std::uint8_t> downsample_box(std::span<const std::uint8_t> rgb, int width, int height, int factor) {
  const std::size_t big_w = static_cast<std::size_t>(width) * factor;
  if (factor < 1 || rgb.size() != big_w * height * factor * 3) {
    throw std::invalid_argument("downsample_box: " + std::to_string(rgb.size()) + " bytes for " +
                                std::to_string(width) + "x" + std::to_string(height) + " times " +
                                std::to_string(factor));
  }
  if (factor == 1) return std::vector<std::uint8_t>(rgb.begin(), rgb.end());
  std::vector<std::uint8_t> out(static_cast<std::size_t>(width) * height * 3);
  const unsigned n = static_cast<unsigned>(factor * factor);
  std::vector<unsigned> sums(static_cast<std::size_t>(width) * 3);
  for (int y = 0; y < height; ++y) {
    std::fill(sums.begin(), sums.end(), 0u);
    for (int sy = 0; sy < factor; ++sy) {
      const std::uint8_t* src = rgb.data() + (static_cast<std::size_t>(y) * factor + sy) * big_w * 3;
      for (int x = 0; x < width; ++x) {
        for (int sx = 0; sx < factor; ++sx) {
          const std::uint8_t* px = src + (static_cast<std::size_t>(x) * factor + sx) * 3;
          for (int c = 0; c < 3; ++c) sums[static_cast<std::size_t>(x) * 3 + c] += px[c];
        }
      }
    }
    std::uint8_t* dst = out.data() + static_cast<std::size_t>(y) * width * 3;
    for (std::size_t i = 0; i < sums.size(); ++i) dst[i] = static_cast<std::uint8_t>((sums[i] + n / 2) / n);
  }
  return out;
}

std::optional<std::filesystem::path> find_program(const std::string& name) {
  if (name.find('/') != std::string::npos) {
    if (::access(name.c_str(), X_OK) == 0) return std::filesystem::path(name);
    return std::nullopt;
  }
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::filesystem::path p = std::filesystem::path(dir.empty() ? "." : dir) / name;
    std::error_code ec;
    if (std::filesystem::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0) return p;
  }
  return std::nullopt;
}

std::string progress_line(long done, long total, long done_now, double elapsed_s, int bar_width) {
  total = std::max(total, 1L);
  done = std::clamp(done, 0L, total);
  const int marks = static_cast<int>(static_cast<long long>(bar_width) * done / total);
  std::string bar(static_cast<std::size_t>(bar_width) + 2, '-');
  bar.front() = '[';
  bar.back() = ']';
  std::fill_n(bar.begin() + 1, marks, '#');
  char b[160];
  if (done_now > 0 && elapsed_s > 0.0) {
    const double fps = done_now / elapsed_s;
    const long left = std::lround((total - done) / fps);
    std::snprintf(b, sizeof b, " %*ld/%ld frames  %5.1f fps  %ld:%02ld left", static_cast<int>(std::to_string(total).size()),
                  done, total, fps, left / 60, left % 60);
  } else {
    std::snprintf(b, sizeof b, " %*ld/%ld frames    --- fps  --:-- left", static_cast<int>(std::to_string(total).size()),
                  done, total);
  }
  bar += b;
  return bar;
}

Progress::Progress(std::FILE* out, long total, long already_done)
    : out_(out), total_(total), already_(already_done), tty_(::isatty(::fileno(out)) != 0), start_(now_s()),
      done_(already_done) {}

void Progress::update(long done) {
  done_ = done;
  const double t = now_s();
  if (tty_) {
    if (last_draw_ >= 0.0 && t - last_draw_ < 0.2 && done < total_) return;
    std::fprintf(out_, "\r%s", progress_line(done, total_, done - already_, t - start_).c_str());
  } else {
    const long decile = total_ > 0 ? 10 * done / total_ : 10;
    if (decile == last_decile_ || done >= total_) return;  // the end: finish() prints it
    std::fprintf(out_, "%s\n", progress_line(done, total_, done - already_, t - start_).c_str());
    last_decile_ = decile;
  }
  last_draw_ = t;
  std::fflush(out_);
}

void Progress::finish() {
  const std::string line = progress_line(done_, total_, done_ - already_, now_s() - start_);
  std::fprintf(out_, tty_ ? "\r%s\n" : "%s\n", line.c_str());
  std::fflush(out_);
}

}  // namespace terravol::app::output
