/* gfx: the only module that speaks OpenGL and EGL. A thin layer of handles
 * over GL 4.5 core: context, textures, framebuffers, programs with reflection,
 * meshes, timers and readback. Callers never see a GL name. */
#ifndef LIMN_GFX_H
#define LIMN_GFX_H

#include "core/core.h"

/* ---- context ----------------------------------------------------------- */
typedef struct lm_context_desc {
  /* "auto" (default: EGL device platform with a hardware device, else Mesa's
   * surfaceless platform), "device" or "surfaceless". */
  const char *platform;
  bool debug; /* GL debug output to the log */
} lm_context_desc;

/* A headless OpenGL 4.5 core context, current on this thread. */
bool lm_context_create_headless(const lm_context_desc *desc, lm_error *err);
/* For a context somebody else made current (a GLFW window): load and check GL. */
bool lm_context_adopt_current(lm_error *err);
/* Releases the headless context whole: current none, the context destroyed,
 * the display terminated (which stops the driver's threads) and the
 * thread's EGL state released; the next create starts afresh. */
void lm_context_destroy(void);
/* Keeps the Mesa drivers loaded so far (in a "dri" folder) mapped until the
 * process ends. Called before a display closes: a driver keeps an allocation
 * in a static of its own, which LeakSanitizer can only see as reachable while
 * the driver is mapped (unloaded, it reports a leak in an unknown module). */
void lm_keep_drivers_loaded(void);
const char *lm_gl_renderer(void);
const char *lm_gl_version(void);
const char *lm_context_platform(void); /* "egl-device", "egl-surfaceless", "window" */

/* ---- formats ----------------------------------------------------------- */
typedef enum lm_format {
  LM_FORMAT_NONE,
  LM_FORMAT_RGBA8,
  LM_FORMAT_RGBA16F,
  LM_FORMAT_RGBA32F,
  LM_FORMAT_R16F,
  LM_FORMAT_R32F,
  LM_FORMAT_RG16F,
  LM_FORMAT_RG32F,
  LM_FORMAT_DEPTH32F,
  LM_FORMAT_COUNT
} lm_format;
const char *lm_format_name(lm_format f);
lm_format lm_format_parse(const char *name); /* LM_FORMAT_NONE when unknown */
bool lm_format_is_depth(lm_format f);
int lm_format_bytes(lm_format f); /* bytes per texel */
/* Every format name, comma separated, for error messages. */
const char *lm_format_list(void);

/* ---- textures ---------------------------------------------------------- */
typedef struct lm_texture { uint32_t id; } lm_texture;
typedef struct lm_texture_desc {
  lm_format format;
  int width, height;
  bool mips;
} lm_texture_desc;
/* Refuses sizes over the GL limit with a message naming `label` and the size. */
bool lm_texture_create(lm_texture *tex, const lm_texture_desc *desc, const char *label, lm_error *err);
/* An image texture (a material's): RGBA8 texels, rows top first, stored as
 * GL_SRGB8_ALPHA8 when `srgb` (sampling returns linear values) else RGBA8;
 * mipmapped, trilinear, repeating. Refuses sizes over the GL limit. */
bool lm_texture_upload_rgba8(lm_texture *tex, int width, int height, const unsigned char *rgba, bool srgb,
                             const char *label, lm_error *err);
void lm_texture_destroy(lm_texture *tex);
void lm_texture_generate_mips(lm_texture tex);
void lm_texture_clear(lm_texture tex); /* zero every texel of level 0 */
/* Sets the rectangle x, y, width, height of level 0 to value (a depth
 * format's texels to value[0]), whatever framebuffer is bound. */
void lm_texture_clear_rect(lm_texture tex, lm_format format, int x, int y, int width, int height,
                           const float value[4]);
int lm_texture_max_size(void);

/* ---- framebuffers and passes ------------------------------------------ */
#define LM_MAX_COLOR_OUTPUTS 8
typedef struct lm_attachments {
  lm_texture color[LM_MAX_COLOR_OUTPUTS];
  int color_count;
  lm_texture depth; /* id 0: none */
  int width, height;
} lm_attachments;
/* Binds (a cached) framebuffer for these attachments and sets the viewport. */
bool lm_attachments_bind(const lm_attachments *att, lm_error *err);
void lm_clear(int color_count, const float rgba[4], bool clear_depth, float depth);
void lm_draw_fullscreen(void);
/* The same over what the outputs hold, the fragment's colour premultiplied by
 * its alpha (colour + (1 - alpha) * output; blending on for this draw only). */
void lm_draw_fullscreen_over(void);
/* Draws `count` points from no vertex data (the vertex shader numbers them by
 * gl_VertexID), each one pixel, added to what the outputs hold (additive
 * blending, on for this draw only). */
void lm_draw_points(int count);
void lm_set_viewport(int x, int y, int width, int height);
/* Draws (and clears) only within the rectangle, or everywhere when off. */
void lm_set_scissor(bool on, int x, int y, int width, int height);
/* Uploads a shader storage block to `binding` (grows its buffer as needed). */
void lm_storage_upload(int binding, const void *data, size_t bytes);
/* Uploads the first `block` bytes of data (its `bytes`, zeros after them) to
 * a uniform block of `block` bytes at uniform binding `binding` (1 .. 7; 0 is
 * the frame's). */
void lm_uniform_upload(int binding, const void *data, size_t bytes, size_t block);
/* Depth test and back-face culling for scene passes; off for full-screen
 * ones. Camera views test reversed depth (near 1, far 0). Shadow casters
 * draw both faces (a light inside a closed mesh sees its back faces; a
 * front-lit light's tiles then cull them: lm_set_cull_back_faces) and
 * clamp depth (casters before the near plane count). */
void lm_set_scene_state(bool on, bool shadow_caster);
/* Which winding faces front in the draws that follow: clockwise for a mirrored node (its world
 * matrix's determinant negative), counter-clockwise (GL's default) else. */
void lm_set_front_face_clockwise(bool clockwise);
/* Back faces culled (true) or drawn in the scene draws that follow: a shadow tile of a light that sees
 * no face from behind (lm_shadow_front_lit) draws its front faces alone, so that no texel where a closed
 * caster's front and back faces meet at its outline stores the back face by a tie of depth. */
void lm_set_cull_back_faces(bool on);
/* A blended scene pass (lm_pass_desc.blend): the output becomes the
 * fragment's first colour plus its second (index 1) times the output, per
 * channel; depth tested, not written. Off: no blending, depth written. */
void lm_set_blend_state(bool on);
/* Shadow casters of a pass with a transmittance output (of index `transmit`
 * among `count`): opaque ones write every output but it (translucent off);
 * blended ones write it alone, multiplying its rgb by theirs and keeping the
 * least alpha (their depth), depth tested, not written (translucent on).
 * lm_set_caster_layer(-1, count, false) gives every output back. */
void lm_set_caster_layer(int transmit, int count, bool translucent);
/* The depth a scene pass clears to: far, so 0 for a camera, 1 for a shadow tile. */
float lm_scene_clear_depth(bool shadow_caster);
/* Framebuffers cache by attachment set; drop entries that name this texture. */
void lm_framebuffers_forget(lm_texture tex);

/* ---- shader sources (pure text, no GL; testable on its own) ------------ */
/* A shader file with its #includes expanded. Each file gets a source-string
 * number used in #line directives, so compiler logs map back to file:line. */
typedef struct lm_shader_source {
  lm_buf text;
  char **files; /* files[i] is source string i */
  int file_count, file_cap;
} lm_shader_source;
/* `defines` is "NAME=VALUE;NAME2" (may be NULL). Include paths resolve
 * against the including file's directory, then `include_dir`. */
bool lm_shader_source_load(lm_shader_source *src, const char *path, const char *include_dir,
                           const char *defines, lm_error *err);
void lm_shader_source_free(lm_shader_source *src);
/* Rewrites a compiler log ("0:12(3): error ..." or "0(12) : error ...")
 * into "file:line: error ..." lines. */
void lm_shader_map_log(const lm_shader_source *src, const char *log, lm_buf *out);

/* ---- programs ---------------------------------------------------------- */
typedef enum lm_uniform_type {
  LM_UNIFORM_FLOAT, LM_UNIFORM_VEC2, LM_UNIFORM_VEC3, LM_UNIFORM_VEC4,
  LM_UNIFORM_INT, LM_UNIFORM_IVEC2, LM_UNIFORM_IVEC3, LM_UNIFORM_IVEC4,
  LM_UNIFORM_BOOL, LM_UNIFORM_MAT3, LM_UNIFORM_MAT4,
  LM_UNIFORM_SAMPLER, LM_UNIFORM_SAMPLER_SHADOW, LM_UNIFORM_OTHER
} lm_uniform_type;
const char *lm_uniform_type_name(lm_uniform_type t);
int lm_uniform_type_components(lm_uniform_type t); /* 1..16, 0 for samplers */

typedef struct lm_uniform {
  char name[64];
  lm_uniform_type type;
  int location; /* -1: declared in the source but not active */
  int unit;     /* texture unit, for samplers */
  union {       /* its value after linking (the GLSL initializer, else 0) */
    float f[16];
    int i[4];
  } initial;
} lm_uniform;

typedef struct lm_program {
  uint32_t id;
  char label[256]; /* "shaders/direct.frag [DEFINE=1]" */
  lm_uniform *uniforms; /* every uniform declared in the sources */
  int uniform_count, uniform_cap;
  int output_count; /* fragment outputs */
} lm_program;

/* Compiles and links (cached by files and defines). Paths are relative to
 * the shader directory. Errors name the original file:line. */
lm_program *lm_program_get(const char *vert, const char *frag, const char *defines, lm_error *err);
const lm_uniform *lm_program_uniform(const lm_program *p, const char *name);
void lm_program_use(const lm_program *p);
void lm_program_set(const lm_program *p, const lm_uniform *u, const float *values);
void lm_program_set_int(const lm_program *p, const lm_uniform *u, const int *values);
void lm_program_bind_texture(const lm_uniform *u, lm_texture tex);
/* Every value uniform back to its initial value: a cached program serves many
 * passes, and one pass's parameters must not leak into the next. */
void lm_program_reset(const lm_program *p);
/* Forget every compiled program (shader files changed). */
void lm_programs_clear(void);
/* Shader files changed, keeping what runs: each cached program is rebuilt on
 * its next use; when that fails the old program stays in use and
 * lm_programs_error says why (file:line) until a later rebuild succeeds. */
void lm_programs_invalidate(void);
/* How many times lm_programs_invalidate ran: a change means the shaders may draw otherwise. */
unsigned lm_programs_generation(void);
/* The first failed rebuild's message since the last invalidation, or NULL. */
const char *lm_programs_error(void);
int lm_program_count(void);
/* The cached programs whose defines name `define` (NULL: all), e.g. the
 * lighting passes' light-set variants (LIGHT_SET); *build_ms (may be NULL)
 * gets the wall milliseconds their compiles and links took (CLOCK_MONOTONIC;
 * a driver may finish compiling at the first draw, which is not counted). */
int lm_programs_stats(const char *define, double *build_ms);
/* The directory shader paths are relative to: <root>/shaders. */
const char *lm_shader_dir(void);

/* ---- per-frame engine data (std140 block LimnFrame, binding 0) --------- */
/* 16-byte aligned wherever it lives: its matrices are read as cglm's mat4,
 * whose SIMD loads need that. */
typedef struct lm_frame_data {
  LM_ALIGNED(16) float view[16];
  float proj[16], view_proj[16], inv_view[16];
  float camera_pos[4];
  float frustum_o[4], frustum_u[4], frustum_v[4]; /* rays to the far plane */
  float clip[4];        /* near, far, 1/far, tan(fov_y/2) */
  float output_size[4]; /* w, h, 1/w, 1/h */
  float time[4];        /* seconds, frame index */
  int32_t counts[4];    /* lights */
  float prev_view_proj[16]; /* the previous frame's (this frame's on the first) */
  float exposure[4];  /* pre-exposure E (lights, sky, ambient, emission arrive times it), 1/E,
                         E over the last frame's (what a history kept since is rescaled by), the
                         exposure meter's last key times E (1: none) */
} lm_frame_data;
typedef struct lm_light_data {
  float position[4];  /* xyz, w = type: 0 point, 1 spot, 2 directional */
  float direction[4]; /* xyz (unit, from the light), w = cos(outer cone) */
  float color[4];     /* rgb * power, w = radius (point/spot attenuation) */
  float params[4];    /* x = cos(inner cone), y = falloff (lm_falloff) */
} lm_light_data;
void lm_frame_upload(const lm_frame_data *frame, const lm_light_data *lights, int light_count);

/* ---- meshes ------------------------------------------------------------ */
/* A mesh's vertices on the GPU, quantized as glTF's KHR_mesh_quantization
 * allows (with llvmpipe the GPU's copy lives in the process: about half the
 * floats' memory): positions unorm16 over the mesh's bounding cube,
 * position = origin + extent * q (the instance matrices apply it:
 * lm_mesh_dequantize), or floats for a mesh that deforms (its bounds move
 * each frame); normals octahedral, snorm16 x 2 (attribute 1 is a vec2:
 * common.glsl's oct_decode); uvs unorm16 when every one lies in [0, 1], else
 * floats; 16-bit indices below 65536 vertices. */
typedef struct lm_mesh {
  uint32_t vao, vbo, tbo, ibo, pbo;
  int index_count;
  bool prev;
  bool float_positions, float_uvs, short_indices;
  float origin[3], extent; /* quantized positions' box: its lowest corner and side */
} lm_mesh;
/* Interleaved position(3) normal(3) uv(2) floats, stored as above (attributes
 * 0, 1, 2); `deforms`: positions stay floats (lm_mesh_update_vertices).
 * tangents (may be NULL): xyz and handedness w a vertex, attribute 10; without,
 * the attribute reads (0, 0, 0, 1), which shaders take for "none". */
void lm_mesh_create(lm_mesh *m, const float *vertices, int vertex_count, const float *tangents,
                    const uint32_t *indices, int index_count, bool deforms);
void lm_mesh_destroy(lm_mesh *m);
/* Reads back the first vertex_count vertices and index_count indices given to lm_mesh_create
 * (a scene that freed its own copy after the upload and needs it again: lm_scene_restore_geometry),
 * as floats again: the quantized values the GPU draws, each within LM_MESH_POSITION_ERROR times
 * the extent, LM_MESH_NORMAL_ERROR radians and LM_MESH_UV_ERROR of what was given. */
void lm_mesh_read(const lm_mesh *m, float *vertices, int vertex_count, uint32_t *indices, int index_count);
#define LM_MESH_POSITION_ERROR (0.5f / 65535 + 1e-6f) /* rounding, and float arithmetic's */
#define LM_MESH_NORMAL_ERROR 1e-4f
#define LM_MESH_UV_ERROR (0.5f / 65535 + 1e-6f)
/* Multiplies a node's model matrix (column-major) by m's dequantization:
 * out = model * translate(origin) * scale(extent); model itself for float positions. */
void lm_mesh_dequantize(const lm_mesh *m, const float model[16], float out[16]);
/* Replaces the interleaved vertices (the same count as created): a deformed mesh's new pose
 * (one not created `deforms` keeps its quantized box: positions outside it are clamped). */
void lm_mesh_update_vertices(lm_mesh *m, const float *vertices, int vertex_count);
/* A deformed mesh's positions in the previous frame (xyz a vertex, the same
 * count as created), attribute 15 (in_prev_position, w 1) for velocities;
 * NULL: the mesh did not deform since, and attribute 15 reads (0, 0, 0, 0),
 * which shaders take for "the current position". */
void lm_mesh_set_prev_positions(lm_mesh *m, const float *positions, int vertex_count);
/* One instance of a drawn mesh: attributes 3-6 (mat4 instance_model, the
 * columns), 7-9 (mat3 instance_normal, the model matrix's inverse
 * transpose) and 11-14 (mat4 instance_prev_model, the node's model matrix
 * in the previous frame, for velocities), stepping once an instance. */
typedef struct lm_instance { float model[16]; float normal[9]; float prev_model[16]; } lm_instance;
/* Replaces the instances the next draws read (grows the buffer as needed). */
void lm_instances_upload(const lm_instance *instances, int count);
/* Draws indices first_index .. first_index + index_count - 1 of m (a range of
 * its index buffer: the whole mesh, or a simplified copy stored after it)
 * once for each of the uploaded instances first .. first + count - 1: one
 * draw call however many there are. */
void lm_mesh_draw_instances(const lm_mesh *m, int first_index, int index_count, int first, int count);
/* On a software rasterizer, draws flush after this many triangles of a frame (lm_frame_upload
 * starts one; lm_mesh_draw_instances counts). */
#define LM_FLUSH_TRIANGLES 16384

/* ---- timers ------------------------------------------------------------ */
/* LM_CLOCK_PROCESS: glFinish plus the process's CPU time (every thread's),
 * asked for alone: on a software rasterizer the rendering is this process's
 * threads' work, which other processes on a loaded machine disturb far less
 * than they do the wall clock; a GPU's work it does not count. */
typedef enum lm_clock { LM_CLOCK_AUTO, LM_CLOCK_GPU, LM_CLOCK_CPU, LM_CLOCK_PROCESS } lm_clock;
/* GPU queries unless the renderer is a software one whose queries are not
 * trustworthy (llvmpipe, softpipe): then glFinish plus CLOCK_MONOTONIC. */
lm_clock lm_clock_choose(lm_clock wanted);
const char *lm_clock_name(lm_clock c);
typedef struct lm_timer { lm_clock clock; uint32_t query; double start_ms, ms; } lm_timer;
void lm_timer_begin(lm_timer *t, lm_clock clock);
void lm_timer_end(lm_timer *t);
/* Milliseconds; waits for a GPU query's result. */
double lm_timer_read(lm_timer *t);
void lm_timer_destroy(lm_timer *t);
void lm_finish(void);
/* GPU memory in use, MiB, as the driver reports it (GL_NVX_gpu_memory_info:
 * dedicated memory less what is available, the whole GPU's); -1 when it
 * reports none (llvmpipe: textures and buffers are the process's memory). */
double lm_gpu_memory_used_mib(void);

/* ---- readback ---------------------------------------------------------- */
/* RGBA rows, top row first. `floats` selects float32 or uint8 output. */
void lm_texture_read(lm_texture tex, int width, int height, bool floats, void *out);
/* A read-back that does not stall: started after the passes that write the
 * texture (RGBA floats into a buffer, with a fence), collected later, by
 * then finished (a frame on), into rows bottom first as GL keeps them. */
typedef struct lm_readback {
  unsigned buffer;
  void *fence;
  int width, height;
} lm_readback;
void lm_readback_start(lm_readback *rb, lm_texture tex, int width, int height);
/* Copies the started read into out (width * height RGBA floats), waiting for
 * it if the GPU has not finished it; false (out untouched) if none was started. */
bool lm_readback_collect(lm_readback *rb, float *out);
void lm_readback_free(lm_readback *rb);

/* ---- uploads, copies and the window's framebuffer ---------------------- */
/* Replaces level 0 of an rgba8 texture with RGBA bytes, top row first. */
void lm_texture_upload(lm_texture tex, int width, int height, const uint8_t *rgba);
/* Replaces level 0 of a colour texture (any format) with RGBA floats, top row first. */
void lm_texture_upload_floats(lm_texture tex, int width, int height, const float *rgba);
/* Copies level 0 of src into dst (same format and size). */
void lm_texture_copy(lm_texture dst, lm_texture src, int width, int height);
/* Copies the rectangle x, y, width, height of src's level 0 to the same place in dst (same format). */
void lm_texture_copy_rect(lm_texture dst, lm_texture src, int x, int y, int width, int height);
/* Copies src's width x height texels at (sx, sy) to dst at (dx, dy). */
void lm_texture_copy_moved(lm_texture dst, int dx, int dy, lm_texture src, int sx, int sy, int width, int height);
/* Binds the window's (default) framebuffer and sets the viewport. */
void lm_screen_bind(int width, int height);
/* Copies the rectangle (x, y: from the bottom left) of src, a texture of the
 * window's size, to the same place in the window's back buffer, no shader (on
 * llvmpipe a copy of the pixels); the scissor test ends off and the window's
 * framebuffer bound. */
bool lm_screen_blit(lm_texture src, int x, int y, int width, int height, lm_error *err);
/* The default framebuffer's back buffer as RGB bytes, top row first. */
void lm_screen_read(int width, int height, uint8_t *rgb);

/* ---- object counts (leak checks) --------------------------------------- */
typedef struct lm_gfx_counts {
  int textures, framebuffers, programs; /* GL objects alive now */
} lm_gfx_counts;
lm_gfx_counts lm_gfx_stats(void);

/* ---- windows (GLFW) ---------------------------------------------------- */
/* A window with an OpenGL 4.5 core context, made current and adopted (one
 * window per process). Keys are named as on the keyboard: "A".."Z",
 * "0".."9", "F1".."F12", "Tab", "Escape", "Space", "PageUp", "PageDown",
 * "Home", "End", "Left", "Right", "Up", "Down", "Enter", "Backspace". */
typedef struct lm_window lm_window;
lm_window *lm_window_create(const char *title, int width, int height, lm_error *err);
void lm_window_destroy(lm_window *w);
bool lm_window_should_close(const lm_window *w);
void lm_window_poll(lm_window *w);
void lm_window_swap(lm_window *w);
/* The framebuffer's size in pixels: 0x0 while the window is minimized. */
void lm_window_size(lm_window *w, int *width, int *height);
void lm_window_resize(lm_window *w, int width, int height);
/* The next key pressed since the last call (its name); false when none. */
bool lm_window_next_key(lm_window *w, char *name, size_t cap);
bool lm_window_key_down(const lm_window *w, const char *name);
/* Cursor movement in pixels since the last call while the left button is held. */
void lm_window_mouse_drag(lm_window *w, double *dx, double *dy);
/* Where the cursor is, window pixels from the top left (outside: beyond the size). */
void lm_window_cursor(const lm_window *w, double *x, double *y);
/* The GLFWwindow, for a user interface library's GLFW backend (the viewer's panel). */
void *lm_window_handle(lm_window *w);

#endif
