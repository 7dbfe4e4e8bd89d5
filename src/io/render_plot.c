/* render_plot.c: the energy against time (energy.png), division times as dashed lines. */
#define _POSIX_C_SOURCE 200809L

#include "io/render.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>

#include "public/error.h"
#include "io/render_base.h"

/** A "nice" tick spacing (1, 2 or 5 times a power of ten) near @p raw. */
static double sp_nice_step(double raw) {
  double p = pow(10.0, floor(log10(raw)));
  double f = raw / p;
  return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
}

/**
 * Widen [*lo, *hi] when it is empty or too narrow to tick (a single point,
 * constant energy), so nothing divides by zero; otherwise pad by @p pad of
 * the range on each side.
 */
static void sp_axis_range(double *lo, double *hi, double pad) {
  double scale = fmax(fabs(*lo), fabs(*hi));
  if (!(*hi - *lo > 1e-12 * scale) || !(*hi - *lo > 1e-300)) {
    double d = scale > 0 ? 0.05 * scale : 1.0;
    *lo -= d;
    *hi += d;
    return;
  }
  double d = pad * (*hi - *lo);
  *lo -= d;
  *hi += d;
}

/**
 * Tick label for @p v on an axis with tick spacing @p step: as many decimals
 * as the spacing needs, and exponent notation for very large or small
 * magnitudes, so neighbouring labels always differ.
 */
static void sp_tick_label(char *buf, size_t len, double v, double step,
                          double maxabs) {
  if (fabs(v) < 1e-9 * step) v = 0.0; /* -1.2e-17 is 0 */
  int step_exp = (int)floor(log10(step) + 1e-9);
  if (maxabs >= 1e5 || maxabs < 1e-3) {
    int mag = v != 0 ? (int)floor(log10(fabs(v))) : step_exp;
    int digits = mag - step_exp;
    digits = digits < 0 ? 0 : digits > 12 ? 12 : digits;
    snprintf(buf, len, "%.*e", digits, v);
  } else {
    int dec = step_exp < 0 ? -step_exp : 0;
    snprintf(buf, len, "%.*f", dec > 12 ? 12 : dec, v);
  }
}

int sp_render_energy(const double *t, const double *energy, int n,
                     const double *marks, int n_marks, const char *path) {
  SP_CHECK(n >= 0 && (n == 0 || (t && energy)), SP_ERR_INTERNAL,
           "render: %d energy values but no arrays", n);
  const int W = 800, H = 500;
  const double L = 100, R = W - 25, T = 25, B = H - 60; /* plot area */

  /* Data range over the finite points only. */
  double t0 = HUGE_VAL, t1 = -HUGE_VAL, e0 = HUGE_VAL, e1 = -HUGE_VAL;
  int n_ok = 0;
  for (int i = 0; i < n; ++i)
    if (isfinite(t[i]) && isfinite(energy[i])) {
      t0 = fmin(t0, t[i]);
      t1 = fmax(t1, t[i]);
      e0 = fmin(e0, energy[i]);
      e1 = fmax(e1, energy[i]);
      ++n_ok;
    }
  if (!n_ok) t0 = e0 = 0, t1 = e1 = 1;
  sp_axis_range(&t0, &t1, 0.0);
  sp_axis_range(&e0, &e1, 0.05);
  const double sx = (R - L) / (t1 - t0), sy = (B - T) / (e1 - e0);
#define SP_PX(tv) (L + ((tv) - t0) * sx)
#define SP_PY(ev) (B - ((ev) - e0) * sy)

  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  SP_CALL(sp_render_cairo_check(cairo_surface_status(surf), "creating a surface", path));
  cairo_t *cr = cairo_create(surf);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 13);

  /* Ticks, grid lines and labels on both axes. */
  char label[64];
  cairo_text_extents_t ext;
  for (int axis = 0; axis < 2; ++axis) {
    double lo = axis ? e0 : t0, hi = axis ? e1 : t1;
    double step = sp_nice_step((hi - lo) / 5.0);
    double maxabs = fmax(fabs(lo), fabs(hi));
    double first = ceil(lo / step - 1e-9) * step;
    for (int i = 0; i < 40; ++i) {
      double v = first + i * step;
      if (v > hi + 1e-9 * step) break;
      sp_tick_label(label, sizeof label, v, step, maxabs);
      cairo_text_extents(cr, label, &ext);
      cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
      cairo_set_line_width(cr, 1);
      if (axis == 0) {
        double x = floor(SP_PX(v)) + 0.5;
        cairo_move_to(cr, x, T);
        cairo_line_to(cr, x, B + 5);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, x - ext.width / 2 - ext.x_bearing, B + 20);
      } else {
        double y = floor(SP_PY(v)) + 0.5;
        cairo_move_to(cr, L - 5, y);
        cairo_line_to(cr, R, y);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, L - 9 - ext.width - ext.x_bearing,
                      y - ext.height / 2 - ext.y_bearing);
      }
      cairo_show_text(cr, label);
    }
  }

  /* Axis titles. */
  cairo_set_font_size(cr, 15);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_text_extents(cr, "t", &ext);
  cairo_move_to(cr, (L + R) / 2 - ext.width / 2, H - 15);
  cairo_show_text(cr, "t");
  cairo_text_extents(cr, "energy", &ext);
  cairo_save(cr);
  cairo_move_to(cr, 22, (T + B) / 2 + ext.width / 2);
  cairo_rotate(cr, -SP_RENDER_PI / 2);
  cairo_show_text(cr, "energy");
  cairo_restore(cr);

  /* Plot contents, clipped to the plot area. */
  cairo_save(cr);
  cairo_rectangle(cr, L, T, R - L, B - T);
  cairo_clip(cr);
  if (marks && n_marks > 0) { /* e.g. divisions: dashed verticals */
    const double dash[] = {6, 4};
    cairo_set_dash(cr, dash, 2, 0);
    cairo_set_source_rgb(cr, 0.8, 0.3, 0.2);
    cairo_set_line_width(cr, 1);
    for (int i = 0; i < n_marks; ++i)
      if (isfinite(marks[i]) && marks[i] >= t0 && marks[i] <= t1) {
        double x = floor(SP_PX(marks[i])) + 0.5;
        cairo_move_to(cr, x, T);
        cairo_line_to(cr, x, B);
      }
    cairo_stroke(cr);
    cairo_set_dash(cr, NULL, 0, 0);
  }
  cairo_set_source_rgb(cr, 0.1, 0.3, 0.75);
  cairo_set_line_width(cr, 1.8);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  int pen_down = 0; /* a non-finite value breaks the line */
  for (int i = 0; i < n; ++i) {
    if (!(isfinite(t[i]) && isfinite(energy[i]))) {
      pen_down = 0;
      continue;
    }
    if (pen_down) cairo_line_to(cr, SP_PX(t[i]), SP_PY(energy[i]));
    else cairo_move_to(cr, SP_PX(t[i]), SP_PY(energy[i]));
    pen_down = 1;
  }
  cairo_stroke(cr);
  if (n_ok <= 30) /* few points (n = 1 has no line at all): mark them */
    for (int i = 0; i < n; ++i)
      if (isfinite(t[i]) && isfinite(energy[i])) {
        cairo_new_sub_path(cr);
        cairo_arc(cr, SP_PX(t[i]), SP_PY(energy[i]), 3, 0, 2 * SP_RENDER_PI);
        cairo_fill(cr);
      }
  cairo_restore(cr);
#undef SP_PX
#undef SP_PY

  /* Frame. */
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, floor(L) + 0.5, floor(T) + 0.5, floor(R - L),
                  floor(B - T));
  cairo_stroke(cr);

  int rc = sp_render_cairo_check(cairo_status(cr), "drawing", path);
  cairo_destroy(cr);
  if (rc == SP_OK) rc = sp_render_png_write(surf, path);
  cairo_surface_destroy(surf);
  return rc;
}
