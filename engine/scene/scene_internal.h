/* Helpers shared by the scene module's sources, not part of its API. */
#ifndef LIMN_SCENE_INTERNAL_H
#define LIMN_SCENE_INTERNAL_H

#include "scene/scene.h"

/* Frees a mesh's deformation data (rest pose, morph targets, skin weights). */
void lm_scene_mesh_free_deform(lm_scene_mesh *m);
/* Frees the scene's animations and skins. */
void lm_scene_free_animations(lm_scene *s);
/* Node indices at or above `from` moved up by `by` (lm_scene_add_root): the
 * animations' and skins' node references follow. */
void lm_scene_shift_animation_nodes(lm_scene *s, int from, int by);

#endif
