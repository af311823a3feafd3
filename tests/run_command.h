// Running the terravol executable from tests: exit status, output and wall time.
#pragma once

#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "temp_dir.h"

namespace terravol::test {

struct CommandResult {
  int status = -1;  // exit status; 128 + signal when killed; 124 when it timed out
  std::string out, err;
  double seconds = 0.0;
};

// Runs `LAUNCHER terravol ARGS` through the shell with a time limit (coreutils timeout); the
// launcher may be empty, or e.g. "mpirun -np 2".
inline CommandResult run_terravol_under(const std::string& launcher, const std::string& args, int timeout_s = 30) {
  static TempDir dir;
  const auto out = dir.path() / "stdout", err = dir.path() / "stderr";
  const std::string cmd = "timeout " + std::to_string(timeout_s) + " " + launcher + (launcher.empty() ? "" : " ") +
                          std::string(TERRAVOL_EXE) + " " + args + " >" + out.string() + " 2>" + err.string() +
                          " </dev/null";
  const auto t0 = std::chrono::steady_clock::now();
  const int raw = std::system(cmd.c_str());
  CommandResult r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  auto slurp = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// Runs `terravol ARGS` through the shell with a time limit (coreutils timeout).
inline CommandResult run_terravol(const std::string& args, int timeout_s = 30) {
  return run_terravol_under("", args, timeout_s);
}

}  // namespace terravol::test
