/* scene: the scene graph (nodes with local/world transforms), meshes,
 * materials, lights and cameras, and the built-in scenes. */
#ifndef LIMN_SCENE_H
#define LIMN_SCENE_H

#include "gfx/gfx.h"

#define LM_NAME_MAX 64

/* A material's textures beyond the base colour, for the "pbr" technique. */
typedef enum lm_texture_slot {
  LM_TEX_BASE_COLOR,         /* sRGB rgb, alpha a */
  LM_TEX_METALLIC_ROUGHNESS, /* linear: roughness g, metallic b */
  LM_TEX_NORMAL,             /* linear, tangent space */
  LM_TEX_OCCLUSION,          /* linear r */
  LM_TEX_EMISSIVE,           /* sRGB */
  LM_TEX_SLOTS
} lm_texture_slot;

typedef enum lm_alpha_mode { LM_ALPHA_OPAQUE, LM_ALPHA_MASK, LM_ALPHA_BLEND } lm_alpha_mode;

/* Phong material of seed 000 plus the reflectance rho that ISR reads. */
typedef struct lm_material {
  char name[LM_NAME_MAX];
  float color[3];  /* diffuse albedo, linear (the pbr technique: the base colour) */
  float rho;       /* reflectance, the G-buffer's "radiation mask" */
  float ka, kd, ks, shininess;
  int base_color_texture; /* 1 + index into the scene's textures; 0: none */
  /* Mirror reflection in [0, 1] (seed 003 chapter 6): the share of the
   * reflected view added on top of the surface's own light, as POV-Ray's
   * finish { reflection r } does. 0: not reflective. */
  float reflectivity;
} lm_material;

/* glTF's metallic-roughness data of a material, beside it (lm_scene's
 * material_pbr, same index), for the "pbr" technique (shaders/pbr.frag). A
 * material without it (set false) gets it derived from its Phong values. */
typedef struct lm_material_pbr {
  bool set;
  float metallic, roughness, normal_scale, occlusion_strength;
  float emissive[3];   /* factor times KHR_materials_emissive_strength */
  float alpha;         /* base colour alpha */
  lm_alpha_mode alpha_mode;
  float alpha_cutoff;
  int textures[LM_TEX_SLOTS]; /* 1 + index; 0: none (the base colour's is the material's) */
  /* KHR_texture_transform per slot: uv' = (a b c; d e f) (u v 1); all zero: identity */
  float uv_transform[LM_TEX_SLOTS][6];
  /* Glass (KHR_materials_transmission, _ior, _volume), drawn by a blended
   * material's forward pass: the share of light that passes through, tinted
   * by the base colour; the index of refraction (Fresnel at normal
   * incidence ((ior - 1) / (ior + 1))^2; 0 in a material built without
   * one: 1.5); and the volume's absorption, attenuation_color left after
   * attenuation_distance (0: none) over a path of `thickness`. */
  float transmission, ior;
  float attenuation_color[3], attenuation_distance, thickness;
} lm_material_pbr;

/* Material `material`'s metallic-roughness data (m: its Phong values, with
 * any overrides): glTF's when set, else derived from m: metallic 1 - kd and
 * the roughness whose GGX lobe the exponent matches (alpha^2 = 2 /
 * (shininess + 2), the inverse of gltf.h's conversion). */
struct lm_scene;
lm_material_pbr lm_scene_material_pbr(const struct lm_scene *s, int material, const lm_material *m);

/* A material's image: RGBA8 texels (sRGB-encoded colour), rows top first. */
typedef struct lm_scene_texture {
  char name[LM_NAME_MAX];
  int width, height;
  unsigned char *rgba;
  bool linear;     /* data (metallic-roughness, normals, occlusion), not sRGB colour */
  lm_texture gpu;
} lm_scene_texture;

typedef enum lm_light_type { LM_LIGHT_POINT, LM_LIGHT_SPOT, LM_LIGHT_DIRECTIONAL } lm_light_type;

/* How point and spot lights fade with distance d. */
typedef enum lm_falloff {
  LM_FALLOFF_WINDOW,         /* saturate(1 - (d / radius)^2), seed 000 eq 16 (the default) */
  LM_FALLOFF_NONE,           /* constant: POV-Ray's default light */
  LM_FALLOFF_INVERSE_SQUARE, /* 1 / d^2: physical, and POV-Ray's fade_power 2 */
  LM_FALLOFF_RANGE,          /* KHR_lights_punctual: clamp(1 - (d / radius)^4, 0, 1) / d^2,
                                radius 0: no range (plain 1 / d^2); glTF's point and spot lights */
} lm_falloff;

/* The falloff at distance d >= 0 (shaders/lighting.glsl's light_falloff, its
 * GLSL twin: change both together). Finite for every d and radius. */
float lm_light_falloff(lm_falloff f, float d, float radius);

/* Position and direction come from the node (lights shine along the node's -Z). */
typedef struct lm_light {
  char name[LM_NAME_MAX];
  lm_light_type type;
  float color[3];
  float power;  /* engine units; glTF's candela and lux arrive scaled by LM_GLTF_EXPOSURE */
  float radius; /* the window's radius or the range; see lm_falloff */
  float inner_cone, outer_cone; /* spot half-angles, radians */
  lm_falloff falloff;
  bool casts_shadows;
  int node;
  /* Soft shadows (PCSS): the light's diameter in the scene's unit (point,
   * spot) or its angular diameter in radians (directional); 0: the default,
   * LM_LIGHT_SUN_SIZE, or LM_LIGHT_SIZE_SHARE of the shadow map's range. */
  float size;
} lm_light;
#define LM_LIGHT_SUN_SIZE 0.0093f  /* the sun's angular diameter, radians (0.53 degrees) */
#define LM_LIGHT_SIZE_SHARE 0.01f  /* a local light's default size as a share of its range */

/* The most lights a lighting shader evaluates unrolled, a variant compiled
 * for the scene's light set (light_set() in the pipeline API,
 * shaders/lighting.glsl); scenes with more take the general loop. */
#define LM_LIGHT_SET_MAX 16
/* A scene of at most LM_LIGHT_SET_MAX lights (a light-set variant, or the
 * general loop over them: light_set()) reads the lights and their shadow
 * records and views from uniform blocks (bindings 1, 2, 3) that copy the
 * first records of the storage blocks a scene of more lights reads: llvmpipe
 * reads a storage buffer in a fragment shader lane by lane (a loop that
 * checks and loads each lane's address, even one all lanes share), a uniform
 * block at an index all lanes share once, at others in one gather. At most 6
 * shadow views a light (a cube; 4 cascades) and as many RSM views after them
 * (lm_shadow_plan.view_data), LM_LIGHT_SET_VIEWS in all. */
#define LM_LIGHT_SET_VIEWS (LM_LIGHT_SET_MAX * 12)

/* Distance beyond which a point or spot light adds nothing (the window's or
 * range's radius); INFINITY for directional lights and unbounded falloffs. */
float lm_light_reach(const lm_light *l);

/* Looks along the node's -Z with +Y up, as in glTF. */
typedef struct lm_camera {
  char name[LM_NAME_MAX];
  float fov_y; /* radians, vertical */
  float znear, zfar;
  int node;
  float aspect; /* glTF's aspectRatio (width / height; 0: none), kept for export-gltf: the
                   projection keeps fov_y and takes the output's aspect (lm_scene_frame_data) */
  float ortho[2]; /* glTF orthographic xmag, ymag; 0, 0: perspective. Kept so that a
                     file's camera indices hold, refused by lm_scene_camera_check. */
} lm_camera;

/* A simplified copy of a mesh (lm_scene_mesh.casters, .lods). */
#define LM_LOD_LEVELS 5
typedef struct lm_mesh_lod {
  int first, count; /* its indices in the mesh's GPU index buffer */
  float error;      /* how far it may lie from the mesh, local units */
} lm_mesh_lod;

/* A spatial cluster of a large static mesh's triangles (engine/scene/chunks.c):
 * a run of one of its index ranges (the mesh whole, or a simplified copy),
 * with the bounds of its vertices, so that a draw leaves out the chunks
 * wholly outside its view. In a mesh of at least LM_CHUNK_MIN_TRIANGLES, a
 * range of at least 2 * LM_CHUNK_TRIANGLES triangles is cut into runs of
 * LM_CHUNK_TRIANGLES to 2 * LM_CHUNK_TRIANGLES along meshoptimizer's
 * space-filling curve (its triangles reordered in the GPU index buffer: the
 * same triangles, so the same image). Smaller meshes are objects a view
 * keeps or leaves whole (the big scene's spheres, 3840 triangles), and their
 * instances stay one draw. On outdoor.glb's terrain (64800 triangles) seen
 * from its `ground` view, chunks of 2048 / 1024 / 512 leave out 16% / 20% /
 * 23% of the camera's triangles and 30% / 37% / 42% of the shadow tiles'.
 * Small chunks pay most in a moving camera's scrolled cascade strips, a few
 * texels wide across a tile: walking on outdoor (`limn bench --motion --walk
 * 0.0075`, 640x480) they drew 61.2k / 47.5k / 40.8k shadow triangles a frame
 * with chunks of 512 / 256 / 128 (docs/benchmarks.md). */
#define LM_CHUNK_TRIANGLES 128
#define LM_CHUNK_MIN_TRIANGLES 8192
typedef struct lm_mesh_chunk {
  int first, count;   /* its indices in the mesh's GPU index buffer */
  float bounds[2][3]; /* min, max of its finite positions, local space */
} lm_mesh_chunk;
typedef struct lm_chunk_span { int first, count; } lm_chunk_span; /* chunks[first .. first + count) of a mesh */

typedef struct lm_scene_mesh {
  char name[LM_NAME_MAX];
  float *vertices; /* position(3) normal(3) uv(2); a deformed mesh's: its pose at the scene's time */
  float *tangents; /* xyz, handedness w (glTF TANGENT) a vertex; NULL: none (pbr.frag derives a frame) */
  int vertex_count;
  uint32_t *indices;
  int index_count;
  float bounds[2][3]; /* min, max of the finite positions, local space */
  lm_mesh gpu;
  /* Deformation (glTF morph targets and skins), evaluated on the CPU by
   * lm_scene_set_time into `vertices` from `rest`; NULL / 0 when none. A
   * deformed mesh belongs to one node (the loader gives each skinned or
   * morphed node its own copy), so its vertices are that node's pose. */
  float *rest;             /* the undeformed vertices, 8 floats each as `vertices` */
  float *prev_positions;   /* xyz a vertex at the previous time lm_scene_set_time posed (velocities);
                              NULL until its first call, which makes it the pose itself */
  int target_count;        /* morph targets */
  float *target_positions; /* target_count * vertex_count * 3 deltas */
  float *target_normals;   /* the same, or NULL */
  float *default_weights;  /* target_count: the mesh's `weights` (0 when absent) */
  int influence_sets;      /* JOINTS_n / WEIGHTS_n pairs: 4 influences each */
  uint16_t *joints;        /* vertex_count * 4 * influence_sets (a vertex's sets together), indices into
                              the skin's joints */
  float *joint_weights;    /* the same layout, normalized to sum 1 a vertex */
  bool dirty;              /* vertices (or prev_positions) changed since the last upload (lm_scene_upload_deformed) */
  /* Simplified copies made at upload (meshoptimizer, on worker threads), each level
   * about a quarter of the last's triangles within LM_LOD_ERROR times 4^level
   * of the mesh's extent, stored after the mesh's own indices in its GPU
   * index buffer: `casters` over positions alone (shadow tiles), `lods` with
   * the seams of normals and uvs kept (the camera's passes; where the seams
   * leave no copy, over positions with each corner's vertex chosen by its
   * normal: engine/scene/lod.c corners_by_normal). A level's error
   * (local units, meshoptimizer's measure, every level made from the mesh)
   * says how far its surface lies from the mesh's (the mesh's vertices lie
   * within 3.5 times it: test_casters), and is no less than the finer
   * levels'. None (0
   * levels) for a deformed mesh, one of fewer than LM_LOD_MIN_TRIANGLES, and
   * no level that keeps over 3/4 of the last's triangles. */
  lm_mesh_lod casters[LM_LOD_LEVELS], lods[LM_LOD_LEVELS];
  int caster_levels, lod_levels;
  /* Copies made over positions where the mesh has uv seams: each corner took
   * one side's uv, so a textured material (an alpha-cut caster) cannot draw them. */
  bool casters_mix_uvs, lods_mix_uvs;
  bool simplifying; /* its copies are being made: its GL buffers come after (lm_scene_upload waits) */
  /* Spatial chunks made by lm_scene_upload (none for a deformed mesh: its
   * bounds move): the whole mesh's, then each copy's (a count of 0: drawn whole). */
  lm_mesh_chunk *chunks;
  int chunk_count;
  lm_chunk_span whole_chunks, caster_chunks[LM_LOD_LEVELS], lod_chunks[LM_LOD_LEVELS];
} lm_scene_mesh;
/* The first level's target error, a share of the mesh's extent: 1/16 of 1%, so that a mesh as large as a
 * terrain (160 m, outdoor.glb) has copies within a shadow texel of a near cascade (10 cm), while the
 * budgets of 1%, 4% and 16% of the extent serve meshes of a few metres as before. */
#define LM_LOD_ERROR 0.000625f
#define LM_LOD_MIN_TRIANGLES 32 /* meshes below this are always drawn whole (a tree's trunk, 40, is not) */

/* Whether `count` indices close: each directed edge between welded vertices (weld[i]: the vertex i is
 * welded to; NULL: each its own) met by its reverse, so no border and one winding. Triangles with two
 * corners welded together draw nothing and are passed over. */
bool lm_indices_closed(const uint32_t *indices, int count, const int *weld);
/* Welds `count` vertices (8 floats each, xyz first) by position: weld[i] is the first vertex whose
 * position rounds to i's at 1/65536 of the extent (the GPU's 16 bits: lm_mesh), so that copies of a
 * corner a few ulps apart (a flat-shaded box's faces, a sphere's seam) meet. */
void lm_weld_positions(const float *vertices, int count, int *weld);

typedef struct lm_node {
  char name[LM_NAME_MAX];
  int parent;            /* -1: root */
  float local[16];       /* column-major */
  float world[16];       /* by lm_scene_update */
  int mesh, material;    /* -1: none */
  /* The rest pose as glTF's T * R * S (what an animation channel replaces);
   * trs false: `local` is a matrix and no channel may target the node. */
  bool trs;
  float translation[3], rotation[4], scale[3]; /* rotation: x y z w, unit */
  int skin;              /* index into the scene's skins; -1: none */
  float *weights;        /* morph weights, its mesh's target_count; NULL: none */
} lm_node;

/* ---- time: glTF animation (engine/scene/anim.c) ------------------------ */
typedef enum lm_anim_path { LM_ANIM_TRANSLATION, LM_ANIM_ROTATION, LM_ANIM_SCALE, LM_ANIM_WEIGHTS } lm_anim_path;
typedef enum lm_anim_interp { LM_ANIM_STEP, LM_ANIM_LINEAR, LM_ANIM_CUBICSPLINE } lm_anim_interp;
typedef struct lm_anim_channel {
  int node;              /* the lm node it moves (for weights: the node whose mesh morphs) */
  lm_anim_path path;
  lm_anim_interp interp;
  int count;             /* keys */
  int width;             /* floats a value: 3 (translation, scale), 4 (rotation), target count (weights) */
  float *times;          /* count, finite, strictly increasing */
  float *values;         /* count * width; CUBICSPLINE: count * 3 * width (in-tangent, value, out-tangent) */
} lm_anim_channel;
typedef struct lm_animation {
  char name[LM_NAME_MAX];
  lm_anim_channel *channels;
  int channel_count;
  float start, end;      /* first and last key time over its channels */
} lm_animation;
/* glTF skin: joint j's matrix is inverse(world of the skinned node) x world
 * of joints[j] x inverse_bind[j]. */
#define LM_SKIN_MAX_JOINTS 256
typedef struct lm_skin {
  char name[LM_NAME_MAX];
  int *joints;           /* lm nodes */
  float *inverse_bind;   /* joint_count * 16, column-major (identity when the file has none) */
  int joint_count;
} lm_skin;
#define LM_ANIM_ALL (-1)  /* every animation of the scene at once */
#define LM_ANIM_NONE (-2) /* the rest pose */

typedef struct lm_scene {
  char name[LM_NAME_MAX];
  lm_node *nodes;
  int node_count, node_cap;
  lm_scene_mesh *meshes;
  int mesh_count, mesh_cap;
  lm_material *materials;
  lm_material_pbr *material_pbr; /* one per material (zero: none) */
  int material_count, material_cap;
  lm_light *lights;
  int light_count, light_cap;
  lm_camera *cameras;
  int camera_count, camera_cap;
  lm_scene_texture *textures;
  int texture_count, texture_cap;
  lm_animation *animations;
  int animation_count, animation_cap;
  lm_skin *skins;
  int skin_count, skin_cap;
  double time;           /* the seconds lm_scene_set_time last posed */
  int animation;         /* and its animation (LM_ANIM_NONE before any) */
  bool uploaded;
  /* Set before lm_scene_upload by an owner that reads no vertex on the CPU
   * (a renderer's, not an exporter's): the upload frees each undeformed
   * mesh's vertices and indices once they are on the GPU (vertices NULL),
   * so that the two copies are never whole together, and the textures'
   * pixels (rgba NULL); the tracer reads the geometry back
   * (lm_scene_restore_geometry). */
  bool gpu_only;
  struct lm_lod_work *lod_work; /* the threads making simplified copies, while a mesh waits for its own */
} lm_scene;

/* The animation `spec` names exactly: its name, its index (digits only: "0"),
 * or "all" (LM_ANIM_ALL). -3 with a message listing the scene's animations. */
int lm_scene_find_animation(const lm_scene *s, const char *spec, lm_error *err);
/* First and last key time of animation `anim` (LM_ANIM_ALL: over all); 0, 0 when none. */
void lm_scene_animation_range(const lm_scene *s, int anim, float *start, float *end);
/* Poses the scene at `seconds` of animation `anim` (LM_ANIM_ALL, or
 * LM_ANIM_NONE for the rest pose): node transforms and morph weights from
 * the channels (times before the first key hold the first value, after the
 * last the last), world transforms, then skinned and morphed vertices and
 * their bounds on the CPU (meshes marked dirty). The pose it replaces becomes
 * the previous one (mesh prev_positions), for velocities. Never produces a
 * non-finite value from finite keys. */
void lm_scene_set_time(lm_scene *s, int anim, double seconds);
/* True when the scene has any animation (and so any node that can move). */
bool lm_scene_animated(const lm_scene *s);

lm_scene *lm_scene_create(const char *name);
void lm_scene_destroy(lm_scene *s);
int lm_scene_add_material(lm_scene *s, const lm_material *m);
/* Copies the arrays. */
int lm_scene_add_mesh(lm_scene *s, const char *name, const float *vertices, int vertex_count,
                      const uint32_t *indices, int index_count);
/* A cube of half-size `half` about the origin as mesh `name`: 24 vertices,
 * outward normals per face, UVs 0..1 on each face (engine/scene/builtin.c). */
int lm_scene_add_cube(lm_scene *s, const char *name, float half);
/* Gives mesh `mesh` tangents (4 floats a vertex, copied), before the upload. */
void lm_scene_mesh_set_tangents(lm_scene *s, int mesh, const float *tangents);
int lm_scene_add_node(lm_scene *s, const char *name, int parent, const float local[16], int mesh,
                      int material);
int lm_scene_add_light(lm_scene *s, const lm_light *l);
/* Takes ownership of `rgba` (malloc'd). Returns the texture's index. */
int lm_scene_add_texture(lm_scene *s, const char *name, int width, int height, unsigned char *rgba);
/* True when a mesh node's material has a reflectivity above 0. */
bool lm_scene_reflective(const lm_scene *s);
/* Index of the material called `name`, or -1. */
int lm_scene_find_material(const lm_scene *s, const char *name);
/* Index of the first node called `name`, or -1. */
int lm_scene_find_node(const lm_scene *s, const char *name);
int lm_scene_add_camera(lm_scene *s, const lm_camera *c);
/* Puts a new node (index 0) above every root: all node indices, and the
 * lights' and cameras' nodes, move up by one. A scaled root is the same scene
 * in another unit (cameras under it see the same image: lm_scene_frame_data). */
int lm_scene_add_root(lm_scene *s, const char *name, const float local[16]);
/* World transforms from local ones (parents come before children). */
void lm_scene_update(lm_scene *s);
/* Moves a node (a camera the viewer flies) so its world transform becomes
 * `world`: its local transform is set against its parent's, then updated. */
void lm_scene_node_set_world(lm_scene *s, int node, const float world[16]);
/* The axis-aligned box holding the box lo..hi moved by the affine transform m
 * (column-major), one product a row rather than eight corners; out_lo and
 * out_hi must not be lo or hi. */
void lm_box_transform(const float m[16], const float lo[3], const float hi[3], float out_lo[3], float out_hi[3]);
/* World-space box of one mesh node; false for a node without a mesh, empty or not finite bounds. */
bool lm_scene_node_bounds(const lm_scene *s, int node, float lo[3], float hi[3]);
/* World-space box around every mesh node; false (and a unit box) when empty. */
bool lm_scene_bounds(const lm_scene *s, float min[3], float max[3]);
/* Adds a camera (and its node) called `name` that frames the scene's bounds:
 * 45 degrees vertical field of view, looking at the bounds' centre from +Z
 * and 20 degrees above, as near as every corner of the bounds allows with a
 * 5% margin at an output of width / height `aspect` (<= 0: any output at
 * least as wide as high). Near and far enclose the bounds. Returns the
 * camera's index. World transforms are updated. */
int lm_scene_add_framing_camera(lm_scene *s, const char *name, float aspect);
/* False, with a message naming the camera, when the passes cannot render
 * through camera `cam` as posed: an orthographic one (every pass rebuilds
 * positions from depth along rays from one eye, common.glsl's
 * position_from_depth), or one whose world transform an animation scales to
 * zero (no view inverts it). An index with no camera is the engine's default
 * one, which they can. */
bool lm_scene_camera_check(const lm_scene *s, int cam, lm_error *err);
/* Whether camera cam's world transform inverts into a view (no zero scale):
 * the loader refuses a file whose camera does not, lm_scene_camera_check a
 * pose in which it does not. */
bool lm_scene_camera_invertible(const lm_scene *s, int cam);

/* Reads a camera list (engine/scene/camlist.c: one view per line, "name
 * eye_x eye_y eye_z target_x target_y target_z fov_y_degrees [near far]",
 * '#' comments) and adds a camera per view. Returns the index of the first
 * camera added and the count in *count; -1 with "file:line: ..." and the
 * scene unchanged. Without near and far, far covers the whole scene. */
int lm_scene_add_camera_list(lm_scene *s, const char *path, int *count, lm_error *err);
/* The world transform of a camera at `eye` looking at `target` (-Z forward,
 * +Y up as glTF; straight up or down takes -Z for up; an eye at the target
 * looks down -Z), as camera lists, job paths and turntables place cameras. */
void lm_camera_look_at(const float eye[3], const float target[3], float world[16]);


/* The node's material, or the engine's default one (material -1 or out of range). */
const lm_material *lm_scene_node_material(const lm_scene *s, const lm_node *n);

/* A scene built in code: "cornell"; "cornell_pov" (the box lit only by
 * lights POV-Ray matches exactly, engine/scene/pov.h); "cornell_mirror"
 * (cornell_pov with a mirror for its left wall); "field" (open ground
 * under a sun, for cascaded shadows). NULL with a message listing the names. */
lm_scene *lm_scene_builtin(const char *name, lm_error *err);
const char *lm_scene_builtin_list(void);

/* Takes the materials and textures of `from` (the same scene file read
 * again after an artist changed it) for `s`, leaving geometry, lights and
 * cameras alone: the viewer's reload. Both must have the same nodes (count
 * and meshes), else a message and `s` unchanged. Textures are uploaded when
 * `s` was. `from` keeps its own copies. Shaders reload separately through
 * lm_programs_clear. */
bool lm_scene_reload_materials(lm_scene *s, const lm_scene *from, lm_error *err);

/* ---- rendering (needs a GL context) ------------------------------------ */
bool lm_scene_upload(lm_scene *s, lm_error *err);
/* Texture i, mesh i (with its simplified copies) to the GPU, as
 * lm_scene_upload does for every one; a gpu_only scene frees the CPU copy
 * (a mesh's unless it deforms). One already there: nothing to do. A mesh
 * with copies to make is queued for worker threads and goes to the GPU
 * (on this thread) at a later call or at lm_scene_upload, which waits for
 * every one. */
bool lm_scene_upload_texture(lm_scene *s, int i, lm_error *err);
void lm_scene_upload_mesh(lm_scene *s, int i);
/* Reads back from the GPU the vertices and indices a gpu_only upload freed
 * (the tracer's, when a technique with traced rays is loaded); needs the GL
 * context. Nothing to do when none were freed. */
void lm_scene_restore_geometry(lm_scene *s);
/* Uploads the vertices of the deformed meshes that lm_scene_set_time changed,
 * with their prev_positions (lm_mesh_set_prev_positions); a mesh that did not
 * change since the last call draws its current positions as the previous
 * ones (it stood still for a frame). Returns how many meshes changed. */
int lm_scene_upload_deformed(lm_scene *s);
/* Frame block for camera `cam` at an output of width x height. */
void lm_scene_frame_data(const lm_scene *s, int cam, int width, int height, lm_frame_data *out);
/* Fills up to `max` lights; returns how many. */
int lm_scene_light_data(const lm_scene *s, lm_light_data *out, int max);
/* lm_light_reach of the light packed in d: what light culling reads. */
float lm_light_data_reach(const lm_light_data *d);

/* Clustered light culling (engine/scene/lightgrid.c): the frustum cut into
 * screen tiles and exponential depth slices, each listing the lights whose
 * reach (and cone) touches it; lights of infinite reach and no cone (a
 * spot's, under 90 degrees, culls it at any reach) are listed once for all.
 * `data` is the LimnLightGrid storage block (shaders/common.glsl). */
typedef struct lm_light_grid {
  int tiles_x, tiles_y, slices, tile_px; /* tile_px 0: no culling, every light everywhere */
  float near, far, slice_scale;          /* slice = floor(log(z / near) * slice_scale) */
  int global;                            /* lights of infinite reach and no cone */
  long listed;                           /* entries of all cluster lists */
  uint32_t *data;
  size_t count, cap;                     /* words */
} lm_light_grid;
/* Fills g for frame f's camera and lights; cull false lists every light for
 * every pixel (the reference the culled result must match). */
void lm_light_grid_build(lm_light_grid *g, const lm_frame_data *f, const lm_light_data *lights, int n, bool cull);
/* The cluster of a pixel at (x, y) (output pixels from the bottom left) and
 * linear depth / far depth01; -1 outside the grid (it evaluates every light). */
int lm_light_grid_cluster(const lm_light_grid *g, float x, float y, float depth01);
/* How many lights a pixel of `cluster` evaluates, of light_count in the frame. */
int lm_light_grid_count(const lm_light_grid *g, int cluster, int light_count);
/* Does a pixel of `cluster` evaluate light i? */
bool lm_light_grid_has(const lm_light_grid *g, int cluster, int light);
void lm_light_grid_free(lm_light_grid *g);

/* A parameter override: material `material`'s parameter `name` ("color",
 * "rho", "ka", "kd", "ks", "shininess", "reflectivity") takes v[0 .. count) for one draw.
 * (The frame graph carries these as lm_pass_material_param; the renderer
 * copies them over, as scene and graph do not include each other.) */
typedef struct lm_material_param {
  const char *material, *name;
  int count;
  float v[4];
} lm_material_param;
/* Checks overrides against the scene: an unknown material or parameter, or
 * the wrong count of numbers, is a message naming it. */
bool lm_scene_check_params(const lm_scene *s, const lm_material_param *params, int count, lm_error *err);
/* Names of the parameters a material has, for messages. */
const char *lm_material_param_list(void);

/* alphaMode BLEND materials in a scene draw: left out (the G-buffer keeps the
 * opaque layer), drawn as shadow casters (with a transmit output: after the
 * opaque ones, into it alone, define ALPHA_BLEND; without, as opaque ones),
 * or drawn alone, back to front, one node a draw (the forward pass over the
 * lit image). */
typedef enum lm_blend_draw { LM_BLEND_SKIP, LM_BLEND_CAST, LM_BLEND_ONLY } lm_blend_draw;

typedef struct lm_scene_draw_desc {
  const lm_program *program; /* bound: the technique's program */
  /* The technique's program with `defines` added ("BASE_COLOR_TEXTURE" for a
   * textured material; for a technique that declares material_pbr also
   * MR_TEXTURE, NORMAL_TEXTURE, OCCLUSION_TEXTURE, EMISSIVE_TEXTURE, joined
   * by ';'), bound and ready; NULL with a message. NULL: every material
   * draws with `program` and without its textures. */
  const lm_program *(*variant)(void *ctx, const char *defines, lm_error *err);
  void *ctx;
  const float *view_proj; /* column-major: nodes wholly outside are culled; NULL: none are */
  bool pancake; /* an orthographic shadow tile: nodes before its near plane still cast, so stay */
  const lm_material_param *params; /* overrides (checked by lm_scene_check_params) */
  int param_count;
  /* Each node's world transform in the previous frame (16 floats a node,
   * node_count of them): lm_instance.prev_model, for velocities. NULL: the
   * current ones (nothing moved). */
  const float *prev_world;
  /* With `dynamic` (a flag a node) and `layer` 1, only the nodes not flagged
   * are drawn, with layer 2 only those flagged (a shadow tile's static layer,
   * and the moving casters drawn over it); layer 0 or dynamic NULL: all. */
  const bool *dynamic;
  int layer;
  /* A node whose mesh has simplified copies draws the coarsest whose error,
   * times the node's largest scale, is at most lod_texels texels of this
   * view (lod_view_proj, lod_size texels wide and high) where the node's
   * bounds come nearest its eye (the light's for a shadow tile: `casters`;
   * the camera's for camera passes, lod_camera: `lods`, which keep normals
   * and uvs, as an RSM view needs too; a textured material never draws copies
   * whose uvs are mixed, nor does a caster whose texture's alpha cuts its
   * shadow). NULL or lod_texels 0: every mesh whole. */
  const float *lod_view_proj;
  int lod_size[2];
  float lod_texels;
  bool lod_camera;
  lm_blend_draw blend; /* what becomes of alphaMode BLEND materials */
  const float *eye_view_proj; /* the camera's, whose clip w orders the nodes: LM_BLEND_ONLY farthest first,
                                 * the others nearest first within a run of one mesh (NULL: by index) */
  int transmit, outputs;      /* LM_BLEND_CAST: lm_pass_desc.transmit, of the pass's `outputs` */
} lm_scene_draw_desc;
typedef struct lm_scene_draw_stats {
  int drawn, culled; /* mesh nodes drawn, and left out by the frustum test */
  int calls;         /* draw calls: one for the nodes of a mesh and material in view */
  int kept;          /* views (shadow tiles) kept from the last frame instead of drawn */
  int in_place;      /* of those, the ones still in the pass's outputs: neither cleared nor copied */
  int layered;       /* views drawn again over their kept static layer: only their moving casters drawn */
  int scrolled;      /* views (cascades) whose last texels moved with them: only the strips they uncover drawn */
  long triangles;    /* triangles drawn */
  int simplified;    /* of drawn, nodes drawn with a simplified copy */
  int chunks_culled; /* chunks of drawn nodes' meshes left out by the frustum test (lm_mesh_chunk) */
} lm_scene_draw_stats;
/* Draws every mesh node whose bounds reach into the frustum, the nodes of one
 * mesh and material in one instanced draw (each node's matrices in the
 * instance attributes of lm_instance; a technique declaring the uniforms
 * model or normal_matrix is an error), setting the material uniforms (material_color, material_rho,
 * material_k, material_reflectivity; material_pbr, material_emissive,
 * material_alpha) and the textures with their transforms (base_color_tex,
 * base_color_xform, mr_tex, ...; material_glass, material_attenuation) and
 * BLEND materials as d->blend says. Adds to *stats (may be NULL). */
bool lm_scene_draw(const lm_scene *s, const lm_scene_draw_desc *d, lm_scene_draw_stats *stats, lm_error *err);
/* True when the world-space box lo..hi lies wholly outside one clip plane of view_proj. */
bool lm_box_outside_frustum(const float view_proj[16], const float lo[3], const float hi[3]);
/* Would lm_scene_draw with this view_proj and pancake cull mesh node `node`?
 * False for a node whose bounds are not finite (it is drawn). */
bool lm_scene_node_culled(const lm_scene *s, int node, const float view_proj[16], bool pancake);
/* Does a mesh node of the scene have an alphaMode BLEND material? */
bool lm_scene_has_blend(const lm_scene *s);
/* Uniforms a scene draw sets itself; scripts may not bind them. */
bool lm_scene_owns_uniform(const char *name);

#endif
