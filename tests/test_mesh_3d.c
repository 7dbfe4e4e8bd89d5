/* The ellipsoid mesh (sp_mesh_ellipsoid, the cubed ball), each
 * test_* function one behaviour:
 *  - node and element counts equal the formulas (n = 2^r, L buffer shells)
 *    V = (n+1)^3 + (n+L)(6n^2+2), E = n^3 + 6n^2(n+L), and
 *    sp_mesh_ellipsoid_nodes / _elements say the same; r = 0 is deal.II's
 *    7-hexahedron ball of 16 nodes;
 *  - every node index in range and used, det J > 0 at all 8 Gauss points of
 *    every element, and conformity: every face shared by two elements except
 *    the 6n^2 of the outer surface (duplicated nodes on the patches'
 *    interfaces would add faces);
 *  - the 6n^2 + 2 nodes of the boundary lie on the ellipsoid (and on
 *    (1+w)^2 for the buffer's), none outside Omega (sp_mesh_contains);
 *  - the volume converges to 4/3 pi a b c at order 2 (within 0.15) from
 *    below (the boundary's bilinear patches lie inside the convex hull of
 *    their nodes on the ellipsoid);
 *  - the buffer shell: 6n^2 L elements, Omega's volume unchanged, and its
 *    volume exactly ((1+w)^3 - 1) times Omega's (its surfaces are Omega's
 *    boundary scaled by 1 and 1+w, and 2x2x2 Gauss integrates a trilinear
 *    det J exactly), so its relative error against the exact shell
 *    4/3 pi a b c ((1+w)^3 - 1) is Omega's, which converges at order 2;
 *  - the unit ball's mesh is exactly symmetric under the axis mirrors and
 *    permutations (every mapped node has a node at the same coordinates);
 *  - h halves with each refinement; bad arguments are SP_ERR_INPUT naming
 *    the argument, nothing made. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "mesh/mesh.h"
#include "mesh/q1.h"

static const double pi = 3.14159265358979323846;

static long long expected_nodes(int r, int layers) {
  const long long n = 1LL << r;
  return (n + 1) * (n + 1) * (n + 1) + (n + layers) * (6 * n * n + 2);
}

static long long expected_elements(int r, int layers) {
  const long long n = 1LL << r;
  return n * n * n + 6 * n * n * (n + layers);
}

/** (x/a)^2 + (y/b)^2 + (z/c)^2 of node i. */
static double level(const sp_mesh *m, int i) {
  const double *x = m->xy + 3 * (size_t)i;
  const double u = x[0] / m->bounds[2], v = x[1] / m->bounds[3], w = x[2] / m->bounds[5];
  return u * u + v * v + w * w;
}

static void test_counts(void) {
  for (int r = 0; r <= 4; ++r)
    for (int layers = 0; layers <= 3; layers += 3) {
      sp_mesh *m = NULL;
      CHECK_OK(sp_mesh_ellipsoid(r, 0.5, 0.25, 0.3, layers, 0.1, &m));
      CHECK(m->dim == 3 && m->nodes_per_elem == 8 && m->is_ellipse == 1, "r = %d: dim %d", r,
            m->dim);
      CHECK(m->n_nodes == expected_nodes(r, layers), "r = %d, L = %d: %d nodes, want %lld", r,
            layers, m->n_nodes, expected_nodes(r, layers));
      CHECK(m->n_elems == expected_elements(r, layers), "r = %d, L = %d: %d elements, want %lld",
            r, layers, m->n_elems, expected_elements(r, layers));
      CHECK(sp_mesh_ellipsoid_nodes(r, layers) == m->n_nodes, "sp_mesh_ellipsoid_nodes %lld",
            sp_mesh_ellipsoid_nodes(r, layers));
      CHECK(sp_mesh_ellipsoid_elements(r, layers) == m->n_elems,
            "sp_mesh_ellipsoid_elements %lld", sp_mesh_ellipsoid_elements(r, layers));
      CHECK(m->bounds[0] == 0 && m->bounds[1] == 0 && m->bounds[2] == 0.5 &&
                m->bounds[3] == 0.25 && m->bounds[4] == 0 && m->bounds[5] == 0.3,
            "r = %d: bounds", r);
      sp_mesh_destroy(&m);
    }
  sp_mesh *m = NULL;
  CHECK_OK(sp_mesh_ellipsoid(0, 1, 1, 1, 0, 0, &m));
  CHECK(m->n_elems == 7 && m->n_nodes == 16, "r = 0: %d elements, %d nodes, want 7 and 16",
        m->n_elems, m->n_nodes);
  sp_mesh_destroy(&m);
}

typedef struct {
  int node[4];
} face_key;

static int face_compare(const void *pa, const void *pb) {
  const face_key *a = pa, *b = pb;
  for (int i = 0; i < 4; ++i)
    if (a->node[i] != b->node[i]) return a->node[i] < b->node[i] ? -1 : 1;
  return 0;
}

static int int_compare(const void *pa, const void *pb) {
  const int a = *(const int *)pa, b = *(const int *)pb;
  return (a > b) - (a < b);
}

/** Faces used by one element (the boundary), or -1 if a face is used by
 *  more than two. */
static int boundary_faces(const sp_mesh *m) {
  static const int face[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                 {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  const int n_faces = 6 * m->n_elems;
  face_key *faces = malloc((size_t)n_faces * sizeof *faces);
  for (int e = 0; e < m->n_elems; ++e)
    for (int f = 0; f < 6; ++f) {
      face_key *k = &faces[6 * e + f];
      for (int i = 0; i < 4; ++i) k->node[i] = m->elem[8 * e + face[f][i]];
      qsort(k->node, 4, sizeof(int), int_compare);
    }
  qsort(faces, (size_t)n_faces, sizeof *faces, face_compare);
  int boundary = 0;
  for (int i = 0; i < n_faces;) {
    int j = i;
    while (j < n_faces && face_compare(&faces[i], &faces[j]) == 0) ++j;
    if (j - i == 1) ++boundary;
    else if (j - i != 2) boundary = -n_faces;
    i = j;
  }
  free(faces);
  return boundary < 0 ? -1 : boundary;
}

static void test_valid_and_conforming(void) {
  printf("element quality (a, b, c = 0.5, 0.25, 0.3; buffer width 0.1):\n"
         "   r  layers  detJ min/max (worst element)\n");
  double worst_prev[2] = {0, 0};
  for (int r = 0; r <= 4; ++r)
    for (int layers = 0; layers <= 2; layers += 2) {
      sp_mesh *m = NULL;
      CHECK_OK(sp_mesh_ellipsoid(r, 0.5, 0.25, 0.3, layers, 0.1, &m));
      int bad_index = 0, unused = 0, bad_region = 0, n_buffer = 0, nonpositive = 0;
      double worst = 1;
      char *used = calloc((size_t)m->n_nodes, 1);
      for (int c = 0; c < 8 * m->n_elems; ++c) {
        if (m->elem[c] < 0 || m->elem[c] >= m->n_nodes) ++bad_index;
        else used[m->elem[c]] = 1;
      }
      for (int i = 0; i < m->n_nodes; ++i) unused += !used[i];
      free(used);
      for (int e = 0; e < m->n_elems; ++e) {
        bad_region += m->region[e] != SP_REGION_OMEGA && m->region[e] != SP_REGION_BUFFER;
        n_buffer += m->region[e] == SP_REGION_BUFFER;
        double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], N[SP_Q1_MAX_NODES];
        double dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w, lo = INFINITY, hi = 0;
        sp_mesh_elem_xy(m, e, xe);
        for (int q = 0; q < 8; ++q) {
          const double det = sp_q1_point(3, xe, q, N, dNdx, x, &w);
          nonpositive += !(det > 0);
          lo = fmin(lo, det);
          hi = fmax(hi, det);
        }
        worst = fmin(worst, lo / hi);
      }
      const int n = 1 << r;
      printf("  %2d  %6d  %.4f\n", r, layers, worst);
      CHECK(bad_index == 0 && unused == 0 && bad_region == 0,
            "r = %d, L = %d: %d indices out of range, %d unused nodes, %d bad regions", r,
            layers, bad_index, unused, bad_region);
      CHECK(nonpositive == 0, "r = %d, L = %d: det J <= 0 at %d Gauss points", r, layers,
            nonpositive);
      CHECK(n_buffer == 6 * n * n * layers, "r = %d, L = %d: %d buffer elements, want %d", r,
            layers, n_buffer, 6 * n * n * layers);
      const int boundary = boundary_faces(m);
      CHECK(boundary == 6 * n * n, "r = %d, L = %d: %d boundary faces (-1: a face in three "
            "elements), want 6n^2 = %d", r, layers, boundary, 6 * n * n);
      /* the blend is smooth inside each patch: from r = 1 on, refining
       * makes the worst element less distorted, never more (measured:
       * 0.30, 0.44, 0.61, 0.76 at r = 1..4) */
      if (r >= 2)
        CHECK(worst >= worst_prev[layers / 2], "r = %d, L = %d: the worst element's det J "
              "ratio %.4f fell from %.4f", r, layers, worst, worst_prev[layers / 2]);
      worst_prev[layers / 2] = worst;
      sp_mesh_destroy(&m);
    }
}

static void test_boundary_nodes_on_the_ellipsoid(void) {
  const double width = 0.2;
  for (int r = 0; r <= 4; ++r)
    for (int layers = 0; layers <= 2; layers += 2) {
      sp_mesh *m = NULL;
      CHECK_OK(sp_mesh_ellipsoid(r, 0.5, 0.25, 0.3, layers, width, &m));
      const int n = 1 << r;
      int on = 0, outer = 0, inside = 0;
      for (int i = 0; i < m->n_nodes; ++i) {
        on += fabs(level(m, i) - 1) < 1e-14;
        outer += fabs(level(m, i) - (1 + width) * (1 + width)) < 1e-13;
        inside += sp_mesh_contains(m, m->xy + 3 * (size_t)i);
      }
      CHECK(on == 6 * n * n + 2, "r = %d: %d nodes on the ellipsoid, want 6n^2 + 2 = %d", r,
            on, 6 * n * n + 2);
      if (layers)
        CHECK(outer == 6 * n * n + 2, "r = %d: %d nodes on the buffer's outer boundary", r,
              outer);
      CHECK(inside == (int)expected_nodes(r, 0), "r = %d, L = %d: %d nodes in Omega, want %lld",
            r, layers, inside, expected_nodes(r, 0));
      sp_mesh_destroy(&m);
    }
}

static void test_volume_converges_second_order(void) {
  const double a = 0.5, b = 0.25, c = 0.3, exact = 4.0 / 3.0 * pi * a * b * c;
  double error_prev = 0;
  printf("volume of the ellipsoid %g x %g x %g (4/3 pi a b c = %.15f):\n"
         "   r  elements  volume             error      order\n",
         a, b, c, exact);
  for (int r = 2; r <= 5; ++r) {
    sp_mesh *m = NULL;
    CHECK_OK(sp_mesh_ellipsoid(r, a, b, c, 0, 0, &m));
    const double volume = sp_mesh_region_area(m, SP_REGION_OMEGA), error = exact - volume;
    CHECK(error > 0, "r = %d: the mesh (inside the ellipsoid) must be smaller: %.15g", r,
          volume);
    if (r == 2) {
      printf("  %2d  %8d  %.15f  %.3e\n", r, m->n_elems, volume, error);
    } else {
      const double order = log(error_prev / error) / log(2.0);
      printf("  %2d  %8d  %.15f  %.3e  %.3f\n", r, m->n_elems, volume, error, order);
      CHECK(fabs(order - 2) <= 0.15, "r = %d: observed order %.3f", r, order);
    }
    error_prev = error;
    sp_mesh_destroy(&m);
  }
}

static void test_buffer_shell(void) {
  const double a = 0.5, b = 0.25, c = 0.3, width = 0.1;
  const int layers = 2;
  const double grow = (1 + width) * (1 + width) * (1 + width) - 1;
  const double shell = 4.0 / 3.0 * pi * a * b * c * grow;
  double error_prev = 0;
  printf("buffer shell (%d layers, width %g; exact %.15f):\n"
         "   r  Omega volume       buffer volume      relative error  order\n",
         layers, width, shell);
  for (int r = 1; r <= 4; ++r) {
    sp_mesh *plain = NULL, *m = NULL;
    CHECK_OK(sp_mesh_ellipsoid(r, a, b, c, 0, 0, &plain));
    CHECK_OK(sp_mesh_ellipsoid(r, a, b, c, layers, width, &m));
    const double omega = sp_mesh_region_area(m, SP_REGION_OMEGA);
    const double buffer = sp_mesh_region_area(m, SP_REGION_BUFFER);
    CHECK_NEAR(omega, sp_mesh_region_area(plain, SP_REGION_OMEGA), 1e-14);
    CHECK(fabs(buffer - grow * omega) <= 1e-13 * buffer,
          "r = %d: buffer %.17g, ((1+w)^3 - 1) Omega = %.17g", r, buffer, grow * omega);
    const double error = (shell - buffer) / shell;
    CHECK(error > 0, "r = %d: the buffer volume %.15g is not below the shell's", r, buffer);
    if (r == 1) {
      printf("  %2d  %.15f  %.15f  %.3e\n", r, omega, buffer, error);
    } else {
      const double order = log(error_prev / error) / log(2.0);
      printf("  %2d  %.15f  %.15f  %.3e       %.3f\n", r, omega, buffer, error, order);
      if (r >= 3) CHECK(fabs(order - 2) <= 0.15, "r = %d: observed order %.3f", r, order);
    }
    error_prev = error;
    sp_mesh_destroy(&plain);
    sp_mesh_destroy(&m);
  }
}

static int point_compare(const void *pa, const void *pb) {
  const double *a = pa, *b = pb;
  for (int d = 0; d < 3; ++d)
    if (a[d] != b[d]) return a[d] < b[d] ? -1 : 1;
  return 0;
}

static void test_unit_ball_is_symmetric(void) {
  sp_mesh *m = NULL;
  CHECK_OK(sp_mesh_ellipsoid(3, 1, 1, 1, 2, 0.1, &m));
  double *sorted = malloc(3 * (size_t)m->n_nodes * sizeof *sorted);
  memcpy(sorted, m->xy, 3 * (size_t)m->n_nodes * sizeof *sorted);
  qsort(sorted, (size_t)m->n_nodes, 3 * sizeof *sorted, point_compare);
  int missing = 0;
  for (int i = 0; i < m->n_nodes; ++i) {
    const double *x = m->xy + 3 * (size_t)i;
    const double images[4][3] = {{-x[0], x[1], x[2]}, {x[0], -x[1], x[2]},
                                 {x[0], x[1], -x[2]}, {x[1], x[2], x[0]}};
    for (int k = 0; k < 4; ++k)
      missing += !bsearch(images[k], sorted, (size_t)m->n_nodes, 3 * sizeof *sorted,
                          point_compare);
  }
  CHECK(missing == 0, "%d mirrored or rotated nodes have no node at their coordinates",
        missing);
  free(sorted);
  sp_mesh_destroy(&m);
}

static void test_h_halves_with_refinement(void) {
  double h_prev = 0;
  for (int r = 0; r <= 5; ++r) {
    sp_mesh *m = NULL;
    CHECK_OK(sp_mesh_ellipsoid(r, 0.5, 0.25, 0.3, 0, 0, &m));
    printf("  r = %d  h = %.6f\n", r, m->h);
    if (r >= 2)
      CHECK(h_prev / m->h > 1.8 && h_prev / m->h < 2.2, "r = %d: h ratio %.4f", r,
            h_prev / m->h);
    h_prev = m->h;
    sp_mesh_destroy(&m);
  }
}

static void test_contains(void) {
  sp_mesh *m = NULL;
  CHECK_OK(sp_mesh_ellipsoid(1, 0.5, 0.25, 0.3, 0, 0, &m));
  CHECK(sp_mesh_contains(m, (double[]){0, 0, 0}) == 1, "centre");
  CHECK(sp_mesh_contains(m, (double[]){0, 0, -0.3}) == 1, "end of the z semi-axis");
  CHECK(sp_mesh_contains(m, (double[]){0, 0.25, 0}) == 1, "end of the y semi-axis");
  CHECK(sp_mesh_contains(m, (double[]){0, 0, 0.3001}) == 0, "beyond the z semi-axis");
  CHECK(sp_mesh_contains(m, (double[]){0.3, 0.15, 0.18}) == 0, "outside near the diagonal");
  CHECK(sp_mesh_contains(m, (double[]){0.25, 0.125, 0.15}) == 1, "inside near the diagonal");
  sp_mesh_destroy(&m);
  CHECK_OK(sp_mesh_box(0, 0, 0, 1, 1, 2, 1, 1, 1, &m));
  CHECK(sp_mesh_contains(m, (double[]){0.5, 0.5, 1.9}) == 1, "in the box");
  CHECK(sp_mesh_contains(m, (double[]){0.5, 0.5, 2.1}) == 0, "above the box");
  sp_mesh_destroy(&m);
}

static void expect_input_error(int rc, sp_mesh *m, const char *name) {
  CHECK(rc == SP_ERR_INPUT, "bad %s: rc = %d, want SP_ERR_INPUT", name, rc);
  CHECK(m == NULL, "bad %s: *out must stay NULL", name);
  CHECK(strstr(sp_error_message(), name) != NULL, "message \"%s\" does not name %s",
        sp_error_message(), name);
}

static void test_rejects_bad_arguments(void) {
  sp_mesh *m = NULL;
  expect_input_error(sp_mesh_ellipsoid(-1, 1, 1, 1, 0, 0, &m), m, "refinements");
  expect_input_error(sp_mesh_ellipsoid(SP_MESH_ELLIPSOID_MAX_REFINEMENTS + 1, 1, 1, 1, 0, 0, &m),
                     m, "refinements");
  expect_input_error(sp_mesh_ellipsoid(2, 0, 1, 1, 0, 0, &m), m, "semi-axis a");
  expect_input_error(sp_mesh_ellipsoid(2, 1, NAN, 1, 0, 0, &m), m, "semi-axis b");
  expect_input_error(sp_mesh_ellipsoid(2, 1, 1, -1, 0, 0, &m), m, "semi-axis c");
  expect_input_error(sp_mesh_ellipsoid(2, 1, 1, 1, -1, 0.1, &m), m, "buffer_layers");
  expect_input_error(sp_mesh_ellipsoid(2, 1, 1, 1, 2, 0, &m), m, "buffer_width");
}

int main(void) {
  test_counts();
  test_valid_and_conforming();
  test_boundary_nodes_on_the_ellipsoid();
  test_volume_converges_second_order();
  test_buffer_shell();
  test_unit_ball_is_symmetric();
  test_h_halves_with_refinement();
  test_contains();
  test_rejects_bad_arguments();
  TEST_DONE();
}
