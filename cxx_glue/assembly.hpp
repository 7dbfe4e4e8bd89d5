// Assembly of the step equations over the mesh, driven by the layout:
// element -> (cells present, pairs of their nodes), Epetra maps from the node
// partition, the matrix graph, residual/Jacobian fills and energies.
#ifndef SP_ASSEMBLY_HPP
#define SP_ASSEMBLY_HPP

#include <Epetra_Comm.h>
#include <Epetra_CrsGraph.h>
#include <Epetra_FECrsMatrix.h>
#include <Epetra_Map.h>
#include <Epetra_Vector.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "residual.hpp"
#include "softpack_solver.h"

namespace sp {

class Assembly {
 public:
  Assembly(const Epetra_Comm &comm, const sp_mesh_view &mesh,
           const sp_layout_view &layout);

  // True if the layout is the one this assembly was built for.
  bool same_layout(const sp_layout_view &layout) const;

  const Epetra_Map &map() const { return *map_; }
  const Epetra_CrsGraph &graph() const { return *graph_; }
  int n_dofs() const { return 2 * n_pairs_; }
  int n_cells() const { return n_cells_; }
  int dim() const { return dim_; }  // the mesh's: 2 or 3

  // Residual F (owned rows of map()) at the full (replicated) state.
  void residual(const sp_step_data &data, const double *state, Epetra_Vector &F) const;
  // Jacobian of kind SP_SOLVER_JAC_* into J (values replaced).
  void jacobian(const sp_step_data &data, const double *state, int kind,
                Epetra_FECrsMatrix &J) const;
  // Energy parts summed over this rank's elements and reduced.
  sp_energy_parts energy(const sp_model_params &model, const double *state) const;
  // Largest |J_kind - J_fd| / max|J_fd| over elements (reduced).
  double check_jacobian(const sp_step_data &data, const double *state, int kind) const;
  // Largest over elements of max|K_a - K_b| / max|K_b| between the element
  // Jacobians of two kinds, over the entries of present unknowns (reduced).
  double compare_jacobians(const sp_step_data &data, const double *state, int kind_a,
                           int kind_b) const;
  // The shape term's weights of every pair p (replicated, reduced over the
  // ranks): u[dim p + i] = int N_p Ihat_i, i < dim() (one per principal
  // moment), over the quadrature points where c^n >= the cell's threshold,
  // Ihat_i about the cell's frozen centre and eigenvector i (data.shape).
  // The term's rows in mu are -coef_i u_i, and int_mask Ihat_i c =
  // sum_p u[dim p + i] c_p for any c of the layout.
  void shape_weights(const sp_step_data &data, std::vector<double> &u) const;
  int pair_cell(int p) const { return pair_cell_[p]; }
  // Gathers and computes every element matrix of this rank without adding
  // them into a matrix (the element kernel alone, for timing).
  void element_pass(const sp_step_data &data, const double *state, int kind) const;

 private:
  struct Gathered;  // per-element scratch
  int n_cells_on(int e) const { return (int)(elem_start_[e + 1] - elem_start_[e]); }
  // Element e's geometry (a view into geo_*).
  ElementGeometry geometry(int e) const {
    const size_t eq = (size_t)nq_ * e;
    return ElementGeometry{dim_, nen_, nq_, &geo_N_[eq * nen_], &geo_dNdx_[eq * nen_ * dim_],
                           &geo_x_[eq * dim_], &geo_w_[eq], geo_buffer_[e] != 0};
  }
  void gather(int e, const sp_step_data &data, const double *state,
              Gathered &g) const;
  void element_matrix(int e, const sp_step_data &data, const Gathered &g,
                      int kind, double *R, double *K) const;

  const Epetra_Comm &comm_;
  int n_nodes_, n_pairs_, n_cells_;
  // The mesh's element: dimension, nodes and Gauss points (q1.h).
  int dim_, nen_, nq_;
  std::vector<int> node_start_, pair_cell_;
  // Every element's geometry at its Gauss points (ElementGeometry's layout).
  std::vector<double> geo_N_, geo_dNdx_, geo_x_, geo_w_;
  std::vector<char> geo_buffer_;
  std::vector<int> my_elems_;    // elements this rank assembles
  // The element-slot table (sp_layout_view): slots of element e are
  // elem_start_[e]..elem_start_[e+1]-1, 64-bit as 8 x slots can pass 2^31.
  std::vector<int64_t> elem_start_;
  std::vector<int> slot_cell_;   // cell of each slot
  std::vector<int> slot_pair_;   // nen_ per slot: pair of (cell, node a)
  std::unique_ptr<Epetra_Map> map_;
  std::unique_ptr<Epetra_CrsGraph> graph_;
};

// Whether the entry (row of slot j field f, column of slot j2 field f2)
// can be non-zero: c-rows see only their own cell; mu-rows see their own
// cell and the c of every other cell present (the repulsion).
inline bool coupled(int j, int f, int j2, int f2) {
  if (j == j2) return true;
  return f == 1 && f2 == 0;
}

}  // namespace sp
#endif
