/* Helpers shared by the scene module's sources, not part of its API. */
#ifndef LIMN_SCENE_INTERNAL_H
#define LIMN_SCENE_INTERNAL_H

/* The glTF bridge is C++ and uses these too. */
#ifdef __cplusplus
extern "C" {
#endif

#include "scene/scene.h"

/* Frees a mesh's deformation data (rest pose, morph targets, skin weights). */
void lm_scene_mesh_free_deform(lm_scene_mesh *m);
/* Frees the scene's animations and skins. */
void lm_scene_free_animations(lm_scene *s);
/* Node indices at or above `from` moved up by `by` (lm_scene_add_root): the
 * animations' and skins' node references follow. */
void lm_scene_shift_animation_nodes(lm_scene *s, int from, int by);
/* Column-major T * R * S (q: x y z w, unit) as glTF composes a node. */
void lm_scene_trs_matrix(const float t[3], const float q[4], const float s[3], float out[16]);
/* Poses the scene as lm_scene_set_time does, leaving prev_positions, the
 * scene's time and its animation alone: the loader's rest pose. */
void lm_scene_pose(lm_scene *s, int anim, double seconds);
/* Simplified copies (engine/scene/lod.c). lm_scene_simplify_mesh queues
 * mesh i's two chains for the worker threads (started at the first call)
 * and makes the GL buffers of the meshes done so far, waiting while too
 * many wait (each keeps its CPU copy); lm_scene_mesh_uploaded then ends
 * each one's upload (a mesh without copies too: scene.c calls it after its
 * buffers). lm_scene_finish_meshes waits for every one and stops
 * the threads; lm_scene_drop_meshes stops them, leaving what is not done
 * (a scene destroyed half-read). All on the GL context's thread. */
void lm_scene_simplify_mesh(lm_scene *s, int i);
void lm_scene_mesh_uploaded(lm_scene *s, int i);
/* A copy of `count` vertices (8 floats each) with each moved onto its first twin by position
 * (lm_weld_positions): corners a few ulps apart (a flat-shaded box's faces as exporters write them) could
 * quantize a step apart on the GPU (lm_mesh), a crack through which a shadow tile sees a face from behind,
 * and would be borders to the simplifier, which opened such boxes. What a static mesh's buffers and
 * caster copies are made of; its CPU vertices stay as read (loaders compare them: a shared mesh). */
float *lm_welded_vertices(const float *vertices, int count);
void lm_scene_finish_meshes(lm_scene *s);
void lm_scene_drop_meshes(lm_scene *s);
/* Cuts a static mesh's index ranges (the mesh whole, then its simplified
 * copies) into spatial chunks (m->chunks; engine/scene/chunks.c), reordering
 * the triangles of each range in `indices`, the buffer its GPU mesh is made
 * from. A deformed or small mesh gets none. */
void lm_scene_mesh_chunk(lm_scene_mesh *m, uint32_t *indices);

#ifdef __cplusplus
}
#endif
#endif
