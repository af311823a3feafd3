// MPI for terravol's commands (mpi_session.h).
#include "app/cli/mpi_session.h"

// The C API only: Open MPI's mpi.h would otherwise pull in its deprecated C++ bindings, which
// need libmpi_cxx.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace terravol::app::cli {

namespace {

constexpr std::size_t kChunk = std::size_t{1} << 26;  // floats per message

void check(int code, const char* what) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw std::runtime_error(std::string("MPI: ") + what + " failed (" + std::string(text, static_cast<std::size_t>(length)) + ")");
}

double all_reduce(double value, MPI_Op op) {
  double out = 0.0;
  check(MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, op, MPI_COMM_WORLD), "MPI_Allreduce");
  return out;
}

bool launched_by_mpi() {
  for (const char* key : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"}) {
    if (std::getenv(key) != nullptr) return true;
  }
  return false;
}

}  // namespace

MpiSession::MpiSession() {
  if (!launched_by_mpi()) return;
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) {
    int provided = 0;
    check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  }
  active_ = true;
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  check(MPI_Comm_rank(MPI_COMM_WORLD, &rank_), "MPI_Comm_rank");
  check(MPI_Comm_size(MPI_COMM_WORLD, &size_), "MPI_Comm_size");
  if (const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE")) local_size_ = std::max(1, std::atoi(local));
}

MpiSession::~MpiSession() {
  if (active_) MPI_Finalize();
}

std::string MpiSession::first_error(const std::string& error) const {
  if (!active_) return error;
  const int failed = error.empty() ? 0 : 1;
  std::vector<int> all(static_cast<std::size_t>(size_));
  check(MPI_Allgather(&failed, 1, MPI_INT, all.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
  const auto first = std::find(all.begin(), all.end(), 1);
  if (first == all.end()) return {};
  const int root = static_cast<int>(first - all.begin());
  int length = rank_ == root ? static_cast<int>(std::min<std::size_t>(error.size(), 4096)) : 0;
  check(MPI_Bcast(&length, 1, MPI_INT, root, MPI_COMM_WORLD), "MPI_Bcast");
  std::string message = rank_ == root ? error.substr(0, static_cast<std::size_t>(length)) : std::string(static_cast<std::size_t>(length), ' ');
  check(MPI_Bcast(message.data(), length, MPI_CHAR, root, MPI_COMM_WORLD), "MPI_Bcast");
  if (root != 0) message = "rank " + std::to_string(root) + ": " + message;
  return message;
}

double MpiSession::sum(double value) const { return active_ ? all_reduce(value, MPI_SUM) : value; }
double MpiSession::min(double value) const { return active_ ? all_reduce(value, MPI_MIN) : value; }
double MpiSession::max(double value) const { return active_ ? all_reduce(value, MPI_MAX) : value; }

void MpiSession::send_to_root(std::span<const float> values) const {
  for (std::size_t at = 0; at < values.size(); at += kChunk) {
    const int n = static_cast<int>(std::min(kChunk, values.size() - at));
    check(MPI_Send(values.data() + at, n, MPI_FLOAT, 0, 0, MPI_COMM_WORLD), "MPI_Send");
  }
}

void MpiSession::receive(int from, std::span<float> values) const {
  for (std::size_t at = 0; at < values.size(); at += kChunk) {
    const int n = static_cast<int>(std::min(kChunk, values.size() - at));
    MPI_Status status;
    check(MPI_Recv(values.data() + at, n, MPI_FLOAT, from, 0, MPI_COMM_WORLD, &status), "MPI_Recv");
    int got = 0;
    MPI_Get_count(&status, MPI_FLOAT, &got);
    if (got != n) {
      throw std::runtime_error("MPI: rank " + std::to_string(from) + " sent " + std::to_string(got) + " values, not " +
                               std::to_string(n));
    }
  }
}

void MpiSession::abort(const std::string& message) const {
  std::fprintf(stderr, "terravol: %s\n", message.c_str());
  std::fflush(stderr);
  if (active_) MPI_Abort(MPI_COMM_WORLD, 1);
  std::_Exit(1);
}

}  // namespace terravol::app::cli
