/* anim: glTF animation evaluated at a time (node transforms, morph weights),
 * skinned and morphed vertices on the CPU. */
#include "scene/scene_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lm_scene_mesh_free_deform(lm_scene_mesh *m) {
  free(m->rest);
  free(m->prev_positions);
  free(m->target_positions);
  free(m->target_normals);
  free(m->default_weights);
  free(m->joints);
  free(m->joint_weights);
}

void lm_scene_free_animations(lm_scene *s) {
  for (int a = 0; a < s->animation_count; a++) {
    for (int c = 0; c < s->animations[a].channel_count; c++) {
      free(s->animations[a].channels[c].times);
      free(s->animations[a].channels[c].values);
    }
    free(s->animations[a].channels);
  }
  free(s->animations);
  for (int k = 0; k < s->skin_count; k++) {
    free(s->skins[k].joints);
    free(s->skins[k].inverse_bind);
  }
  free(s->skins);
}

void lm_scene_shift_animation_nodes(lm_scene *s, int from, int by) {
  for (int a = 0; a < s->animation_count; a++)
    for (int c = 0; c < s->animations[a].channel_count; c++)
      if (s->animations[a].channels[c].node >= from) s->animations[a].channels[c].node += by;
  for (int k = 0; k < s->skin_count; k++)
    for (int j = 0; j < s->skins[k].joint_count; j++)
      if (s->skins[k].joints[j] >= from) s->skins[k].joints[j] += by;
}

bool lm_scene_animated(const lm_scene *s) { return s->animation_count > 0; }

int lm_scene_find_animation(const lm_scene *s, const char *spec, lm_error *err) {
  if (!strcmp(spec, "all")) return LM_ANIM_ALL;
  for (int a = 0; a < s->animation_count; a++)
    if (!strcmp(s->animations[a].name, spec)) return a;
  char *end;
  long i = strtol(spec, &end, 10);
  if (*spec && !*end && i >= 0 && i < s->animation_count) return (int)i;
  char list[512] = "";
  for (int a = 0; a < s->animation_count && strlen(list) < sizeof list - LM_NAME_MAX - 8; a++)
    snprintf(list + strlen(list), sizeof list - strlen(list), "%s%d '%s'", a ? ", " : "", a, s->animations[a].name);
  lm_error_set(err, "scene '%s' has no animation '%s' (it has %s; or 'all')", s->name, spec,
               s->animation_count ? list : "none");
  return -3;
}

void lm_scene_animation_range(const lm_scene *s, int anim, float *start, float *end) {
  *start = *end = 0;
  bool any = false;
  for (int a = 0; a < s->animation_count; a++) {
    if (anim != LM_ANIM_ALL && anim != a) continue;
    if (!any || s->animations[a].start < *start) *start = s->animations[a].start;
    if (!any || s->animations[a].end > *end) *end = s->animations[a].end;
    any = true;
  }
}

/* Stub until the evaluation lands: records the time only. */
void lm_scene_set_time(lm_scene *s, int anim, double seconds) {
  s->animation = anim;
  s->time = seconds;
}
