// An Epetra copy of CsrRows (linear.hpp) for the backends that work on
// Epetra matrices (Amesos2's KLU2): built once per pattern, rows
// distributed as given (contiguous in rank order); each set_values()
// overwrites the values in place through a precomputed slot table, one pass.
#ifndef SP_EPETRA_ROWS_HPP
#define SP_EPETRA_ROWS_HPP

#include <Epetra_CrsMatrix.h>
#include <Epetra_Map.h>
#include <Epetra_MpiComm.h>
#include <Epetra_Vector.h>

#include <memory>
#include <vector>

#include "linear.hpp"

namespace sp {

class EpetraRows {
 public:
  // The pattern of A (values zero); throws on an Epetra failure.
  EpetraRows(const Epetra_MpiComm &comm, const CsrRows &A);
  // A has this pattern: same rows on this rank, same entries.
  bool same_pattern(const CsrRows &A) const {
    return (int)slot_.size() == A.row_ptr[A.n_rows] && map_->NumMyElements() == A.n_rows &&
           map_->NumGlobalElements() == A.n_global;
  }
  void set_values(const CsrRows &A) {
    for (size_t k = 0; k < slot_.size(); ++k) *slot_[k] = A.val[k];
  }
  Epetra_CrsMatrix &matrix() { return *matrix_; }
  Epetra_Vector &lhs() { return *lhs_; }
  Epetra_Vector &rhs() { return *rhs_; }
  int n_local() const { return map_->NumMyElements(); }

 private:
  std::unique_ptr<Epetra_Map> map_;
  std::unique_ptr<Epetra_CrsMatrix> matrix_;
  std::unique_ptr<Epetra_Vector> lhs_, rhs_;
  std::vector<double *> slot_;  // slot_[k]: where entry k of the caller's rows lives
};

}  // namespace sp
#endif
