#include "epetra_rows.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace sp {

EpetraRows::EpetraRows(const Epetra_MpiComm &comm, const CsrRows &A) {
  // Epetra's (global size, local size) constructor numbers the rows
  // contiguously in rank order: exactly the layout of CsrRows.
  map_ = std::make_unique<Epetra_Map>(A.n_global, A.n_rows, 0, comm);
  if (map_->MinMyGID() != A.first_row && A.n_rows > 0)
    throw std::logic_error("Epetra copy: rows are not contiguous in rank order");
  std::vector<int> lengths(A.n_rows);
  for (int i = 0; i < A.n_rows; ++i) lengths[i] = A.row_ptr[i + 1] - A.row_ptr[i];
  matrix_ = std::make_unique<Epetra_CrsMatrix>(Copy, *map_, lengths.data(), true);
  std::vector<double> zeros;
  for (int i = 0; i < A.n_rows; ++i) {
    zeros.assign(lengths[i], 0.0);
    if (matrix_->InsertGlobalValues(A.first_row + i, lengths[i], zeros.data(),
                                    const_cast<int *>(A.col + A.row_ptr[i])) < 0)
      throw std::runtime_error("Epetra copy: matrix insertion failed");
  }
  if (matrix_->FillComplete() != 0) throw std::runtime_error("Epetra copy: FillComplete failed");
  slot_.resize(A.row_ptr[A.n_rows]);
  std::vector<std::pair<int, int>> gid_pos;
  for (int i = 0; i < A.n_rows; ++i) {
    int len;
    double *vals;
    int *idx;
    matrix_->ExtractMyRowView(i, len, vals, idx);
    gid_pos.resize(len);
    for (int p = 0; p < len; ++p) gid_pos[p] = {matrix_->ColMap().GID(idx[p]), p};
    std::sort(gid_pos.begin(), gid_pos.end());
    for (int k = A.row_ptr[i]; k < A.row_ptr[i + 1]; ++k) {
      auto it = std::lower_bound(gid_pos.begin(), gid_pos.end(), std::make_pair(A.col[k], -1));
      if (it == gid_pos.end() || it->first != A.col[k])
        throw std::logic_error("Epetra copy: entry missing from the matrix");
      slot_[k] = vals + it->second;
    }
  }
  lhs_ = std::make_unique<Epetra_Vector>(*map_);
  rhs_ = std::make_unique<Epetra_Vector>(*map_);
}

}  // namespace sp
