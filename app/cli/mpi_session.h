// A command's MPI world when it runs under mpirun (Open MPI, Debian's mpi-default-dev), or a
// world of one process without MPI. Only `terravol rf` splits its work over ranks.
#pragma once

#include <cstddef>
#include <exception>
#include <span>
#include <string>
#include <vector>

namespace terravol::app::cli {

// Thrown on the ranks other than 0 when a command fails there too: rank 0 prints the one line,
// the others exit with status 1 silently (main.cpp).
class QuietFailure : public std::exception {
 public:
  const char* what() const noexcept override { return "failed on another rank"; }
};

class MpiSession {
 public:
  // Initialises MPI (MPI_Init_thread, funneled: only the calling thread talks MPI) when an MPI
  // launcher started the process (Open MPI's OMPI_COMM_WORLD_SIZE, or PMI_SIZE / PMIX_RANK in the
  // environment); otherwise MPI is not touched and the world is this process alone. Errors of
  // MPI calls return (MPI_ERRORS_RETURN) and throw std::runtime_error("MPI: ...").
  MpiSession();
  ~MpiSession();  // MPI_Finalize when initialised here
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  bool active() const { return active_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  // Ranks on this node (Open MPI's OMPI_COMM_WORLD_LOCAL_SIZE; 1 when unknown): they share its
  // cores.
  int local_size() const { return local_size_; }

  // Collective: every rank passes its error ("" when it did fine). Returns "" when every rank did
  // fine, else the message of the lowest failing rank, on every rank.
  std::string first_error(const std::string& error) const;
  // Collective: the sum, the minimum and the maximum over the ranks.
  double sum(double value) const;
  double min(double value) const;
  double max(double value) const;
  // Point to point, for gathering on rank 0 (any size; sent in chunks below 2^31 values).
  void send_to_root(std::span<const float> values) const;
  void receive(int from, std::span<float> values) const;
  // Prints "terravol: MESSAGE" on stderr and ends every rank (MPI_Abort, status 1): for a failure
  // on rank 0 while other ranks may wait for it.
  [[noreturn]] void abort(const std::string& message) const;

 private:
  bool active_ = false;
  int rank_ = 0, size_ = 1, local_size_ = 1;
};

}  // namespace terravol::app::cli
