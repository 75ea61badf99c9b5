/* Shared by graph.c (recording, compiling) and graph_exec.c (execution). */
#ifndef LIMN_GRAPH_INTERNAL_H
#define LIMN_GRAPH_INTERNAL_H

#include "graph/graph.h"

typedef struct graph_target {
  lm_target_desc desc; /* name owned: persistent ones by the heap, others by the arena */
  int width, height;
  bool used;           /* read or written by a pass that runs */
  int first, last;     /* live pass indices that touch it */
  int slot;
  bool alone;          /* lm_graph_target_info.alone */
  lm_texture texture;  /* persistent: owned; transient: borrowed from the pool */
  int alloc_w, alloc_h; /* persistent: the size its texture was made at */
} graph_target;

typedef struct graph_pass {
  lm_pass_desc desc; /* arrays and strings live in the frame arena */
  bool culled;
  lm_timer timer;
  double ms;
} graph_pass;

typedef struct pool_texture {
  lm_texture_desc desc;
  lm_texture texture;
  int idle_frames;
  bool taken;
} pool_texture;

typedef struct graph_slot {
  lm_texture_desc desc;
  int free_after; /* last pass index of its current holder */
} graph_slot;

/* Field by field: padding bytes make memcmp unreliable. */
static inline bool lm_texture_desc_equal(const lm_texture_desc *a, const lm_texture_desc *b) {
  return a->format == b->format && a->width == b->width && a->height == b->height && a->mips == b->mips;
}

struct lm_graph {
  int width, height;
  lm_arena arena;
  graph_target *targets;
  int target_count, target_cap, persistent_count;
  graph_pass *passes;
  int pass_count, pass_cap;
  int *outputs;
  int output_count, output_cap;
  graph_slot *slots;
  int slot_count, slot_cap;
  pool_texture *pool;
  int pool_count, pool_cap;
  lm_timer *timers; /* reused across frames, one per pass index */
  int timer_count, timer_cap;
  bool compiled;
  bool no_sharing; /* lm_graph_set_sharing(g, false) */
};

#endif
