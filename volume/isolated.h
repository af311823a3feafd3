// Running a parser that is not safe on hostile input (OpenVDB's reader corrupts the heap or
// crashes on some corrupt files: tests/volume/readers_test.cpp, VdbHostile) in a child
// process, so that a bad file costs an error message instead of the process.
// Private to volume/, and objects/ (textures decoded by VTK).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

#include "volume/volume.h"

namespace terravol::volume::detail {

struct IsolatedRun {
  bool ok = false;      // the child finished and its output is complete
  std::string output;   // what work() returned
  std::string failure;  // when !ok: what happened, e.g. "crashed (signal 11: Segmentation fault)"
  bool timed_out = false;  // the child was killed after timeout_seconds
};

// Forks; the child sends stdout and stderr to /dev/null, limits its address space to the
// parent's current size plus extra_memory bytes, runs work() and writes the string it returns
// to a pipe, then _exit(0)s without running destructors. The parent reads the output, killing
// the child after timeout_seconds. work() must not throw, must not use threads (TBB) and must
// not rely on locks other threads of the parent may hold (the child has one thread).
// The caller should serialise calls that touch the same libraries (see vdb_file.cpp).
IsolatedRun run_isolated(const std::function<std::string()>& work, std::size_t extra_memory, double timeout_seconds);

// Parses a volume in an isolated child: parse() runs there (its io::FormatError and other
// exceptions travel back as a FormatError; its Volume through serialize_volume), and a crash,
// a timeout (30 s + 1 s per 20 MB of input) or exhausted memory (3 GiB + 4 x the input) ends
// as FormatError(source, "corrupt FORMAT file (the FORMAT reader crashed ...)"). A timeout is
// tried once more in a new child first: a child forked while another of the parent's threads
// held a lock it then needs waits forever. That is the likely cause of the one timeout seen on
// a valid file (a CI run's render of a small VDB, 2026-12-06; never reproduced). The same
// moment twice is far less likely, and a file that truly hangs its reader costs twice the time.
// The caller holds whatever lock keeps its other threads out of the libraries parse() uses.
Volume parse_isolated(std::string_view bytes, const std::string& source, const std::string& format,
                      const std::function<Volume()>& parse);

}  // namespace terravol::volume::detail
