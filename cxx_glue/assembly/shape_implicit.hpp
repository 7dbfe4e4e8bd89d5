// The linearised implicit shape term (softpack_solver.h, sp_shape_coef;
// docs/model.md): per cell, the coefficients follow the new state's moments,
// coef_i - sum_j gain[i][j] dI_j with dI_j = int_mask Ihat_j (c - c^n) =
// sum_p u[n p + j] (c_p - c^n_p), i, j < n, n the mesh's dimension (the
// principal moments of a cell: 2 in 2D, 3 in 3D). Its residual part is computed by the
// element kernels from the coefficients (data_at); its Jacobian part, u_i
// gain[i][j] u_j^T per cell, is a low-rank term beside the sparse Jacobian
// (jacobian_term), solved by LowRankSolver.
#ifndef SP_SHAPE_IMPLICIT_HPP
#define SP_SHAPE_IMPLICIT_HPP

#include <vector>

#include "assembly/assembly.hpp"
#include "linear/linear_low_rank.hpp"
#include "softpack_solver.h"

namespace sp {

class ImplicitShape {
 public:
  // Takes a step's shape data: the weights and the active cells (those with
  // a non-zero gain). Collective (the weights are reduced). Throws on a gain
  // that is not finite. Without an implicit term it only forgets the last.
  void prepare(const sp_step_data &data, const Assembly &assembly);
  // The step data with the coefficients at the full (replicated) state,
  // data itself when there is no implicit term.
  const sp_step_data &data_at(const sp_step_data &data, const Assembly &assembly,
                              const double *state);
  // The Jacobian's low-rank part U C V^T on this rank's rows
  // (assembly.my_rows()): U's columns n a + i are u_i of active cell a on its mu
  // rows, V's the same on its c rows, C_a = -gain (n x n; R_mu holds
  // +coef_i u_i, and coef_i falls by gain[i][j] dI_j). Empty without one.
  LowRankTerm jacobian_term(const Assembly &assembly) const;

 private:
  int n_moments_ = 2;                // n: the mesh's dimension
  std::vector<double> u_;            // n per pair (Assembly::shape_weights)
  std::vector<sp_shape_coef> coef_;  // the coefficients at the last state
  sp_step_data data_{};              // the step data pointing at them
  std::vector<int> active_of_cell_;  // cell -> active index or -1
  std::vector<double> gain_;         // n^2 per active cell, gain[i][j] at n^2 a + n i + j
};

}  // namespace sp
#endif
