/* Reading what src/output.c writes, for tests: whole files, and the
 * DataArrays of a .vtu (inline base64 with a UInt64 byte-count header). */
#ifndef SP_TEST_VTU_READ_H
#define SP_TEST_VTU_READ_H
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The whole file as a string (NULL if unreadable); its length in *len. */
static char *slurp(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *s = malloc((size_t)n + 1);
  size_t got = fread(s, 1, (size_t)n, f);
  s[got] = '\0';
  fclose(f);
  if (len) *len = got;
  return s;
}

static int b64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

/* Decode base64 from s up to '<'. A padded quad may also occur mid-stream
 * (some writers encode the header separately), so accept that too.
 * Returns the byte count. */
static size_t b64_decode(const char *s, unsigned char *out, size_t cap) {
  size_t n = 0;
  char q[4];
  int nq = 0;
  for (; *s && *s != '<'; ++s) {
    if (*s == ' ' || *s == '\n' || *s == '\r' || *s == '\t') continue;
    q[nq++] = *s;
    if (nq < 4) continue;
    nq = 0;
    int pad = (q[2] == '=') + (q[3] == '=');
    unsigned v = 0;
    for (int i = 0; i < 4; ++i)
      v = v << 6 | (unsigned)(q[i] == '=' ? 0 : b64_value(q[i]));
    unsigned char b[3] = {(unsigned char)(v >> 16), (unsigned char)(v >> 8),
                          (unsigned char)v};
    for (int i = 0; i < 3 - pad && n < cap; ++i) out[n++] = b[i];
  }
  return n;
}

/* The data of DataArray @p name in @p xml after its UInt64 byte-count
 * header: a malloc'd copy, its length in *bytes; NULL if absent or short. */
static unsigned char *vtu_array_data(const char *xml, const char *name, size_t *bytes) {
  char key[64];
  snprintf(key, sizeof key, "Name=\"%s\"", name);
  const char *p = strstr(xml, key);
  if (!p || !(p = strchr(p, '>'))) return NULL;
  const size_t cap = strlen(p);
  unsigned char *raw = malloc(cap + 8);
  const size_t n = b64_decode(p + 1, raw, cap);
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
#endif
