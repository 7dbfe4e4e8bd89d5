/* The C. elegans scene in 2D (inputs/embryo/celegans_8_2d.yaml: P0 to the
 * 8-cell stage by its lineage table, s = 0), through `softpack run`,
 * about 15 s of CPU:
 * - the table's fractions are the CShaper atlas's volume ratios (Cao et
 *   al. 2020) to 5e-7 (the scene gives 6 digits);
 * - divisions.csv has exactly the table's 7 divisions, no more (s = 0,
 *   no division: rules), in the embryo's order: AB before P1, ABa and ABp
 *   before EMS, P2 last; each first daughter's share of its parent's mass
 *   is the table's to 1e-9 (the smoothed cut) and the daughters sum to the
 *   parent to 1e-12;
 * - at the end there are 8 cells, named ABal, ABar, ABpl, ABpr, MS, E, C
 *   and P3; each cell's mass as a fraction of the 8 cells' is the product
 *   of the fractions along its lineage to 1e-9 relative (every cell's
 *   mass is conserved between divisions);
 * - the last fields file's cell_name array (FieldData) has the 8 names,
 *   cell k's at tuple k - 1 as in cells.csv;
 * - each cell's area (c >= 1/2) as a fraction of the 8 cells' is the
 *   atlas's volume fraction V_i / sum V within d / R_i relative, where d =
 *   sqrt(kappa / 2 alpha) is the interface width and R_i = sqrt(A_i / pi)
 *   the cell's radius: the c >= 1/2 set of a cell differs from its mass by
 *   at most about half an interface width d/2 along its perimeter 2 pi R,
 *   a relative pi R d / (pi R^2) = d / R (the atlas's own 8-cell volumes
 *   are not the products of its division ratios either: P3's fraction
 *   differs from the product by 0.7%, well inside). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "public/run.h"

#define SCENE SP_SOURCE_DIR "/inputs/embryo/celegans_8_2d.yaml"
#define OUT "test_celegans_2d_out"
enum { N_DIV = 7, N_FINAL = 8 };

/* The atlas's volumes (um^3) and the lineage. */
static const struct {
  const char *name, *parent;
  double volume;
} atlas[] = {{"P0", "", 20769},    {"AB", "P0", 12304},  {"P1", "P0", 8465},
             {"ABa", "AB", 6195},  {"ABp", "AB", 6109},  {"EMS", "P1", 4856},
             {"P2", "P1", 3609},   {"ABal", "ABa", 2930}, {"ABar", "ABa", 3162},
             {"ABpl", "ABp", 3156}, {"ABpr", "ABp", 2857}, {"MS", "EMS", 2550},
             {"E", "EMS", 2249},   {"C", "P2", 2368},    {"P3", "P2", 1157}};
enum { N_ATLAS = sizeof atlas / sizeof atlas[0] };

static int atlas_index(const char *name) {
  for (int i = 0; i < N_ATLAS; ++i)
    if (!strcmp(atlas[i].name, name)) return i;
  return -1;
}

typedef struct {
  double mass, area;
  char name[32];
} cell_row;

/** The rows of cells.csv's last step: their number. */
static int read_last_cells(int last_step, cell_row *rows, int cap) {
  csv_table t;
  CHECK(csv_read(OUT "/cells.csv", &t) == 0, "no cells.csv");
  CHECK(!strcmp(t.header, "step,t,cell,mass,xc,yc,I1,I2,angle,core_mass,area,name\n"),
        "cells.csv header: %s", t.header);
  int n = 0;
  for (int i = 0; i < t.n_rows && n < cap; ++i) {
    if ((int)at(&t, i, "step") != last_step) continue;
    rows[n] = (cell_row){.mass = at(&t, i, "mass"), .area = at(&t, i, "area")};
    snprintf(rows[n].name, sizeof rows[n].name, "%s", at_str(&t, i, "name"));
    ++n;
  }
  csv_free(&t);
  return n;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  CHECK(system("rm -rf " OUT) == 0, "cannot clear the output");
  const char *set[] = {"output.pictures=false", "output.every=100000"};
  sp_run_summary sum;
  CHECK_OK(sp_run_file(SCENE, 2, set, OUT, MPI_COMM_WORLD, NULL, NULL, &sum));
  printf("%d steps to t = %.6g, %d divisions, %d cells\n", sum.steps, sum.t_final,
         sum.divisions, sum.n_cells);
  CHECK(sum.divisions == N_DIV && sum.n_cells == N_FINAL, "%d divisions, %d cells",
        sum.divisions, sum.n_cells);

  division_row rows[N_DIV + 2];
  const int n = divisions_read(OUT, NULL, rows, N_DIV + 2);
  CHECK(n == N_DIV, "%d rows in divisions.csv, the table has %d", n, N_DIV);
  double t_of[N_ATLAS], share_of[N_ATLAS]; /* a parent's division time; a cell's share */
  for (int i = 0; i < N_ATLAS; ++i) t_of[i] = NAN, share_of[i] = 1.0;
  for (int i = 0; i < n; ++i) {
    const division_row *r = &rows[i];
    const int p = atlas_index(r->parent_name), a = atlas_index(r->first),
              b = atlas_index(r->second);
    CHECK(p >= 0 && a >= 0 && b >= 0 && !strcmp(atlas[a].parent, r->parent_name) &&
              !strcmp(atlas[b].parent, r->parent_name),
          "division %d: %s -> %s, %s is not the lineage's", i + 1, r->parent_name, r->first,
          r->second);
    if (p < 0 || a < 0 || b < 0) continue;
    const double ratio = atlas[a].volume / (atlas[a].volume + atlas[b].volume);
    const double share = r->a / r->before;
    printf("t = %.6f: %-3s -> %-4s %-4s table %.6f (atlas %.6f), share %.12f\n", r->t,
           r->parent_name, r->first, r->second, r->fraction, ratio, share);
    CHECK(fabs(r->fraction - ratio) <= 5e-7, "%s: the table's %.17g, the atlas's %.17g",
          r->parent_name, r->fraction, ratio);
    CHECK(fabs(share - r->fraction) <= 1e-9, "%s: share %.12f, table %.12f", r->parent_name,
          share, r->fraction);
    CHECK(fabs(r->a + r->b - r->before) <= 1e-12 * r->before, "%s: %.17g + %.17g != %.17g",
          r->parent_name, r->a, r->b, r->before);
    t_of[p] = r->t;
    share_of[a] = r->fraction;
    share_of[b] = 1 - r->fraction;
  }
  const double t_ab = t_of[atlas_index("AB")], t_p1 = t_of[atlas_index("P1")];
  const double t_aba = t_of[atlas_index("ABa")], t_abp = t_of[atlas_index("ABp")];
  const double t_ems = t_of[atlas_index("EMS")], t_p2 = t_of[atlas_index("P2")];
  CHECK(t_ab < t_p1, "AB at %g, not before P1 at %g", t_ab, t_p1);
  CHECK(fmax(t_aba, t_abp) < t_ems, "ABa, ABp at %g, %g, not before EMS at %g", t_aba, t_abp,
        t_ems);
  for (int i = 0; i < N_ATLAS; ++i)
    CHECK(isnan(t_of[i]) || t_of[i] <= t_p2, "%s divides at %g, after P2 at %g", atlas[i].name,
          t_of[i], t_p2);

  cell_row cells[N_FINAL + 2];
  const int m = read_last_cells(sum.steps, cells, N_FINAL + 2);
  CHECK(m == N_FINAL, "%d cells at the end", m);
  double mass = 0, area = 0, volume = 0;
  for (int k = 0; k < m; ++k) mass += cells[k].mass, area += cells[k].area;
  for (int i = 7; i < N_ATLAS; ++i) volume += atlas[i].volume;
  const double d = sqrt(1e-3 / (2 * 4.0)); /* the scene: kappa = 1e-3, alpha = 4 (defaults) */
  int seen[N_ATLAS] = {0};
  printf("cell  mass fraction  lineage product  area fraction  atlas   off     d/R\n");
  for (int k = 0; k < m; ++k) {
    const int i = atlas_index(cells[k].name);
    CHECK(i >= 7 && !seen[i], "cell %d at the end is %s", k + 1, cells[k].name);
    if (i < 7 || seen[i]) continue;
    seen[i] = 1;
    double product = 1;
    for (int j = i; j > 0; j = atlas_index(atlas[j].parent)) product *= share_of[j];
    const double mf = cells[k].mass / mass, af = cells[k].area / area;
    const double want = atlas[i].volume / volume, radius = sqrt(cells[k].area / acos(-1.0));
    const double off = fabs(af - want) / want;
    printf("%-4s  %.9f    %.9f      %.5f        %.5f %.4f  %.4f\n", cells[k].name, mf, product,
           af, want, off, d / radius);
    CHECK(fabs(mf - product) <= 1e-9 * product, "%s: mass fraction %.12f, lineage %.12f",
          cells[k].name, mf, product);
    CHECK(off <= d / radius, "%s: area fraction %.5f, atlas %.5f: %.4f off, above d/R = %.4f",
          cells[k].name, af, want, off, d / radius);
  }

  /* The last fields file (fields.pvd's last DataSet) names every cell, cell
   * k's name at tuple k - 1, as cells.csv does at the end. */
  char *pvd = slurp(OUT "/fields.pvd", NULL), vtu[256] = "";
  const char *last = NULL;
  for (const char *p = pvd; p && (p = strstr(p, "file=\"")); p += 6) last = p + 6;
  if (last) snprintf(vtu, sizeof vtu, OUT "/%.*s", (int)strcspn(last, "\""), last);
  char *xml = slurp(vtu, NULL);
  CHECK(xml != NULL, "cannot read the last fields file '%s'", vtu);
  char names[N_FINAL + 2][32];
  const int n_names = xml ? vtu_strings(xml, "cell_name", names, N_FINAL + 2) : -1;
  CHECK(n_names == N_FINAL, "%s: %d names in cell_name", vtu, n_names);
  for (int k = 0; k < n_names && k < m; ++k)
    CHECK(!strcmp(names[k], cells[k].name), "%s: cell %d is %s, cells.csv says %s", vtu, k + 1,
          names[k], cells[k].name);
  printf("%s: cell_name", vtu);
  for (int k = 0; k < n_names; ++k) printf(" %s", names[k]);
  printf("\n");
  free(xml);
  free(pvd);
  MPI_Finalize();
  TEST_DONE();
}
