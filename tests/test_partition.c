/* The node partition of MPI runs (src/mesh/partition.h): the RCB order is a
 * permutation and renumbering keeps the mesh; on a 3:1 rectangle, ranges of
 * the RCB order cut the element edges of straight lines across the short
 * side and ranges of the row-by-row numbering those of lines along the long
 * side (bounds derived below, not measured); on the ellipse, ranges of the
 * RCB order cut fewer edges than ranges of its own (ring-by-ring)
 * numbering; the ranges balance the unknowns of a layout whose cells cover
 * only part of the mesh. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

/** Element edges whose two nodes belong to different ranks (each interior
 *  edge is counted once per element side: a proxy for the interface). */
static int edge_cut(const sp_mesh *mesh, int n_ranks, const int *first_node) {
  int *owner = malloc(sizeof(int) * (size_t)mesh->n_nodes);
  for (int r = 0; r < n_ranks; ++r)
    for (int i = first_node[r]; i < first_node[r + 1]; ++i) owner[i] = r;
  int cut = 0;
  for (int e = 0; e < mesh->n_elems; ++e)
    for (int a = 0; a < 4; ++a)
      cut += owner[mesh->elem[4 * e + a]] != owner[mesh->elem[4 * e + (a + 1) % 4]];
  free(owner);
  return cut;
}

/* An nx x ny rectangle, nx = 3 ny, one cell on every node (ranges of equal
 * node counts), P = 2 and 4 ranks. Counting as edge_cut does (an edge
 * inside the domain twice, one on its boundary once):
 * - the rectangle's own numbering (row by row, i fastest): a range boundary
 *   at node index s splits every one of the nx + 1 columns of nodes exactly
 *   once (the column's indices grow with the row), so it cuts nx + 1
 *   vertical edges: at least 2 nx (the two boundary columns count once);
 *   P - 1 boundaries: >= 2 nx (P - 1).
 * - the RCB order: the first split is at the median x (the longer extent),
 *   so every one of the ny + 1 rows of nodes is split once, plus at most
 *   one vertical edge in the column holding the median (nodes of equal x
 *   are ordered by y): at most ny + 2 edges, <= 2 (ny + 2). With P = 4 the
 *   halves are still longer in x (1.5 x 1) and split alike. A range
 *   boundary of sp_partition_ranges may sit a node away from the RCB
 *   split (equal shares vs the recursion's halves of odd counts): each
 *   node moved across adds at most its 4 edges, counted twice: 8. So
 *   <= (P - 1) (2 (ny + 2) + 8): 52 and 156 here, against at least 120 and
 *   360 for the row numbering. */
static void test_rectangle_cut_bounds(void) {
  const int nx = 60, ny = 20;
  sp_mesh *rows, *rcb;
  CHECK_OK(sp_mesh_rectangle(0, 0, 3, 1, nx, ny, &rows));
  CHECK_OK(sp_mesh_rectangle(0, 0, 3, 1, nx, ny, &rcb));
  int *order = malloc(sizeof(int) * (size_t)rcb->n_nodes);
  CHECK_OK(sp_partition_rcb_order(rcb, order));
  CHECK_OK(sp_partition_renumber(rcb, order));
  sp_layout *full;
  CHECK_OK(sp_layout_create_full(rows->n_nodes, 1, &full));
  printf("  rectangle %d x %d: ranks | edges cut: rows (bound >=) | RCB (bound <=)\n", nx, ny);
  for (int P = 2; P <= 4; P *= 2) {
    int first[5];
    sp_partition_ranges(full, P, first);
    const int cut_rows = edge_cut(rows, P, first), cut_rcb = edge_cut(rcb, P, first);
    const int rows_at_least = 2 * nx * (P - 1), rcb_at_most = (P - 1) * (2 * (ny + 2) + 8);
    printf("  %27d | %15d (%4d) | %9d (%4d)\n", P, cut_rows, rows_at_least, cut_rcb,
           rcb_at_most);
    CHECK(cut_rows >= rows_at_least, "P = %d: the row numbering cuts %d edges, at least %d",
          P, cut_rows, rows_at_least);
    CHECK(cut_rcb <= rcb_at_most, "P = %d: RCB cuts %d edges, at most %d", P, cut_rcb,
          rcb_at_most);
  }
  free(order);
  sp_layout_destroy(&full);
  sp_mesh_destroy(&rows);
  sp_mesh_destroy(&rcb);
}

static void test_renumbering_keeps_the_mesh(void) {
  sp_mesh *mesh, *copy;
  CHECK_OK(sp_mesh_ellipse(4, 0.5, 0.25, 2, 0.1, &mesh));
  CHECK_OK(sp_mesh_ellipse(4, 0.5, 0.25, 2, 0.1, &copy));
  int *order = malloc(sizeof(int) * (size_t)mesh->n_nodes);
  CHECK_OK(sp_partition_rcb_order(mesh, order));
  int *seen = calloc((size_t)mesh->n_nodes, sizeof(int)), bad = 0;
  for (int j = 0; j < mesh->n_nodes; ++j)
    if (order[j] < 0 || order[j] >= mesh->n_nodes || seen[order[j]]++) ++bad;
  CHECK(bad == 0, "the RCB order is not a permutation (%d bad entries)", bad);
  CHECK_OK(sp_partition_renumber(mesh, order));
  /* every element has the same corner coordinates as before */
  int moved = 0;
  for (int e = 0; e < mesh->n_elems; ++e)
    for (int a = 0; a < 4; ++a)
      for (int d = 0; d < 2; ++d)
        moved += mesh->xy[2 * mesh->elem[4 * e + a] + d] != copy->xy[2 * copy->elem[4 * e + a] + d];
  CHECK(moved == 0, "%d element corner coordinates changed", moved);
  for (int r = 0; r < 2; ++r)
    CHECK(sp_mesh_region_area(mesh, r) == sp_mesh_region_area(copy, r), "region %d area", r);
  /* a repeated entry is refused */
  order[1] = order[0];
  CHECK(sp_partition_renumber(mesh, order) == SP_ERR_INTERNAL, "a non-permutation accepted");
  sp_error_clear();
  free(order);
  free(seen);
  sp_mesh_destroy(&mesh);
  sp_mesh_destroy(&copy);
}

static void test_rcb_cuts_less(void) {
  sp_mesh *ring, *rcb;
  CHECK_OK(sp_mesh_ellipse(5, 0.5, 0.25, 2, 0.1, &ring));
  CHECK_OK(sp_mesh_ellipse(5, 0.5, 0.25, 2, 0.1, &rcb));
  int *order = malloc(sizeof(int) * (size_t)rcb->n_nodes);
  CHECK_OK(sp_partition_rcb_order(rcb, order));
  CHECK_OK(sp_partition_renumber(rcb, order));
  sp_layout *full;
  CHECK_OK(sp_layout_create_full(ring->n_nodes, 1, &full));
  printf("  ranks | edges cut: ring numbering | RCB numbering\n");
  for (int P = 2; P <= 8; P *= 2) {
    int first[9];
    sp_partition_ranges(full, P, first);
    const int cut_ring = edge_cut(ring, P, first), cut_rcb = edge_cut(rcb, P, first);
    printf("  %5d | %25d | %13d\n", P, cut_ring, cut_rcb);
    /* A boundary between ranges of the ring numbering is a whole closed
     * ring around the centre; RCB's are chords across the short axis. How
     * much shorter depends on where this non-uniform mesh puts its nodes
     * (measured 202/260, 658/780, 868/1776), so the bound asserted is the
     * one the geometry gives without that: RCB is never worse. The
     * rectangle above has exact bounds. */
    CHECK(cut_rcb < cut_ring, "P = %d: RCB cuts %d edges, the ring numbering %d", P, cut_rcb,
          cut_ring);
    /* equal node counts (one unknown pair per node) to one node */
    for (int r = 0; r < P; ++r) {
      const int n = first[r + 1] - first[r];
      CHECK(abs(n * P - ring->n_nodes) <= P, "P = %d rank %d: %d of %d nodes", P, r, n,
            ring->n_nodes);
    }
  }
  free(order);
  sp_layout_destroy(&full);
  sp_mesh_destroy(&ring);
  sp_mesh_destroy(&rcb);
}

/* Three cells on the left third of a rectangle: nodes there carry up to 3
 * pairs, the rest none. Equal node ranges would give rank 1 of 2 almost no
 * unknowns; the ranges balance the pairs to one node's worth. */
static void test_ranges_balance_unknowns(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_rectangle(0, 0, 3, 1, 60, 20, &mesh));
  int *order = malloc(sizeof(int) * (size_t)mesh->n_nodes);
  CHECK_OK(sp_partition_rcb_order(mesh, order));
  CHECK_OK(sp_partition_renumber(mesh, order));
  const int nn = mesh->n_nodes, nc = 3;
  unsigned char *mask = calloc((size_t)nn * nc, 1);
  for (int k = 0; k < nc; ++k)
    for (int i = 0; i < nn; ++i)
      mask[k * nn + i] = mesh->xy[2 * i] <= 1.0 + 0.1 * k;
  sp_layout *layout;
  CHECK_OK(sp_layout_create_from_masks(nn, nc, mask, &layout));
  for (int P = 1; P <= 3; ++P) {
    int first[4];
    sp_partition_ranges(layout, P, first);
    CHECK(first[0] == 0 && first[P] == nn, "P = %d: ranges %d..%d", P, first[0], first[P]);
    for (int r = 0; r < P; ++r) {
      const int pairs = layout->node_start[first[r + 1]] - layout->node_start[first[r]];
      const double share = (double)layout->n_pairs / P;
      printf("  P = %d rank %d: nodes %4d..%4d, %5d of %5d pairs\n", P, r, first[r],
             first[r + 1] - 1, pairs, layout->n_pairs);
      CHECK(fabs(pairs - share) <= nc + 1, "P = %d rank %d: %d pairs, share %.1f", P, r,
            pairs, share);
    }
  }
  free(mask);
  free(order);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

int main(void) {
  test_renumbering_keeps_the_mesh();
  test_rectangle_cut_bounds();
  test_rcb_cuts_less();
  test_ranges_balance_unknowns();
  TEST_DONE();
}
