#include "volume/isolated.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <new>
#include <stdexcept>

#include "io/error.h"
#include "volume/reader_common.h"

namespace terravol::volume::detail {

namespace {

// The process's current virtual size in bytes (/proc/self/statm), 0 when unknown.
std::size_t virtual_size() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  if (!(statm >> pages)) return 0;
  return pages * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}

void write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
}

}  // namespace

IsolatedRun run_isolated(const std::function<std::string()>& work, std::size_t extra_memory, double timeout_seconds) {
  IsolatedRun run;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    run.failure = std::string("cannot create a pipe (") + std::strerror(errno) + ")";
    return run;
  }
  const std::size_t limit = virtual_size() + extra_memory;
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    run.failure = std::string("cannot fork (") + std::strerror(errno) + ")";
    return run;
  }
  if (pid == 0) {
    ::close(fds[0]);
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) {
      ::dup2(null, 1);
      ::dup2(null, 2);
    }
    if (limit > extra_memory) {
      const rlimit r{limit, limit};
      ::setrlimit(RLIMIT_AS, &r);
    }
    const std::string out = work();
    write_all(fds[1], out.data(), out.size());
    ::_exit(0);
  }

  ::close(fds[1]);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
  bool timed_out = false;
  char buffer[1 << 16];
  while (true) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // end of output (or an error)
    run.output.append(buffer, static_cast<std::size_t>(n));
  }
  if (timed_out) ::kill(pid, SIGKILL);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  run.timed_out = timed_out;
  if (timed_out) {
    char b[64];
    std::snprintf(b, sizeof b, "took longer than %g s", timeout_seconds);
    run.failure = b;
  } else if (WIFSIGNALED(status)) {
    run.failure = "crashed (signal " + std::to_string(WTERMSIG(status)) + ": " + ::strsignal(WTERMSIG(status)) + ")";
  } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    run.failure = "failed (exit status " + std::to_string(WEXITSTATUS(status)) + ")";
  } else {
    run.ok = true;
  }
  return run;
}

Volume parse_isolated(std::string_view bytes, const std::string& source, const std::string& format,
                      const std::function<Volume()>& parse) {
  const double timeout = 30.0 + static_cast<double>(bytes.size()) / 20e6;
  const std::size_t memory = (std::size_t{3} << 30) + 4 * bytes.size();
  // The child's answer: 'V' + a serialised volume, or 'E' + source + NUL + problem.
  const std::function<std::string()> work =
      [&]() -> std::string {
        try {
          return "V" + serialize_volume(parse());
        } catch (const io::FormatError& e) {
          const std::string what = e.what();
          return "E" + e.source() + '\0' + what.substr(std::min(what.size(), e.source().size() + 2));
        } catch (const std::bad_alloc&) {
          return "E" + source + '\0' + "corrupt " + format + " file (absurd sizes)";
        } catch (const std::exception& e) {
          return "E" + source + '\0' + "corrupt " + format + " file (" + printable(e.what(), 300) + ")";
        } catch (...) {
          return "E" + source + '\0' + "corrupt " + format + " file";
        }
      };
  IsolatedRun run = run_isolated(work, memory, timeout);
  if (run.timed_out) run = run_isolated(work, memory, timeout);  // (see the header)
  if (!run.ok) throw io::FormatError(source, "corrupt " + format + " file (the " + format + " reader " + run.failure + ")");
  if (run.output.empty()) throw io::FormatError(source, "corrupt " + format + " file (no answer from the reader)");
  if (run.output[0] == 'E') {
    const std::size_t nul = run.output.find('\0');
    if (nul == std::string::npos) throw io::FormatError(source, "corrupt " + format + " file");
    throw io::FormatError(run.output.substr(1, nul - 1), run.output.substr(nul + 1));
  }
  return deserialize_volume(std::string_view(run.output).substr(1), source);
}

}  // namespace terravol::volume::detail
