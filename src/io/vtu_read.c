/* vtu_read.c: reads back a .vtu softpack wrote (initial.from), with its own base64 decoder. */
#define _POSIX_C_SOURCE 200809L

#include "io/vtu_read.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "public/error.h"

/** Decode base64 @p in (up to '<' or the end) into @p out; its length. */
static size_t sp_b64_decode(const char *in, unsigned char *out) {
  size_t n = 0;
  unsigned acc = 0;
  int bits = 0;
  for (; *in && *in != '<'; ++in) {
    const char c = *in;
    int v;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    else if (c >= '0' && c <= '9') v = c - '0' + 52;
    else if (c == '+') v = 62;
    else if (c == '/') v = 63;
    else continue; /* whitespace, padding */
    acc = (acc << 6) | (unsigned)v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out[n++] = (unsigned char)(acc >> bits);
    }
  }
  return n;
}

/** The values of the DataArray @p name of a .vtu's text (malloc'd; its
 *  byte count in *bytes), or NULL if it is missing or malformed. */
static void *sp_vtu_array(const char *xml, const char *name, size_t *bytes) {
  char key[64];
  snprintf(key, sizeof key, "Name=\"%s\"", name);
  const char *p = strstr(xml, key);
  if (!p || !(p = strchr(p, '>'))) return NULL;
  const char *end = strchr(p, '<');
  if (!end) return NULL;
  unsigned char *raw = malloc((size_t)(end - p) + 8);
  if (!raw) return NULL;
  const size_t n = sp_b64_decode(p + 1, raw);
  uint64_t header = 0;
  if (n >= 8) memcpy(&header, raw, 8);
  if (n < 8 || n != 8 + header) {
    free(raw);
    return NULL;
  }
  memmove(raw, raw + 8, header);
  *bytes = header;
  return raw;
}

void sp_vtu_fields_free(sp_vtu_fields *v) {
  free(v->xyz);
  free(v->c);
  free(v->mu);
  *v = (sp_vtu_fields){0};
}

int sp_vtu_read(const char *path, sp_vtu_fields *out) {
  *out = (sp_vtu_fields){0};
  FILE *f = fopen(path, "rb");
  SP_CHECK(f, SP_ERR_INPUT, "%s: cannot open it: %s", path, strerror(errno));
  fseek(f, 0, SEEK_END);
  const long len = ftell(f);
  rewind(f);
  char *xml = len >= 0 ? malloc((size_t)len + 1) : NULL;
  const size_t got = xml ? fread(xml, 1, (size_t)len, f) : 0;
  fclose(f);
  if (!xml) return sp_error_set(SP_ERR_MEMORY, "%s: out of memory reading it", path);
  xml[got] = '\0';
  int rc = SP_OK;
  if (!strstr(xml, "<VTKFile type=\"UnstructuredGrid\""))
    rc = sp_error_set(SP_ERR_INPUT, "%s: not a .vtu of one process's fields (a .pvtu's "
                                    "pieces are not read)", path);
  size_t bytes = 0;
  double *pts = rc == SP_OK ? sp_vtu_array(xml, "Points", &bytes) : NULL;
  if (rc == SP_OK && (!pts || bytes % (3 * sizeof(double))))
    rc = sp_error_set(SP_ERR_INPUT, "%s: no readable Points array (not softpack's .vtu?)", path);
  const int n = (int)(bytes / (3 * sizeof(double)));
  int n_cells = 0;
  while (rc == SP_OK) { /* c_1, c_2, ... as long as they exist */
    char name[32];
    snprintf(name, sizeof name, "Name=\"c_%d\"", n_cells + 1);
    if (!strstr(xml, name)) break;
    ++n_cells;
  }
  if (rc == SP_OK && n_cells == 0)
    rc = sp_error_set(SP_ERR_INPUT, "%s: no cell fields (c_1, ...) in it", path);
  if (rc == SP_OK) {
    out->n_points = n;
    out->n_cells = n_cells;
    out->xyz = malloc(sizeof(double) * 3 * (size_t)n + 1);
    out->c = malloc(sizeof(double) * (size_t)n * n_cells + 1);
    out->mu = malloc(sizeof(double) * (size_t)n * n_cells + 1);
    if (!out->xyz || !out->c || !out->mu) rc = sp_error_set(SP_ERR_MEMORY, "out of memory");
  }
  if (rc == SP_OK) memcpy(out->xyz, pts, sizeof(double) * 3 * (size_t)n);
  for (int k = 0; rc == SP_OK && k < n_cells; ++k)
    for (int which = 0; rc == SP_OK && which < 2; ++which) {
      char name[32];
      snprintf(name, sizeof name, "%s_%d", which ? "mu" : "c", k + 1);
      size_t b = 0;
      double *v = sp_vtu_array(xml, name, &b);
      if (!v || b != sizeof(double) * (size_t)n)
        rc = sp_error_set(SP_ERR_INPUT, "%s: array %s missing or of the wrong size", path, name);
      else memcpy((which ? out->mu : out->c) + (size_t)k * n, v, b);
      free(v);
    }
  free(pts);
  free(xml);
  if (rc != SP_OK) sp_vtu_fields_free(out);
  return rc;
}
