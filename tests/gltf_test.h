/* Shared by the glTF tests: small files written by the test itself, JSON
 * with the binary data as a base64 data URI, or GLB, in a scratch folder
 * made by gltf_test_setup (a cmocka group setup) and removed by
 * gltf_test_teardown. Failures are cmocka assertions. */
#ifndef LIMN_GLTF_TEST_H
#define LIMN_GLTF_TEST_H

#include <stddef.h>

/* The scratch folder. */
extern char gltf_test_dir[64];
int gltf_test_setup(void **state);
int gltf_test_teardown(void **state);

/* Binary data of a file under construction; each piece 4-byte aligned. */
typedef struct blob {
  unsigned char data[8192];
  size_t len;
} blob;
/* Appends n bytes; returns where they start. */
size_t blob_add(blob *b, const void *p, size_t n);

/* The path of `name` in the scratch folder (8 kept at a time). */
const char *path_of(const char *name);
const char *write_bytes(const char *name, const void *data, size_t len);
/* Writes `json` with its one "%s" replaced by `b` as a data URI, and
 * "%zu" (if any, after it) by the blob's length. */
const char *write_gltf(const char *name, const char *json, const blob *b);
/* GLB bytes of `json` (its buffer 0 without a uri) and `b` as the BIN chunk. */
size_t make_glb(const char *json, const blob *b, unsigned char *out, size_t cap);
/* One to three random edits of the GLB's len bytes, whose JSON ends at
 * json_end: a bit flipped, a byte replaced, the end cut off, or a digit of
 * the JSON changed (still JSON, other indices and sizes). Returns the new
 * length. Deterministic: failures reproduce. */
size_t mutate_glb(unsigned char *glb, size_t len, size_t json_end);
/* Loads `iters` mutants (mutate_glb) of the count seed GLBs, mutant i of
 * seed i % count, whose JSON ends at json_ends: each loads and passes
 * `check`, or is refused by a message naming its path. LIMN_GLTF_MUTATIONS=N
 * runs N instead (a longer soak, as under ASan). Fails unless some mutants
 * loaded and some did not (the loop explored both sides). */
struct lm_scene;
void gltf_mutation_soak(unsigned char *const *seeds, const size_t *lens, const size_t *json_ends, int count,
                        int iters, void (*check)(struct lm_scene *s));

#endif
