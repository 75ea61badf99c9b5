/* Shared by the fuzz targets: a scratch folder made once per process, and
 * writing (parts of) an input into files there. */
#ifndef LIMN_FUZZ_FILES_H
#define LIMN_FUZZ_FILES_H

#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The scratch folder, made on the first call ("/tmp/limn-fuzz-NAME-XXXXXX"). */
static inline const char *fuzz_dir(const char *name) {
  static char dir[96];
  if (!dir[0]) {
    snprintf(dir, sizeof dir, "/tmp/limn-fuzz-%s-XXXXXX", name);
    if (!mkdtemp(dir)) abort();
  }
  return dir;
}

/* Writes n bytes to dir/file; returns the full path (valid until the next call). */
static inline const char *fuzz_write(const char *dir, const char *file, const void *data, size_t n) {
  static char path[160];
  snprintf(path, sizeof path, "%s/%s", dir, file);
  FILE *f = fopen(path, "wb");
  if (!f) abort();
  fwrite(data, 1, n, f);
  fclose(f);
  return path;
}

/* Splits an input at its first NUL: the first part's length, and the second part. */
static inline size_t fuzz_split(const unsigned char *data, size_t size, const unsigned char **rest, size_t *rest_len) {
  const unsigned char *nul = memchr(data, 0, size);
  size_t first = nul ? (size_t)(nul - data) : size;
  *rest = nul ? nul + 1 : data;
  *rest_len = nul ? size - first - 1 : 0;
  return first;
}

#endif
