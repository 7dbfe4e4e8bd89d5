// Assembly of the step equations over the mesh, driven by the layout:
// element -> (cells present, pairs of their nodes), the Tpetra row map from
// the node partition, the matrix graph, residual/Jacobian fills and energies.
// Only forward declarations of Tpetra here: a unit that includes this header
// and does not touch the Tpetra objects does not pay their compile time.
#ifndef SP_ASSEMBLY_HPP
#define SP_ASSEMBLY_HPP

#include <mpi.h>
#include <Teuchos_RCP.hpp>
#include <Tpetra_CrsGraph_fwd.hpp>
#include <Tpetra_CrsMatrix_fwd.hpp>
#include <Tpetra_Export_fwd.hpp>
#include <Tpetra_Map_fwd.hpp>
#include <Tpetra_Vector_fwd.hpp>

#include <cstdint>
#include <memory>
#include <vector>

#include "assembly/residual.hpp"
#include "softpack_solver.h"

namespace sp {

// The glue's Tpetra types: global ordinal long long, the only one Debian's
// Trilinos 13.2 instantiates (docs/building.md); local ordinal int.
using GlobalId = long long;
using TpetraMap = Tpetra::Map<int, GlobalId>;
using TpetraGraph = Tpetra::CrsGraph<int, GlobalId>;
using TpetraMatrix = Tpetra::CrsMatrix<double, int, GlobalId>;
using TpetraVector = Tpetra::Vector<double, int, GlobalId>;
using TpetraExport = Tpetra::Export<int, GlobalId>;

// Bytes a std::vector holds, and a Tpetra matrix's local rows (values,
// local column indices, row offsets).
template <class V>
double bytes_of(const V &v) {
  return (double)v.capacity() * sizeof(typename V::value_type);
}
double matrix_bytes(const TpetraMatrix &A);

class Assembly {
 public:
  Assembly(MPI_Comm comm, const sp_mesh_view &mesh, const sp_layout_view &layout);
  ~Assembly();  // (out of line: the Tpetra classes are complete in assembly.cpp)

  // True if the layout is the one this assembly was built for.
  bool same_layout(const sp_layout_view &layout) const;

  // This rank's rows (the DOFs of its nodes' pairs, contiguous, in rank
  // order), as a map and as the list of their global ids.
  const Teuchos::RCP<const TpetraMap> &map() const { return map_; }
  const std::vector<GlobalId> &my_rows() const { return my_rows_; }
  // The Jacobian's graph: this rank's rows, every entry any element puts
  // there (fill complete; its column map: this rank's rows, then the others
  // by global id).
  const Teuchos::RCP<const TpetraGraph> &graph() const { return graph_; }
  int n_dofs() const { return 2 * n_pairs_; }
  int n_cells() const { return n_cells_; }
  int dim() const { return dim_; }  // the mesh's: 2 or 3

  // Residual F (owned rows of map()) at the full (replicated) state.
  // Each rank sums its elements' parts into its own rows and into ghost
  // rows (other ranks' rows its elements touch); an Export adds the ghost
  // rows to their owners.
  void residual(const sp_step_data &data, const double *state, TpetraVector &F) const;
  // Jacobian of kind SP_SOLVER_JAC_* into J, a matrix on graph() (values
  // replaced; fill complete on return), summed as the residual is.
  void jacobian(const sp_step_data &data, const double *state, int kind, TpetraMatrix &J) const;
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
  // Bytes of this rank's copies of the mesh and layout (element geometry,
  // pair, slot and DOF tables), of its ghost rows' matrix, and sent by one
  // residual's and one Jacobian's Export of its ghost rows (values, and
  // for the matrix each entry's global column and each row's length).
  double table_bytes() const;
  double ghost_matrix_bytes() const;
  double residual_export_bytes() const;
  double jacobian_export_bytes() const;
  // Gathers and computes every element matrix of this rank without adding
  // them into a matrix (the element kernel alone, for timing).
  void element_pass(const sp_step_data &data, const double *state, int kind) const;

 private:
  // Per-element scratch: the element's unknowns and step inputs, slot-major.
  struct Gathered {
    int n_cells = 0;
    std::vector<double> u, c_old, source;
    std::vector<int> dof;  // global DOF of each element unknown, -1 if absent
    std::vector<const sp_shape_coef *> shape;
    // sigma of slots j and l at [n_cells j + l]; has_adhesion: some
    // entry is not 0 (else the element has no adhesion term)
    std::vector<double> adhesion;
    bool has_adhesion = false;
    ElementInputs inputs(const sp_step_data &d) const {
      ElementInputs in;
      in.c_old = c_old.data();
      in.source = d.source ? source.data() : nullptr;
      in.shape = d.shape ? shape.data() : nullptr;
      in.adhesion = has_adhesion ? adhesion.data() : nullptr;
      in.dt = d.dt;
      in.model = d.model;
      return in;
    }
  };
  int n_cells_on(int e) const { return (int)(elem_start_[e + 1] - elem_start_[e]); }
  // Element e's geometry (a view into geo_*).
  ElementGeometry geometry(int e) const {
    const size_t eq = (size_t)nq_ * e;
    return ElementGeometry{dim_, nen_, nq_, &geo_N_[eq * nen_], &geo_dNdx_[eq * nen_ * dim_],
                           &geo_x_[eq * dim_], &geo_w_[eq], geo_buffer_[e] != 0};
  }
  void gather(int e, const sp_step_data &data, const double *state,
              Gathered &g) const;
  // The adhesion table of element e's slots into g (g.n_cells set).
  void gather_adhesion(int e, const sp_model_params &m, Gathered &g) const;
  void element_matrix(int e, const sp_step_data &data, const Gathered &g,
                      int kind, double *R, double *K) const;
  // The element residual alone (R: 2 nen_ g.n_cells entries, zeroed first).
  void element_rhs(int e, const sp_step_data &data, const Gathered &g, double *R) const;
  // The Tpetra side (assembly_tpetra.cpp): the row, ghost and column maps
  // of this rank's pairs first_pair .. end_pair - 1 and of its elements,
  // the graphs, the Export of the ghost rows to their owners. Collective.
  void build_tpetra(int first_pair, int end_pair);

  MPI_Comm comm_;
  int rank_ = 0;
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
  // Per global DOF: its row in this rank's vectors and matrices (>= 0: an
  // own row, -1 - k: ghost row k, INT_MIN: none of this rank's elements
  // touches it) and its local column (-1: not a column here).
  std::vector<int> row_of_dof_, col_of_dof_;
  std::vector<GlobalId> my_rows_;
  Teuchos::RCP<const TpetraMap> map_, ghost_map_, col_map_;
  Teuchos::RCP<const TpetraGraph> graph_;
  Teuchos::RCP<const TpetraExport> ghost_to_owner_;
  // Scratch for the ghost rows' sums (the values change in const fills).
  Teuchos::RCP<TpetraVector> ghost_residual_;
  Teuchos::RCP<TpetraMatrix> ghost_jacobian_;
};

// Whether the entry (row of slot j field f, column of slot j2 field f2)
// can be non-zero: c-rows see only their own cell; mu-rows see their own
// cell and the c of every other cell present (the repulsion, and the
// adhesion's stiffness blocks).
inline bool coupled(int j, int f, int j2, int f2) {
  if (j == j2) return true;
  return f == 1 && f2 == 0;
}

}  // namespace sp
#endif
