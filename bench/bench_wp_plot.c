/* A log-log plot of series of (x, y) points with cairo (the work-precision
 * report's figures, bench/work_precision.sh):
 *
 *   build/bench/bench_wp_plot OUT.png "x label" "y label" "title" < points
 *
 * Each input line is "SERIES X Y" (SERIES one word; points of a series in
 * the order given are joined by a line). Up to 8 series. */
#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SERIES 8
#define MAX_POINTS 64

typedef struct {
  char name[64];
  int n;
  double x[MAX_POINTS], y[MAX_POINTS];
} series;

static const double colours[MAX_SERIES][3] = {{0.80, 0.10, 0.10}, {0.10, 0.35, 0.80},
                                              {0.10, 0.60, 0.20}, {0.85, 0.55, 0.00},
                                              {0.50, 0.20, 0.65}, {0.00, 0.60, 0.65},
                                              {0.40, 0.40, 0.40}, {0.70, 0.40, 0.30}};

int main(int argc, char **argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: bench_wp_plot OUT.png XLABEL YLABEL TITLE < points\n");
    return 2;
  }
  series s[MAX_SERIES];
  int ns = 0;
  char name[64];
  double x, y;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  while (scanf("%63s %lf %lf", name, &x, &y) == 3) {
    if (!(x > 0) || !(y > 0)) continue; /* log axes */
    int k = 0;
    while (k < ns && strcmp(s[k].name, name) != 0) ++k;
    if (k == ns) {
      if (ns == MAX_SERIES) continue;
      snprintf(s[ns].name, sizeof s[ns].name, "%s", name);
      s[ns++].n = 0;
    }
    if (s[k].n == MAX_POINTS) continue;
    s[k].x[s[k].n] = x;
    s[k].y[s[k].n++] = y;
    x0 = fmin(x0, x), x1 = fmax(x1, x), y0 = fmin(y0, y), y1 = fmax(y1, y);
  }
  if (ns == 0) {
    fprintf(stderr, "bench_wp_plot: no points\n");
    return 2;
  }
  const double lx0 = floor(log10(x0)), lx1 = ceil(log10(x1) + 1e-9);
  const double ly0 = floor(log10(y0)), ly1 = ceil(log10(y1) + 1e-9);
  const int W = 720, H = 540, L = 90, R = 200, T = 50, B = 70;
  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  cairo_t *cr = cairo_create(surf);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  const double pw = W - L - R, ph = H - T - B;
#define PX(v) (L + (log10(v) - lx0) / (lx1 - lx0) * pw)
#define PY(v) (T + ph - (log10(v) - ly0) / (ly1 - ly0) * ph)
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 13);
  cairo_set_line_width(cr, 1);
  char label[64];
  for (double e = lx0; e <= lx1 + 1e-9; ++e) { /* decades along x */
    const double px = L + (e - lx0) / (lx1 - lx0) * pw;
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_move_to(cr, px, T);
    cairo_line_to(cr, px, T + ph);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    snprintf(label, sizeof label, "1e%g", e);
    cairo_move_to(cr, px - 14, T + ph + 18);
    cairo_show_text(cr, label);
  }
  for (double e = ly0; e <= ly1 + 1e-9; ++e) { /* decades along y */
    const double py = T + ph - (e - ly0) / (ly1 - ly0) * ph;
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_move_to(cr, L, py);
    cairo_line_to(cr, L + pw, py);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    snprintf(label, sizeof label, "1e%g", e);
    cairo_move_to(cr, L - 44, py + 4);
    cairo_show_text(cr, label);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, L, T, pw, ph);
  cairo_stroke(cr);
  cairo_move_to(cr, L + pw / 2 - 60, H - 25);
  cairo_show_text(cr, argv[2]);
  cairo_save(cr);
  cairo_move_to(cr, 25, T + ph / 2 + 60);
  cairo_rotate(cr, -M_PI / 2);
  cairo_show_text(cr, argv[3]);
  cairo_restore(cr);
  cairo_set_font_size(cr, 15);
  cairo_move_to(cr, L, 30);
  cairo_show_text(cr, argv[4]);
  cairo_set_font_size(cr, 13);
  cairo_set_line_width(cr, 2);
  for (int k = 0; k < ns; ++k) {
    cairo_set_source_rgb(cr, colours[k][0], colours[k][1], colours[k][2]);
    for (int i = 0; i < s[k].n; ++i) {
      if (i == 0) cairo_move_to(cr, PX(s[k].x[i]), PY(s[k].y[i]));
      else cairo_line_to(cr, PX(s[k].x[i]), PY(s[k].y[i]));
    }
    cairo_stroke(cr);
    for (int i = 0; i < s[k].n; ++i) {
      cairo_arc(cr, PX(s[k].x[i]), PY(s[k].y[i]), 4, 0, 2 * M_PI);
      cairo_fill(cr);
    }
    cairo_rectangle(cr, L + pw + 15, T + 10 + 22 * k, 14, 10);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, L + pw + 35, T + 20 + 22 * k);
    cairo_show_text(cr, s[k].name);
  }
  const int rc = cairo_surface_write_to_png(surf, argv[1]) == CAIRO_STATUS_SUCCESS ? 0 : 1;
  cairo_destroy(cr);
  cairo_surface_destroy(surf);
  return rc;
}
