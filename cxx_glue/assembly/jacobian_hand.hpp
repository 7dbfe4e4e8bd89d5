// The hand-derived element Jacobian of exactly the residual of residual.hpp
// (solver.jacobian: hand). Same element unknowns ((n j + a) 2 + f, n the
// element's nodes, f = 0 c, 1 mu), same ElementGeometry and ElementInputs.
#ifndef SP_JACOBIAN_HAND_HPP
#define SP_JACOBIAN_HAND_HPP

#include "assembly/residual.hpp"

namespace sp {

// Element residual R (2 nodes n_cells entries, as element_residual<double>)
// and Jacobian K = dR/du (row-major n x n). Only the blocks that coupled()
// (assembly.hpp) allows are written; the caller zeroes K beforehand, the
// other blocks are exactly zero.
void hand_element(const ElementGeometry &g, int n_cells, const double *u,
                  const ElementInputs &in, double *R, double *K);

}  // namespace sp
#endif
