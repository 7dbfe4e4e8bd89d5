// The Tpetra side of Assembly (assembly.hpp): the maps and the graph of a
// layout, and the sums of the element residuals and Jacobians into Tpetra
// objects. Kept apart from the element kernels (assembly.cpp, Sacado), so
// each unit includes one of the two heavy libraries.
//
// Finite-element assembly over owned and ghost rows: a rank computes the
// elements it owns (assembly.cpp: first node in its node range); their
// entries in its own rows are summed into the owned vector or matrix in
// place, those in other ranks' rows into a ghost vector or matrix (rows:
// the other ranks' DOFs its elements touch), and an Export adds each ghost
// row to its owner's. Per entry that is the order Epetra's FE classes
// summed in (an owner's elements in element order, then the sums of the
// other ranks'), so the values are the same to the bit on one and two
// processes (with three or more, the other ranks' parts may arrive in
// another order).
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_OrdinalTraits.hpp>
#include <Teuchos_ParameterList.hpp>
#include <Tpetra_CrsGraph.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Export.hpp>
#include <Tpetra_Map.hpp>
#include <Tpetra_Vector.hpp>

#include <algorithm>
#include <climits>
#include <stdexcept>

#include "assembly/assembly.hpp"
#include "base/errors.hpp"
#include "linear/linear.hpp"

namespace sp {

namespace {

// The position of column col in row i of a local matrix whose rows are
// sorted by local column (the graphs below are built so).
template <class LocalMatrix>
size_t entry(const LocalMatrix &A, int i, int col) {
  const int *cols = A.graph.entries.data();
  const int *begin = cols + A.graph.row_map(i), *end = cols + A.graph.row_map(i + 1);
  const int *at = std::lower_bound(begin, end, col);
  if (at == end || *at != col) throw std::logic_error("Jacobian entry outside the graph");
  return (size_t)(at - cols);
}

// A fill-complete graph of rows (global ids) with the given sorted local
// columns (ptr/col, CSR) of col_map; domain and range: map.
Teuchos::RCP<const TpetraGraph> make_graph(const Teuchos::RCP<const TpetraMap> &rows,
                                           const Teuchos::RCP<const TpetraMap> &col_map,
                                           const Teuchos::RCP<const TpetraMap> &map,
                                           std::vector<size_t> &ptr, std::vector<int> &col) {
  Teuchos::ArrayRCP<size_t> p(ptr.size());
  Teuchos::ArrayRCP<int> c(col.size());
  std::copy(ptr.begin(), ptr.end(), p.begin());
  std::copy(col.begin(), col.end(), c.begin());
  auto g = Teuchos::rcp(new TpetraGraph(rows, col_map, p, c));
  g->expertStaticFillComplete(map, map);
  return g;
}

}  // namespace

Assembly::~Assembly() = default;

void Assembly::build_tpetra(int first_pair, int end_pair) {
  ensure_kokkos();
  std::vector<GlobalId> ghost_rows, col_ids;
  std::vector<size_t> own_ptr, ghost_ptr;
  std::vector<int> own_col, ghost_col;
  agree_local(comm_, [&] {
    const int n_dofs = 2 * n_pairs_, first = 2 * first_pair, n_own = 2 * (end_pair - first_pair);
    row_of_dof_.assign(n_dofs, INT_MIN);
    col_of_dof_.assign(n_dofs, -1);
    for (int i = 0; i < n_own; ++i) row_of_dof_[first + i] = i;
    // Each own row's columns from every element touching it (every rank
    // holds the whole element-slot table, so no communication), each ghost
    // row's from this rank's elements: coupled() entries between present
    // unknowns, as global ids for now.
    std::vector<char> mine(elem_start_.size() - 1, 0);
    for (int e : my_elems_) mine[e] = 1;
    std::vector<std::vector<int>> own_rows(n_own), ghost_of;
    for (int e = 0; e + 1 < (int)elem_start_.size(); ++e) {
      const int nc = n_cells_on(e);
      const int64_t s0 = elem_start_[e];
      for (int j = 0; j < nc; ++j)
        for (int a = 0; a < nen_; ++a) {
          const int p = slot_pair_[nen_ * (s0 + j) + a];
          if (p < 0) continue;
          const bool own = p >= first_pair && p < end_pair;
          if (!own && !mine[e]) continue;
          for (int f = 0; f < 2; ++f) {
            const int row = 2 * p + f;
            if (!own && row_of_dof_[row] == INT_MIN) {
              row_of_dof_[row] = -1 - (int)ghost_rows.size();
              ghost_rows.push_back(row);
              ghost_of.emplace_back();
            }
            std::vector<int> &cols = own ? own_rows[row - first] : ghost_of[-1 - row_of_dof_[row]];
            for (int j2 = 0; j2 < nc; ++j2)
              for (int b = 0; b < nen_; ++b) {
                const int p2 = slot_pair_[nen_ * (s0 + j2) + b];
                if (p2 < 0) continue;
                for (int f2 = 0; f2 < 2; ++f2)
                  if (coupled(j, f, j2, f2)) cols.push_back(2 * p2 + f2);
              }
          }
        }
    }
    // Ghost rows by global id.
    std::vector<int> order(ghost_rows.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = (int)k;
    std::sort(order.begin(), order.end(),
              [&](int x, int y) { return ghost_rows[x] < ghost_rows[y]; });
    std::vector<GlobalId> sorted_rows(order.size());
    std::vector<std::vector<int>> sorted_cols(order.size());
    for (size_t k = 0; k < order.size(); ++k) {
      sorted_rows[k] = ghost_rows[order[k]];
      sorted_cols[k].swap(ghost_of[order[k]]);
      row_of_dof_[sorted_rows[k]] = -1 - (int)k;
    }
    ghost_rows.swap(sorted_rows);
    // Columns: this rank's rows, then the others by global id (the order
    // Tpetra and Epetra give a column map they make: remote ids by owner,
    // which is by id as the ranks own increasing ranges).
    for (int i = 0; i < n_own; ++i) {
      col_of_dof_[first + i] = i;
      col_ids.push_back(first + i);
    }
    std::vector<int> others;
    auto note_columns = [&](std::vector<int> &cols) {
      std::sort(cols.begin(), cols.end());
      cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
      for (int c : cols)
        if (c < first || c >= first + n_own) others.push_back(c);
    };
    for (auto &cols : own_rows) note_columns(cols);
    for (auto &cols : sorted_cols) note_columns(cols);
    std::sort(others.begin(), others.end());
    others.erase(std::unique(others.begin(), others.end()), others.end());
    for (int c : others) {
      col_of_dof_[c] = (int)col_ids.size();
      col_ids.push_back(c);
    }
    // CSR of local columns, sorted (local order = global order here but
    // for the remote block after the own one).
    auto to_csr = [&](std::vector<std::vector<int>> &rows, std::vector<size_t> &ptr,
                      std::vector<int> &col) {
      ptr.assign(1, 0);
      for (auto &cols : rows) {
        const size_t start = col.size();
        for (int c : cols) col.push_back(col_of_dof_[c]);
        std::sort(col.begin() + start, col.end());
        ptr.push_back(col.size());
        std::vector<int>().swap(cols);
      }
    };
    to_csr(own_rows, own_ptr, own_col);
    to_csr(sorted_cols, ghost_ptr, ghost_col);
  });
  const auto comm = Teuchos::rcp(new Teuchos::MpiComm<int>(comm_));
  const auto any = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  map_ = Teuchos::rcp(new TpetraMap(any, Teuchos::ArrayView<const GlobalId>(my_rows_), 0, comm));
  ghost_map_ = Teuchos::rcp(new TpetraMap(any, Teuchos::ArrayView<const GlobalId>(ghost_rows), 0, comm));
  col_map_ = Teuchos::rcp(new TpetraMap(any, Teuchos::ArrayView<const GlobalId>(col_ids), 0, comm));
  graph_ = make_graph(map_, col_map_, map_, own_ptr, own_col);
  auto ghost_graph = make_graph(ghost_map_, col_map_, map_, ghost_ptr, ghost_col);
  ghost_to_owner_ = Teuchos::rcp(new TpetraExport(ghost_map_, map_));
  ghost_residual_ = Teuchos::rcp(new TpetraVector(ghost_map_));
  ghost_jacobian_ = Teuchos::rcp(new TpetraMatrix(ghost_graph));
  ghost_jacobian_->fillComplete(map_, map_);
}

void Assembly::residual(const sp_step_data &d, const double *state, TpetraVector &F) const {
  Gathered g;
  std::vector<double> R;
  {
    auto own = F.getLocalViewHost(Tpetra::Access::OverwriteAll);
    auto ghost = ghost_residual_->getLocalViewHost(Tpetra::Access::OverwriteAll);
    Kokkos::deep_copy(own, 0.0);
    Kokkos::deep_copy(ghost, 0.0);
    agree_local(comm_, [&] {
      fault_in_glue(SP_FAULT_ASSEMBLY, "assembly", rank_);
      for (int e : my_elems_) {
        gather(e, d, state, g);
        const int n = 2 * nen_ * g.n_cells;
        R.resize(n);
        element_rhs(e, d, g, R.data());
        for (int i = 0; i < n; ++i) {
          if (g.dof[i] < 0) continue;
          const int row = row_of_dof_[g.dof[i]];
          if (row >= 0) own(row, 0) += R[i];
          else ghost(-1 - row, 0) += R[i];
        }
      }
    });
  }
  if (ghost_map_->getGlobalNumElements() > 0)
    F.doExport(*ghost_residual_, *ghost_to_owner_, Tpetra::ADD);
}

void Assembly::jacobian(const sp_step_data &d, const double *state, int kind,
                        TpetraMatrix &J) const {
  J.resumeFill();
  ghost_jacobian_->resumeFill();
  Gathered g;
  std::vector<double> R, K;
  std::vector<int> col;
  {
    const auto own = J.getLocalMatrixHost(), ghost = ghost_jacobian_->getLocalMatrixHost();
    Kokkos::deep_copy(own.values, 0.0);
    Kokkos::deep_copy(ghost.values, 0.0);
    agree_local(comm_, [&] {
      for (int e : my_elems_) {
        gather(e, d, state, g);
        const int nc = g.n_cells, per_slot = 2 * nen_, n = per_slot * nc;
        R.assign(n, 0.0);
        K.assign((size_t)n * n, 0.0);
        element_matrix(e, d, g, kind, R.data(), K.data());
        col.resize(n);
        for (int i = 0; i < n; ++i) col[i] = g.dof[i] >= 0 ? col_of_dof_[g.dof[i]] : -1;
        for (int i = 0; i < n; ++i) {
          if (g.dof[i] < 0) continue;
          const int j = i / per_slot, f = i % 2, row = row_of_dof_[g.dof[i]];
          const auto &A = row >= 0 ? own : ghost;
          const int r = row >= 0 ? row : -1 - row;
          // columns i2 = per_slot j2 + k, in order (no division per entry)
          for (int j2 = 0, i2 = 0; j2 < nc; ++j2)
            for (int k = 0; k < per_slot; ++k, ++i2)
              if (col[i2] >= 0 && coupled(j, f, j2, k % 2))
                A.values(entry(A, r, col[i2])) += K[(size_t)i * n + i2];
        }
      }
    });
  }
  if (ghost_map_->getGlobalNumElements() > 0)
    J.doExport(*ghost_jacobian_, *ghost_to_owner_, Tpetra::ADD);
  ghost_jacobian_->fillComplete(map_, map_);
  J.fillComplete(map_, map_);
}

double matrix_bytes(const TpetraMatrix &A) {
  return (sizeof(double) + sizeof(int)) * (double)A.getNodeNumEntries() +
         sizeof(size_t) * (double)(A.getNodeNumRows() + 1);
}

double Assembly::table_bytes() const {
  return bytes_of(node_start_) + bytes_of(pair_cell_) + bytes_of(geo_N_) + bytes_of(geo_dNdx_) +
         bytes_of(geo_x_) + bytes_of(geo_w_) + bytes_of(geo_buffer_) + bytes_of(my_elems_) +
         bytes_of(elem_start_) + bytes_of(slot_cell_) + bytes_of(slot_pair_) +
         bytes_of(row_of_dof_) + bytes_of(col_of_dof_) + bytes_of(my_rows_);
}

double Assembly::ghost_matrix_bytes() const {
  return matrix_bytes(*ghost_jacobian_) + sizeof(double) * (double)ghost_map_->getNodeNumElements();
}

double Assembly::residual_export_bytes() const {
  return sizeof(double) * (double)ghost_to_owner_->getNumExportIDs();
}

double Assembly::jacobian_export_bytes() const {
  double entries = 0;
  for (int lid : ghost_to_owner_->getExportLIDs())
    entries += (double)ghost_jacobian_->getNumEntriesInLocalRow(lid);
  return (sizeof(double) + sizeof(GlobalId)) * entries +
         sizeof(size_t) * (double)ghost_to_owner_->getNumExportIDs();
}

}  // namespace sp
