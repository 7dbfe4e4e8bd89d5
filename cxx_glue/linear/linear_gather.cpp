// A serial direct solver under MPI: the rows are gathered on rank 0, which
// factors and solves alone; the other ranks only send their rows and
// right-hand sides and receive their part of the solution. Memory and time
// of the factorisation are those of one process (docs/parallel.md).
#include <chrono>
#include <thread>
#include <vector>

#include "linear/linear.hpp"

namespace sp {
namespace {

class Gathered final : public LinearSolver {
 public:
  Gathered(MPI_Comm comm, std::unique_ptr<LinearSolver> serial) : serial_(std::move(serial)) {
    MPI_Comm_dup(comm, &comm_);
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
  }
  ~Gathered() override { MPI_Comm_free(&comm_); }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    // Row counts and entry counts of every rank (their order is the row order).
    int mine[2] = {A.n_rows, A.row_ptr[A.n_rows]};
    std::vector<int> counts(2 * size_);
    MPI_Gather(mine, 2, MPI_INT, counts.data(), 2, MPI_INT, 0, comm_);
    std::vector<int> row_counts(size_), nnz_counts(size_), row_displs(size_, 0), nnz_displs(size_, 0);
    if (rank_ == 0) {
      for (int r = 0; r < size_; ++r) {
        row_counts[r] = counts[2 * r];
        nnz_counts[r] = counts[2 * r + 1];
        if (r > 0) {
          row_displs[r] = row_displs[r - 1] + row_counts[r - 1];
          nnz_displs[r] = nnz_displs[r - 1] + nnz_counts[r - 1];
        }
      }
      const int n = row_displs[size_ - 1] + row_counts[size_ - 1];
      const int nnz = nnz_displs[size_ - 1] + nnz_counts[size_ - 1];
      lengths_.resize(n);
      col_.resize(nnz);
      val_.resize(nnz);
    }
    row_counts_ = row_counts;
    row_displs_ = row_displs;
    std::vector<int> my_lengths(A.n_rows);
    for (int i = 0; i < A.n_rows; ++i) my_lengths[i] = A.row_ptr[i + 1] - A.row_ptr[i];
    MPI_Gatherv(my_lengths.data(), A.n_rows, MPI_INT, lengths_.data(), row_counts.data(),
                row_displs.data(), MPI_INT, 0, comm_);
    MPI_Gatherv(A.col, mine[1], MPI_INT, col_.data(), nnz_counts.data(), nnz_displs.data(),
                MPI_INT, 0, comm_);
    MPI_Gatherv(A.val, mine[1], MPI_DOUBLE, val_.data(), nnz_counts.data(), nnz_displs.data(),
                MPI_DOUBLE, 0, comm_);
    n_local_ = A.n_rows;
    bool ok = true;  // rank 0 reports; the caller makes the ranks agree
    if (rank_ == 0) {
      const int n = (int)lengths_.size();
      ptr_.assign(n + 1, 0);
      for (int i = 0; i < n; ++i) ptr_[i + 1] = ptr_[i] + lengths_[i];
      CsrRows all;
      all.n_global = n;
      all.first_row = 0;
      all.n_rows = n;
      all.row_ptr = ptr_.data();
      all.col = col_.data();
      all.val = val_.data();
      ok = serial_->factor(all, same_pattern, why);
    }
    idle_until_rank0_done();
    return ok;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    if (rank_ == 0) {
      b_.resize(lengths_.size());
      x_.assign(lengths_.size(), 0.0);
    }
    MPI_Gatherv(b, n_local_, MPI_DOUBLE, b_.data(), row_counts_.data(), row_displs_.data(),
                MPI_DOUBLE, 0, comm_);
    bool ok = true;
    if (rank_ == 0) ok = serial_->solve(b_.data(), x_.data(), why);
    // Scattered even after a failure, so that no rank waits forever.
    MPI_Scatterv(x_.data(), row_counts_.data(), row_displs_.data(), MPI_DOUBLE, x, n_local_,
                 MPI_DOUBLE, 0, comm_);
    return ok;
  }

  int symbolic_count() const override {
    int mine = rank_ == 0 ? serial_->symbolic_count() : 0;
    return mine;  // meaningful on rank 0
  }
  bool out_of_memory() const override { return rank_ == 0 && serial_->out_of_memory(); }

 private:
  // Ranks > 0 wait for rank 0's factorisation without spinning: the next
  // MPI collective would busy-poll a core for seconds, which slows rank 0
  // down on a machine shared with other jobs or with more ranks than cores.
  void idle_until_rank0_done() {
    MPI_Request req;
    MPI_Ibarrier(comm_, &req);
    int done = 0;
    MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    while (!done) {
      std::this_thread::sleep_for(std::chrono::microseconds(500));
      MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    }
  }

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1, n_local_ = 0;
  std::unique_ptr<LinearSolver> serial_;
  std::vector<int> lengths_, ptr_, col_, row_counts_, row_displs_;
  std::vector<double> val_, b_, x_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_gathered(MPI_Comm comm, std::unique_ptr<LinearSolver> serial) {
  return std::make_unique<Gathered>(comm, std::move(serial));
}

}  // namespace sp
