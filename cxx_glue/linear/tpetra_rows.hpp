// A Tpetra copy of CsrRows (linear.hpp) for the backends that work on
// Tpetra matrices (Amesos2's KLU2, Belos + Ifpack2): its graph built once
// per pattern (rows contiguous in rank order, as given); set_values()
// overwrites the values in place through a precomputed slot table, one pass.
#ifndef SP_TPETRA_ROWS_HPP
#define SP_TPETRA_ROWS_HPP

#include <Teuchos_Comm.hpp>
#include <Teuchos_ParameterList.hpp>
#include <Teuchos_RCP.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Map.hpp>
#include <Tpetra_MultiVector.hpp>

#include <vector>

#include "linear/linear.hpp"

namespace sp {

class TpetraRows {
 public:
  using GO = long long;  // Debian 13.2 instantiates Tpetra for GO = long long only
  using Map = Tpetra::Map<int, GO>;
  using Graph = Tpetra::CrsGraph<int, GO>;
  using Matrix = Tpetra::CrsMatrix<double, int, GO>;
  using MV = Tpetra::MultiVector<double, int, GO>;

  // The pattern of A (values zero); throws on a Tpetra failure.
  TpetraRows(const Teuchos::RCP<const Teuchos::Comm<int>> &comm, const CsrRows &A);
  // A has this pattern: same rows on this rank, same number of entries
  // (the caller says whether the pattern is the same; this guards sizes).
  bool same_pattern(const CsrRows &A) const {
    return A.n_global == n_global_ && A.n_rows == n_rows_ && A.row_ptr[A.n_rows] == nnz_;
  }
  void set_values(const CsrRows &A) {
    matrix_->resumeFill();
    {
      auto values = matrix_->getLocalMatrixHost().values;
      for (size_t k = 0; k < slot_.size(); ++k) values(slot_[k]) = A.val[k];
    }
    auto params = Teuchos::rcp(new Teuchos::ParameterList);
    params->set("No Nonlocal Changes", true);  // the graph is fixed: no communication
    matrix_->fillComplete(matrix_->getDomainMap(), matrix_->getRangeMap(), params);
  }
  Teuchos::RCP<Matrix> matrix() const { return matrix_; }
  Teuchos::RCP<MV> lhs() const { return lhs_; }
  Teuchos::RCP<MV> rhs() const { return rhs_; }
  int n_local() const { return n_rows_; }

 private:
  int n_global_, n_rows_, nnz_;
  Teuchos::RCP<const Map> map_;
  Teuchos::RCP<Matrix> matrix_;
  Teuchos::RCP<MV> lhs_, rhs_;
  std::vector<size_t> slot_;
};

}  // namespace sp
#endif
