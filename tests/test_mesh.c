/* Mesh: rectangle and five-patch ellipse counts, geometry, quality, the
 * buffer ring, area convergence, argument checks. Each test_* function is
 * one behaviour of src/mesh/mesh.h. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "mesh/mesh.h"
#include "mesh/q1.h"

static const double pi = 3.14159265358979323846;

/* ---------------------------------------------------------------- helpers */

/** Smallest and largest det J over all Gauss points, and the worst ratio
 *  min/max det J within one element. */
typedef struct {
  double det_min, det_max, worst_element_ratio;
} jacobian_stats;

static jacobian_stats mesh_jacobians(const sp_mesh *m) {
  jacobian_stats s = {INFINITY, -INFINITY, 1.0};
  for (int e = 0; e < m->n_elems; ++e) {
    double xy[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], N[SP_Q1_MAX_NODES];
    double dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w, lo = INFINITY, hi = -INFINITY;
    sp_mesh_elem_xy(m, e, xy);
    for (int q = 0; q < sp_q1_qpoints(m->dim); ++q) {
      double det = sp_q1_point(m->dim, xy, q, N, dNdx, x, &w);
      if (det < lo) lo = det;
      if (det > hi) hi = det;
    }
    if (lo < s.det_min) s.det_min = lo;
    if (hi > s.det_max) s.det_max = hi;
    if (lo / hi < s.worst_element_ratio) s.worst_element_ratio = lo / hi;
  }
  return s;
}

/** (x/a)^2 + (y/b)^2 of node i of an ellipse mesh. */
static double ellipse_level(const sp_mesh *m, int i) {
  double u = m->xy[2 * i] / m->bounds[2], v = m->xy[2 * i + 1] / m->bounds[3];
  return u * u + v * v;
}

/** Area of the N-gon with vertices at uniform parametric angles on the
 *  ellipse with semi-axes (radius a, radius b). */
static double inscribed_polygon_area(int n_vertices, double a, double b,
                                     double radius) {
  return a * b * radius * radius * 0.5 * n_vertices * sin(2 * pi / n_vertices);
}

/** Largest |i - j| over node pairs sharing an element. */
static int mesh_bandwidth(const sp_mesh *m) {
  int bw = 0;
  for (int e = 0; e < m->n_elems; ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        int d = abs(m->elem[4 * e + a] - m->elem[4 * e + b]);
        if (d > bw) bw = d;
      }
  return bw;
}

typedef struct {
  int lo, hi, forward; /* forward: the element walks lo -> hi */
} edge_key;

static int edge_compare(const void *pa, const void *pb) {
  const edge_key *a = pa, *b = pb;
  if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
  if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
  return a->forward - b->forward;
}

/**
 * Conformity: every edge belongs to one element (boundary) or two elements
 * walking it in opposite directions (consistent orientation). Returns the
 * number of boundary edges, or -1 if an edge is used otherwise.
 */
static int mesh_boundary_edges(const sp_mesh *m) {
  int n_edges = 4 * m->n_elems, boundary = 0;
  edge_key *edges = malloc((size_t)n_edges * sizeof *edges);
  for (int e = 0; e < m->n_elems; ++e)
    for (int a = 0; a < 4; ++a) {
      int p = m->elem[4 * e + a], q = m->elem[4 * e + (a + 1) % 4];
      edges[4 * e + a] = (edge_key){p < q ? p : q, p < q ? q : p, p < q};
    }
  qsort(edges, (size_t)n_edges, sizeof *edges, edge_compare);
  for (int i = 0; i < n_edges;) {
    int j = i;
    while (j < n_edges && edges[j].lo == edges[i].lo &&
           edges[j].hi == edges[i].hi)
      ++j;
    if (j - i == 1) ++boundary;
    else if (j - i != 2 || edges[i].forward == edges[i + 1].forward) {
      free(edges);
      return -1;
    }
    i = j;
  }
  free(edges);
  return boundary;
}

/** Basic invariants every mesh must satisfy: indices in range, positive
 *  det J at all Gauss points, every node used, regions valid. */
static void check_mesh_invariants(const sp_mesh *m, const char *what) {
  int bad_index = 0, bad_region = 0, unused = 0;
  char *used = calloc((size_t)m->n_nodes, 1);
  for (int c = 0; c < 4 * m->n_elems; ++c) {
    if (m->elem[c] < 0 || m->elem[c] >= m->n_nodes) ++bad_index;
    else used[m->elem[c]] = 1;
  }
  for (int i = 0; i < m->n_nodes; ++i) unused += !used[i];
  for (int e = 0; e < m->n_elems; ++e)
    bad_region += m->region[e] != SP_REGION_OMEGA &&
                  m->region[e] != SP_REGION_BUFFER;
  free(used);
  CHECK(bad_index == 0, "%s: %d node indices out of range", what, bad_index);
  CHECK(unused == 0, "%s: %d nodes belong to no element", what, unused);
  CHECK(bad_region == 0, "%s: %d elements with an invalid region", what,
        bad_region);
  jacobian_stats js = mesh_jacobians(m);
  CHECK(js.det_min > 0, "%s: det J = %g <= 0 at a Gauss point (not "
        "counterclockwise or inverted)", what, js.det_min);
}

/* ------------------------------------------------------------------ tests */

static void test_rectangle_counts_area_and_numbering(void) {
  sp_mesh *m = NULL;
  CHECK_OK(sp_mesh_rectangle(-1, 0.5, 2, 1.5, 6, 4, &m));
  CHECK(m->n_nodes == 35, "n_nodes = %d, want 7 x 5 = 35", m->n_nodes);
  CHECK(m->n_elems == 24, "n_elems = %d, want 24", m->n_elems);
  CHECK(m->is_ellipse == 0, "is_ellipse = %d", m->is_ellipse);
  CHECK_NEAR(m->bounds[0], -1, 0);
  CHECK_NEAR(m->bounds[1], 0.5, 0);
  CHECK_NEAR(m->bounds[2], 2, 0);
  CHECK_NEAR(m->bounds[3], 1.5, 0);
  CHECK_NEAR(m->h, 0.5, 1e-15); /* dx = 0.5, dy = 0.25 */
  CHECK_NEAR(sp_mesh_region_area(m, SP_REGION_OMEGA), 3.0, 1e-14);
  CHECK_NEAR(sp_mesh_region_area(m, SP_REGION_BUFFER), 0.0, 0);
  check_mesh_invariants(m, "rectangle");
  /* Row by row, i fastest; element 0 counterclockwise from lower left. */
  CHECK_NEAR(m->xy[2 * 8], -0.5, 1e-15);  /* node (1, 1) */
  CHECK_NEAR(m->xy[2 * 8 + 1], 0.75, 1e-15);
  CHECK_NEAR(m->xy[2 * 34], 2, 0);        /* last node: exactly (x1, y1) */
  CHECK_NEAR(m->xy[2 * 34 + 1], 1.5, 0);
  int want[4] = {0, 1, 8, 7};
  for (int a = 0; a < 4; ++a)
    CHECK(m->elem[a] == want[a], "element 0 node %d = %d, want %d", a,
          m->elem[a], want[a]);
  CHECK(mesh_boundary_edges(m) == 20, "boundary edges = %d, want 2(6+4)",
        mesh_boundary_edges(m));
  sp_mesh_destroy(&m);
}

static void test_rectangle_contains(void) {
  sp_mesh *m = NULL;
  CHECK_OK(sp_mesh_rectangle(0, 0, 2, 1, 4, 2, &m));
  CHECK(sp_mesh_contains(m, (double[]){0, 0}) == 1, "corner (0,0) is in Omega");
  CHECK(sp_mesh_contains(m, (double[]){2, 1}) == 1, "corner (2,1) is in Omega");
  CHECK(sp_mesh_contains(m, (double[]){1, 0.5}) == 1, "centre is in Omega");
  CHECK(sp_mesh_contains(m, (double[]){2.001, 0.5}) == 0, "x > x1 is outside");
  CHECK(sp_mesh_contains(m, (double[]){1, -0.001}) == 0, "y < y0 is outside");
  sp_mesh_destroy(&m);
}

static void expect_input_error(int rc, sp_mesh *m, const char *name) {
  CHECK(rc == SP_ERR_INPUT, "bad %s: rc = %d, want SP_ERR_INPUT", name, rc);
  CHECK(m == NULL, "bad %s: *out must stay NULL", name);
  CHECK(strstr(sp_error_message(), name) != NULL,
        "message \"%s\" does not name %s", sp_error_message(), name);
}

static void test_rectangle_rejects_bad_arguments(void) {
  sp_mesh *m = NULL;
  expect_input_error(sp_mesh_rectangle(0, 0, 1, 1, 0, 3, &m), m, "nx");
  expect_input_error(sp_mesh_rectangle(0, 0, 1, 1, 3, -1, &m), m, "ny");
  expect_input_error(sp_mesh_rectangle(1, 0, 1, 1, 3, 3, &m), m, "x1");
  expect_input_error(sp_mesh_rectangle(0, 2, 1, 1, 3, 3, &m), m, "y1");
  expect_input_error(sp_mesh_rectangle(0, NAN, 1, 1, 3, 3, &m), m, "y0");
}

static void test_ellipse_counts(void) {
  for (int r = 0; r <= 5; ++r) {
    sp_mesh *m = NULL;
    CHECK_OK(sp_mesh_ellipse(r, 0.5, 0.25, 0, 0, &m));
    int n = 1 << r;
    CHECK(m->n_elems == 5 * n * n, "r = %d: n_elems = %d, want 5 4^r = %d", r,
          m->n_elems, 5 * n * n);
    CHECK(m->n_nodes == (n + 1) * (n + 1) + 4 * n * n,
          "r = %d: n_nodes = %d, want %d", r, m->n_nodes,
          (n + 1) * (n + 1) + 4 * n * n);
    CHECK(m->is_ellipse == 1, "is_ellipse = %d", m->is_ellipse);
    CHECK(m->bounds[0] == 0 && m->bounds[1] == 0 && m->bounds[2] == 0.5 &&
          m->bounds[3] == 0.25, "r = %d: bounds", r);
    if (r == 0)
      CHECK(m->n_elems == 5 && m->n_nodes == 8, "r = 0: %d elements, %d "
            "nodes, want 5 and 8", m->n_elems, m->n_nodes);
    if (r == 5)
      CHECK(m->n_elems == 5120 && m->n_nodes == 5185, "r = 5 (the paper's "
            "mesh): %d elements, %d nodes, want 5120 and 5185", m->n_elems,
            m->n_nodes);
    sp_mesh_destroy(&m);
  }
}

static void test_ellipse_is_valid_and_well_shaped(void) {
  /* The (a, b) scaling multiplies every det J by a b: the ratios printed
   * are those of the unit disk too. */
  printf("element quality (a = 0.5, b = 0.25; buffer width 0.1):\n"
         "   r  layers  detJ min/max (mesh)  detJ min/max (worst element)\n");
  for (int r = 0; r <= 6; ++r)
    for (int layers = 0; layers <= 2; layers += 2) {
      sp_mesh *m = NULL;
      CHECK_OK(sp_mesh_ellipse(r, 0.5, 0.25, layers, 0.1, &m));
      char what[64];
      snprintf(what, sizeof what, "ellipse r = %d, layers = %d", r, layers);
      check_mesh_invariants(m, what);
      jacobian_stats js = mesh_jacobians(m);
      printf("  %2d  %6d  %19.4f  %28.4f\n", r, layers,
             js.det_min / js.det_max, js.worst_element_ratio);
      /* Distortion per element must not degrade with refinement (the
       * blending map is smooth inside each patch). */
      if (r >= 2)
        CHECK(js.worst_element_ratio > 0.6, "%s: element det J ratio %.3f",
              what, js.worst_element_ratio);
      sp_mesh_destroy(&m);
    }
}

static void test_ellipse_is_conforming(void) {
  for (int r = 0; r <= 5; ++r)
    for (int layers = 0; layers <= 3; layers += 3) {
      sp_mesh *m = NULL;
      CHECK_OK(sp_mesh_ellipse(r, 1.0, 0.6, layers, 0.2, &m));
      int n = 1 << r, boundary = mesh_boundary_edges(m);
      /* No duplicate nodes along patch interfaces: then the interfaces
       * would show up as boundary edges. */
      CHECK(boundary == 4 * n, "r = %d, layers = %d: %d boundary edges "
            "(or -1: non-conforming), want 4n = %d", r, layers, boundary,
            4 * n);
      sp_mesh_destroy(&m);
    }
}

static void test_ellipse_nodes_are_distinct(void) {
  for (int layers = 0; layers <= 2; layers += 2) {
    sp_mesh *m = NULL;
    CHECK_OK(sp_mesh_ellipse(3, 0.5, 0.25, layers, 0.1, &m));
    double min_distance = INFINITY;
    for (int i = 0; i < m->n_nodes; ++i)
      for (int j = i + 1; j < m->n_nodes; ++j) {
        double d = hypot(m->xy[2 * i] - m->xy[2 * j],
                         m->xy[2 * i + 1] - m->xy[2 * j + 1]);
        if (d < min_distance) min_distance = d;
      }
    /* Smallest edge at r = 3 is ~0.01; coinciding nodes would give 0. */
    CHECK(min_distance > 1e-3, "layers = %d: two nodes %.3g apart", layers,
          min_distance);
    sp_mesh_destroy(&m);
  }
}

static void test_ellipse_boundary_nodes_lie_on_the_ellipse(void) {
  for (int r = 0; r <= 5; ++r) {
    sp_mesh *m = NULL;
    CHECK_OK(sp_mesh_ellipse(r, 0.5, 0.25, 0, 0, &m));
    int on = 0, outside = 0;
    for (int i = 0; i < m->n_nodes; ++i) {
      double level = ellipse_level(m, i);
      on += fabs(level - 1) < 1e-14;
      outside += !sp_mesh_contains(m, m->xy + 2 * i);
    }
    CHECK(on == 4 << r, "r = %d: %d nodes on the ellipse, want 4n = %d", r,
          on, 4 << r);
    CHECK(outside == 0, "r = %d: %d nodes outside Omega", r, outside);
    sp_mesh_destroy(&m);
  }
}

static void test_ellipse_area_converges_second_order(void) {
  const double a = 0.5, b = 0.25, exact = pi * a * b;
  double error_prev = 0;
  printf("area of the ellipse a = %g, b = %g (pi a b = %.15f):\n"
         "   r  elements  area               error       order\n", a, b,
         exact);
  for (int r = 2; r <= 6; ++r) {
    sp_mesh *m = NULL;
    CHECK_OK(sp_mesh_ellipse(r, a, b, 0, 0, &m));
    double area = sp_mesh_region_area(m, SP_REGION_OMEGA);
    double error = exact - area;
    /* The mesh is exactly the inscribed 4n-gon at uniform angles, and the
     * 2x2 Gauss rule integrates bilinear det J exactly. */
    CHECK_NEAR(area, inscribed_polygon_area(4 << r, a, b, 1), 1e-14);
    if (r == 2) {
      printf("  %2d  %8d  %.15f  %.3e\n", r, m->n_elems, area, error);
    } else {
      double order = log(error_prev / error) / log(2.0);
      printf("  %2d  %8d  %.15f  %.3e  %.3f\n", r, m->n_elems, area, error,
             order);
      CHECK(fabs(order - 2) <= 0.2, "r = %d: observed order %.3f", r, order);
    }
    CHECK(error > 0, "r = %d: the inscribed polygon must be smaller", r);
    error_prev = error;
    sp_mesh_destroy(&m);
  }
}

static void test_buffer_ring(void) {
  const double a = 0.5, b = 0.25, width = 0.1;
  const int layers = 2;
  printf("buffer ring (%d layers, width %g):\n"
         "   r  elements  Omega area         buffer area        "
         "pi a b ((1+w)^2-1)\n", layers, width);
  for (int r = 0; r <= 5; ++r) {
    sp_mesh *plain = NULL, *m = NULL;
    CHECK_OK(sp_mesh_ellipse(r, a, b, 0, 0, &plain));
    CHECK_OK(sp_mesh_ellipse(r, a, b, layers, width, &m));
    int n = 1 << r;
    CHECK(m->n_elems == 5 * n * n + 2 * 4 * n, "r = %d: %d elements, want "
          "5 4^r + 2 4 2^r = %d", r, m->n_elems, 5 * n * n + 8 * n);
    CHECK(m->n_nodes == plain->n_nodes + layers * 4 * n,
          "r = %d: %d nodes", r, m->n_nodes);
    int n_buffer = 0;
    for (int e = 0; e < m->n_elems; ++e)
      n_buffer += m->region[e] == SP_REGION_BUFFER;
    CHECK(n_buffer == layers * 4 * n, "r = %d: %d buffer elements", r,
          n_buffer);
    double omega = sp_mesh_region_area(m, SP_REGION_OMEGA);
    double buffer = sp_mesh_region_area(m, SP_REGION_BUFFER);
    double ring = pi * a * b * ((1 + width) * (1 + width) - 1);
    CHECK_NEAR(omega, sp_mesh_region_area(plain, SP_REGION_OMEGA), 1e-14);
    CHECK_NEAR(buffer,
               inscribed_polygon_area(4 * n, a, b, 1 + width) -
                   inscribed_polygon_area(4 * n, a, b, 1), 1e-14);
    /* Polygon error: relative 1 - sin(x)/x <= x^2/6, x = 2 pi / 4n. */
    double x = 2 * pi / (4 * n);
    CHECK_NEAR(buffer, ring, ring * x * x / 6);
    printf("  %2d  %8d  %.15f  %.15f  %.15f\n", r, m->n_elems, omega, buffer,
           ring);
    /* Buffer nodes are outside Omega except those on its boundary; the
     * outermost ring is at level (1 + w)^2. */
    int outer = 0, inside = 0;
    for (int i = 0; i < m->n_nodes; ++i) {
      double level = ellipse_level(m, i);
      outer += fabs(level - (1 + width) * (1 + width)) < 1e-13;
      inside += sp_mesh_contains(m, m->xy + 2 * i);
    }
    CHECK(outer == 4 * n, "r = %d: %d nodes on the outer buffer boundary", r,
          outer);
    CHECK(inside == plain->n_nodes, "r = %d: %d nodes in Omega, want %d", r,
          inside, plain->n_nodes);
    sp_mesh_destroy(&plain);
    sp_mesh_destroy(&m);
  }
}

static void test_h_halves_with_refinement(void) {
  double h_prev = 0;
  printf("largest edge h (a = 0.5, b = 0.25):\n");
  for (int r = 0; r <= 6; ++r) {
    sp_mesh *m = NULL;
    CHECK_OK(sp_mesh_ellipse(r, 0.5, 0.25, 0, 0, &m));
    printf("  r = %d  h = %.6f", r, m->h);
    if (r > 0) {
      printf("  ratio %.4f", h_prev / m->h);
      CHECK(h_prev / m->h > 1.8 && h_prev / m->h < 2.2,
            "r = %d: h ratio %.4f", r, h_prev / m->h);
    }
    printf("\n");
    h_prev = m->h;
    sp_mesh_destroy(&m);
  }
}

static void test_ellipse_contains(void) {
  sp_mesh *m = NULL;
  CHECK_OK(sp_mesh_ellipse(1, 0.5, 0.25, 0, 0, &m));
  CHECK(sp_mesh_contains(m, (double[]){0, 0}) == 1, "centre");
  CHECK(sp_mesh_contains(m, (double[]){0.5, 0}) == 1, "end of the x semi-axis");
  CHECK(sp_mesh_contains(m, (double[]){0, -0.25}) == 1, "end of the y semi-axis");
  CHECK(sp_mesh_contains(m, (double[]){0.5 * cos(1.0), 0.25 * sin(1.0)}) == 1,
        "a point on the ellipse");
  CHECK(sp_mesh_contains(m, (double[]){0.5001, 0}) == 0, "beyond the x semi-axis");
  CHECK(sp_mesh_contains(m, (double[]){0.36, 0.18}) == 0, "outside near the diagonal");
  sp_mesh_destroy(&m);
}

static void test_ellipse_numbering_has_small_bandwidth(void) {
  for (int r = 0; r <= 5; ++r) {
    sp_mesh *m = NULL;
    CHECK_OK(sp_mesh_ellipse(r, 0.5, 0.25, 2, 0.1, &m));
    int n = 1 << r, bw = mesh_bandwidth(m);
    CHECK(bw <= 4 * n + 2, "r = %d: bandwidth %d > 4n + 2 = %d", r, bw,
          4 * n + 2);
    sp_mesh_destroy(&m);
  }
}

static void test_ellipse_rejects_bad_arguments(void) {
  sp_mesh *m = NULL;
  expect_input_error(sp_mesh_ellipse(-1, 1, 1, 0, 0, &m), m, "refinements");
  expect_input_error(sp_mesh_ellipse(11, 1, 1, 0, 0, &m), m, "refinements");
  expect_input_error(sp_mesh_ellipse(2, 0, 1, 0, 0, &m), m, "semi-axis a");
  expect_input_error(sp_mesh_ellipse(2, NAN, 1, 0, 0, &m), m, "semi-axis a");
  expect_input_error(sp_mesh_ellipse(2, 1, -1, 0, 0, &m), m, "semi-axis b");
  expect_input_error(sp_mesh_ellipse(2, 1, 1, -1, 0.1, &m), m,
                     "buffer_layers");
  expect_input_error(sp_mesh_ellipse(2, 1, 1, 2, 0, &m), m, "buffer_width");
  /* Without buffer layers the width is unused and not checked. */
  CHECK_OK(sp_mesh_ellipse(0, 1, 1, 0, -5, &m));
  sp_mesh_destroy(&m);
}

static void test_destroy_leaves_null(void) {
  sp_mesh *m = NULL;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 1, 1, &m));
  sp_mesh_destroy(&m);
  CHECK(m == NULL, "destroy must set the pointer to NULL");
  sp_mesh_destroy(&m); /* a second destroy is harmless */
  sp_mesh_destroy(NULL);
}

int main(void) {
  test_rectangle_counts_area_and_numbering();
  test_rectangle_contains();
  test_rectangle_rejects_bad_arguments();
  test_ellipse_counts();
  test_ellipse_is_valid_and_well_shaped();
  test_ellipse_is_conforming();
  test_ellipse_nodes_are_distinct();
  test_ellipse_boundary_nodes_lie_on_the_ellipse();
  test_ellipse_area_converges_second_order();
  test_buffer_ring();
  test_h_halves_with_refinement();
  test_ellipse_contains();
  test_ellipse_numbering_has_small_bandwidth();
  test_ellipse_rejects_bad_arguments();
  test_destroy_leaves_null();
  TEST_DONE();
}
