/* Writing small glTF files for the tests (gltf_test.h). */
#define _DEFAULT_SOURCE /* mkdtemp */
#include "gltf_test.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/gltf.h"

char gltf_test_dir[64];

int gltf_test_setup(void **state) {
  (void)state;
  snprintf(gltf_test_dir, sizeof gltf_test_dir, "/tmp/limn_gltf_XXXXXX");
  return mkdtemp(gltf_test_dir) ? 0 : -1;
}

int gltf_test_teardown(void **state) {
  (void)state;
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", gltf_test_dir);
  return system(cmd) == 0 ? 0 : -1;
}

size_t blob_add(blob *b, const void *p, size_t n) {
  b->len = (b->len + 3) & ~(size_t)3;
  size_t at = b->len;
  assert_true(at + n <= sizeof b->data);
  memcpy(b->data + at, p, n);
  b->len += n;
  return at;
}

static char *base64(const unsigned char *p, size_t n) {
  static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  char *out = malloc(4 * ((n + 2) / 3) + 1), *o = out;
  for (size_t i = 0; i < n; i += 3) {
    uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) |
                 (i + 2 < n ? p[i + 2] : 0);
    *o++ = tab[v >> 18 & 63];
    *o++ = tab[v >> 12 & 63];
    *o++ = i + 1 < n ? tab[v >> 6 & 63] : '=';
    *o++ = i + 2 < n ? tab[v & 63] : '=';
  }
  *o = '\0';
  return out;
}

const char *path_of(const char *name) {
  static char path[8][256];
  static int next;
  char *p = path[next++ % 8];
  snprintf(p, 256, "%s/%s", gltf_test_dir, name);
  return p;
}

const char *write_bytes(const char *name, const void *data, size_t len) {
  const char *path = path_of(name);
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(data, 1, len, f), len);
  fclose(f);
  return path;
}

const char *write_gltf(const char *name, const char *json, const blob *b) {
  char *b64 = base64(b->data, b->len);
  size_t cap = strlen(json) + strlen(b64) + 128;
  char *text = malloc(cap), uri[64];
  snprintf(uri, sizeof uri, "data:application/octet-stream;base64,");
  char *full = malloc(strlen(uri) + strlen(b64) + 1);
  strcpy(full, uri), strcat(full, b64);
  snprintf(text, cap, json, full, b->len);
  const char *path = write_bytes(name, text, strlen(text));
  free(b64), free(full), free(text);
  return path;
}

size_t make_glb(const char *json, const blob *b, unsigned char *out, size_t cap) {
  size_t jlen = (strlen(json) + 3) & ~(size_t)3, blen = (b->len + 3) & ~(size_t)3;
  size_t total = 12 + 8 + jlen + 8 + blen;
  assert_true(total <= cap);
  memset(out, 0, total);
  uint32_t head[3] = {0x46546C67, 2, (uint32_t)total}, jhead[2] = {(uint32_t)jlen, 0x4E4F534A},
           bhead[2] = {(uint32_t)blen, 0x004E4942};
  memcpy(out, head, 12);
  memcpy(out + 12, jhead, 8);
  memset(out + 20, ' ', jlen);
  memcpy(out + 20, json, strlen(json));
  memcpy(out + 20 + jlen, bhead, 8);
  memcpy(out + 28 + jlen, b->data, b->len);
  return total;
}

static uint32_t rng_state = 12345;
static uint32_t rng(void) {
  rng_state = rng_state * 1664525u + 1013904223u;
  return rng_state >> 8;
}

size_t mutate_glb(unsigned char *glb, size_t len, size_t json_end) {
  int edits = 1 + (int)(rng() % 3);
  for (int e = 0; e < edits; e++) {
    uint32_t r = rng();
    size_t at = rng() % len;
    switch (r % 5) {
    case 0: glb[at] ^= (unsigned char)(1u << (rng() % 8)); break; /* flip a bit */
    case 1: glb[at] = (unsigned char)rng(); break;                 /* any byte */
    case 2: len = at + 1; break;                                   /* truncate */
    default: {
      size_t j = 20 + rng() % (json_end - 20);
      for (size_t k = 0; k < 64 && j + k < json_end; k++)
        if (glb[j + k] >= '0' && glb[j + k] <= '9') {
          glb[j + k] = (unsigned char)('0' + rng() % 10);
          break;
        }
    }
    }
  }
  return len;
}

void gltf_mutation_soak(unsigned char *const *seeds, const size_t *lens, const size_t *json_ends, int count,
                        int iters, void (*check)(struct lm_scene *s)) {
  const char *env = getenv("LIMN_GLTF_MUTATIONS");
  if (env && atoi(env) > 0) iters = atoi(env);
  size_t most = 0;
  for (int i = 0; i < count; i++) most = lens[i] > most ? lens[i] : most;
  unsigned char *mutant = malloc(most); /* mutate_glb only shortens */
  int loaded = 0;
  for (int iter = 0; iter < iters; iter++) {
    int seed = iter % count;
    memcpy(mutant, seeds[seed], lens[seed]);
    size_t len = mutate_glb(mutant, lens[seed], json_ends[seed]);
    lm_error err = {""};
    const char *path = write_bytes("mutant.glb", mutant, len);
    lm_scene *s = lm_scene_load_gltf(path, &err);
    if (s) {
      check(s);
      lm_scene_destroy(s);
      loaded++;
    } else if (!strstr(err.msg, path)) {
      fail_msg("iteration %d: message without the path: %s", iter, err.msg);
    }
  }
  free(mutant);
  print_message("mutations: %d of %d still loaded\n", loaded, iters);
  assert_true(loaded > 0 && loaded < iters);
}
