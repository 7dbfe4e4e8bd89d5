#include "linear/tpetra_rows.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace sp {

TpetraRows::TpetraRows(const Teuchos::RCP<const Teuchos::Comm<int>> &comm, const CsrRows &A)
    : n_global_(A.n_global), n_rows_(A.n_rows), nnz_(A.row_ptr[A.n_rows]) {
  // (global size, local size): rows numbered contiguously in rank order
  map_ = Teuchos::rcp(new Map((Tpetra::global_size_t)A.n_global, (size_t)A.n_rows, 0, comm));
  if (A.n_rows > 0 && map_->getMinGlobalIndex() != A.first_row)
    throw std::logic_error("Tpetra copy: rows are not contiguous in rank order");
  std::vector<size_t> lengths(A.n_rows);
  for (int i = 0; i < A.n_rows; ++i) lengths[i] = A.row_ptr[i + 1] - A.row_ptr[i];
  auto graph = Teuchos::rcp(new Graph(map_, Teuchos::ArrayView<const size_t>(lengths)));
  std::vector<GO> cols;
  for (int i = 0; i < A.n_rows; ++i) {
    cols.assign(A.col + A.row_ptr[i], A.col + A.row_ptr[i + 1]);
    graph->insertGlobalIndices(A.first_row + i, Teuchos::ArrayView<const GO>(cols));
  }
  graph->fillComplete();
  matrix_ = Teuchos::rcp(new Matrix(graph));
  matrix_->fillComplete();
  // slot_[k]: entry k of the caller's rows in the matrix's value array
  const auto local = matrix_->getLocalMatrixHost();
  const auto &colmap = *matrix_->getColMap();
  slot_.resize(nnz_);
  std::vector<std::pair<GO, size_t>> gid_pos;
  for (int i = 0; i < A.n_rows; ++i) {
    const size_t begin = local.graph.row_map(i), end = local.graph.row_map(i + 1);
    gid_pos.clear();
    for (size_t p = begin; p < end; ++p)
      gid_pos.emplace_back(colmap.getGlobalElement(local.graph.entries(p)), p);
    std::sort(gid_pos.begin(), gid_pos.end());
    for (int k = A.row_ptr[i]; k < A.row_ptr[i + 1]; ++k) {
      const auto key = std::make_pair((GO)A.col[k], (size_t)0);
      auto it = std::lower_bound(gid_pos.begin(), gid_pos.end(), key);
      if (it == gid_pos.end() || it->first != A.col[k])
        throw std::logic_error("Tpetra copy: entry missing from the matrix");
      slot_[k] = it->second;
    }
  }
  lhs_ = Teuchos::rcp(new MV(map_, 1));
  rhs_ = Teuchos::rcp(new MV(map_, 1));
}

}  // namespace sp
