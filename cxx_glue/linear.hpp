// Direct linear solvers behind one small interface on plain CSR arrays, so
// the backends never see Epetra (and a later move to Tpetra is cheap).
#ifndef SP_LINEAR_HPP
#define SP_LINEAR_HPP

#include <memory>
#include <string>

namespace sp {

class DirectSolver {
 public:
  virtual ~DirectSolver() = default;
  // Factor the n x n matrix in CSR form (0-based). same_pattern: the
  // sparsity pattern equals the previous call's, so the symbolic work
  // (column ordering) can be reused. Returns false on a singular matrix.
  virtual bool factor(int n, const int *row_ptr, const int *col, const double *val,
                      bool same_pattern, std::string &why) = 0;
  // Solve A x = b with the last factorisation.
  virtual bool solve(const double *b, double *x, std::string &why) = 0;
  // Number of symbolic analyses done (for tests of the reuse).
  virtual int symbolic_count() const = 0;
};

// Serial SuperLU (dgstrf/dgstrs on the transposed CSC view of the CSR).
std::unique_ptr<DirectSolver> make_superlu();

}  // namespace sp
#endif
