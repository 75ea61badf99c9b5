/* Textures, framebuffers, draws, the frame block, meshes, timers, readback. */
#include "gfx/gfx.h"

#include <epoxy/gl.h>
#include <math.h>
#include <meshoptimizer.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* ---- formats ----------------------------------------------------------- */
static const struct {
  const char *name;
  GLenum internal;
  int bytes;
} formats[LM_FORMAT_COUNT] = {
    [LM_FORMAT_RGBA8] = {"rgba8", GL_RGBA8, 4},
    [LM_FORMAT_RGBA16F] = {"rgba16f", GL_RGBA16F, 8},
    [LM_FORMAT_RGBA32F] = {"rgba32f", GL_RGBA32F, 16},
    [LM_FORMAT_R16F] = {"r16f", GL_R16F, 2},
    [LM_FORMAT_R32F] = {"r32f", GL_R32F, 4},
    [LM_FORMAT_RG16F] = {"rg16f", GL_RG16F, 4},
    [LM_FORMAT_RG32F] = {"rg32f", GL_RG32F, 8},
    [LM_FORMAT_DEPTH32F] = {"depth32f", GL_DEPTH_COMPONENT32F, 4},
};

const char *lm_format_name(lm_format f) {
  return f > LM_FORMAT_NONE && f < LM_FORMAT_COUNT ? formats[f].name : "none";
}

lm_format lm_format_parse(const char *name) {
  for (int f = 1; f < LM_FORMAT_COUNT; f++)
    if (!strcmp(formats[f].name, name)) return (lm_format)f;
  return LM_FORMAT_NONE;
}

bool lm_format_is_depth(lm_format f) { return f == LM_FORMAT_DEPTH32F; }
int lm_format_bytes(lm_format f) { return f > 0 && f < LM_FORMAT_COUNT ? formats[f].bytes : 0; }

const char *lm_format_list(void) {
  return "rgba8, rgba16f, rgba32f, r16f, r32f, rg16f, rg32f, depth32f";
}

/* ---- textures ---------------------------------------------------------- */
static int live_textures; /* for lm_gfx_stats */

int lm_texture_max_size(void) {
  GLint n = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &n);
  return n;
}

static int mip_levels(int w, int h) {
  int levels = 1;
  while ((w | h) > 1) w >>= 1, h >>= 1, levels++;
  return levels;
}

bool lm_texture_create(lm_texture *tex, const lm_texture_desc *d, const char *label, lm_error *err) {
  int max = lm_texture_max_size();
  if (d->width < 1 || d->height < 1 || d->width > max || d->height > max) {
    lm_error_set(err, "target '%s': size %dx%d is outside 1x1 .. %dx%d", label, d->width, d->height,
                 max, max);
    return false;
  }
  if (d->format <= LM_FORMAT_NONE || d->format >= LM_FORMAT_COUNT) {
    lm_error_set(err, "target '%s': no format", label);
    return false;
  }
  while (glGetError() != GL_NO_ERROR) {}
  GLuint id;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  glTextureStorage2D(id, d->mips ? mip_levels(d->width, d->height) : 1, formats[d->format].internal,
                     d->width, d->height);
  if (glGetError() == GL_OUT_OF_MEMORY) {
    glDeleteTextures(1, &id);
    lm_error_set(err, "target '%s': out of GPU memory for %dx%d %s (%.1f MiB)", label, d->width,
                 d->height, formats[d->format].name,
                 (double)d->width * d->height * formats[d->format].bytes / 1048576.0);
    return false;
  }
  GLenum min = d->mips ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR;
  if (lm_format_is_depth(d->format)) min = GL_NEAREST;
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, min);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, lm_format_is_depth(d->format) ? GL_NEAREST : GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (label) glObjectLabel(GL_TEXTURE, id, -1, label);
  tex->id = id;
  live_textures++;
  return true;
}

bool lm_texture_upload_rgba8(lm_texture *tex, int w, int h, const unsigned char *rgba, bool srgb,
                             const char *label, lm_error *err) {
  int max = lm_texture_max_size();
  if (w < 1 || h < 1 || w > max || h > max) {
    lm_error_set(err, "texture '%s': size %dx%d is outside 1x1 .. %dx%d", label, w, h, max, max);
    return false;
  }
  while (glGetError() != GL_NO_ERROR) {}
  GLuint id;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  glTextureStorage2D(id, mip_levels(w, h), srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, w, h);
  if (glGetError() == GL_OUT_OF_MEMORY) {
    glDeleteTextures(1, &id);
    lm_error_set(err, "texture '%s': out of GPU memory for %dx%d", label, w, h);
    return false;
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  /* Row 0 (the image's top) goes to t = 0: glTF's uv (0, 0) is the image's
   * top left, so its coordinates sample the upload as is. */
  glTextureSubImage2D(id, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
  glGenerateTextureMipmap(id);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_REPEAT);
  tex->id = id;
  return true;
}

void lm_texture_destroy(lm_texture *tex) {
  if (!tex->id) return;
  lm_framebuffers_forget(*tex);
  glDeleteTextures(1, &tex->id);
  tex->id = 0;
  live_textures--;
}

void lm_texture_generate_mips(lm_texture tex) { glGenerateTextureMipmap(tex.id); }

void lm_texture_clear(lm_texture tex) {
  GLint internal = 0;
  glGetTextureLevelParameteriv(tex.id, 0, GL_TEXTURE_INTERNAL_FORMAT, &internal);
  static const float zero[4] = {0, 0, 0, 0};
  glClearTexImage(tex.id, 0, internal == GL_DEPTH_COMPONENT32F ? GL_DEPTH_COMPONENT : GL_RGBA, GL_FLOAT,
                  zero);
}

/* A texture's clear, not a scissored glClear: llvmpipe clears a 512x512
 * rectangle of five targets (r32f, two rgba16f, rgba32f, depth32f) in 3 ms
 * so against 40-50 ms scissored (CPU clock around glFinish, a loaded 2-core
 * machine). A whole framebuffer's glClear stays faster in a frame: llvmpipe
 * folds it into the draws that follow. */
void lm_texture_clear_rect(lm_texture tex, lm_format format, int x, int y, int width, int height,
                           const float value[4]) {
  if (width <= 0 || height <= 0) return;
  glClearTexSubImage(tex.id, 0, x, y, 0, width, height, 1, lm_format_is_depth(format) ? GL_DEPTH_COMPONENT : GL_RGBA,
                     GL_FLOAT, value);
}

/* ---- framebuffers: cached by attachment set ---------------------------- */
typedef struct fbo_entry {
  lm_attachments att;
  GLuint fbo;
} fbo_entry;
static fbo_entry *fbos;
static int fbo_count, fbo_cap;

static bool same_attachments(const lm_attachments *a, const lm_attachments *b) {
  if (a->color_count != b->color_count || a->depth.id != b->depth.id) return false;
  for (int i = 0; i < a->color_count; i++)
    if (a->color[i].id != b->color[i].id) return false;
  return true;
}

/* The cached framebuffer of these attachments (made on first use); 0 when incomplete. */
static GLuint framebuffer_for(const lm_attachments *att, lm_error *err) {
  fbo_entry *e = NULL;
  for (int i = 0; i < fbo_count && !e; i++)
    if (same_attachments(&fbos[i].att, att)) e = &fbos[i];
  if (!e) {
    GLuint fbo;
    glCreateFramebuffers(1, &fbo);
    GLenum bufs[LM_MAX_COLOR_OUTPUTS];
    for (int i = 0; i < att->color_count; i++) {
      glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0 + i, att->color[i].id, 0);
      bufs[i] = GL_COLOR_ATTACHMENT0 + i;
    }
    if (att->depth.id) glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, att->depth.id, 0);
    glNamedFramebufferDrawBuffers(fbo, att->color_count, bufs);
    GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      glDeleteFramebuffers(1, &fbo);
      lm_error_set(err, "framebuffer incomplete (0x%x)", status);
      return 0;
    }
    e = LM_PUSH(fbos, fbo_count, fbo_cap);
    e->att = *att;
    e->fbo = fbo;
  }
  return e->fbo;
}

bool lm_attachments_bind(const lm_attachments *att, lm_error *err) {
  GLuint fbo = framebuffer_for(att, err);
  if (!fbo) return false;
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, att->width, att->height);
  return true;
}

void lm_framebuffers_forget(lm_texture tex) {
  for (int i = 0; i < fbo_count;) {
    bool uses = fbos[i].att.depth.id == tex.id;
    for (int c = 0; c < fbos[i].att.color_count; c++) uses |= fbos[i].att.color[c].id == tex.id;
    if (uses) {
      glDeleteFramebuffers(1, &fbos[i].fbo);
      fbos[i] = fbos[--fbo_count];
    } else {
      i++;
    }
  }
}

void lm_clear(int color_count, const float rgba[4], bool clear_depth, float depth) {
  for (int i = 0; i < color_count; i++) glClearBufferfv(GL_COLOR, i, rgba);
  if (clear_depth) {
    glDepthMask(GL_TRUE);
    glClearBufferfv(GL_DEPTH, 0, &depth);
  }
}

static GLuint empty_vao;
void lm_draw_fullscreen(void) {
  if (!empty_vao) glCreateVertexArrays(1, &empty_vao);
  glBindVertexArray(empty_vao);
  glDrawArrays(GL_TRIANGLES, 0, 3); /* one triangle covering the viewport */
}

void lm_draw_fullscreen_over(void) {
  glEnable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  lm_draw_fullscreen();
  glDisable(GL_BLEND);
}

void lm_draw_points(int count) {
  if (count <= 0) return;
  if (!empty_vao) glCreateVertexArrays(1, &empty_vao);
  glBindVertexArray(empty_vao);
  glEnable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_ONE);
  glPointSize(1.0f);
  glDrawArrays(GL_POINTS, 0, count);
  glDisable(GL_BLEND);
}

void lm_set_viewport(int x, int y, int width, int height) { glViewport(x, y, width, height); }

void lm_set_scissor(bool on, int x, int y, int width, int height) {
  if (!on) {
    glDisable(GL_SCISSOR_TEST);
    return;
  }
  glEnable(GL_SCISSOR_TEST);
  glScissor(x, y, width, height);
}

enum { STORAGE_BINDINGS = 8 };
static struct {
  GLuint buffer;
  size_t size;
} storage[STORAGE_BINDINGS];

void lm_storage_upload(int binding, const void *data, size_t bytes) {
  if (binding < 0 || binding >= STORAGE_BINDINGS) return;
  size_t copy = bytes;
  if (bytes < 16) bytes = 16; /* an empty binding is an error in some drivers */
  if (bytes > storage[binding].size) {
    if (storage[binding].buffer) glDeleteBuffers(1, &storage[binding].buffer);
    glCreateBuffers(1, &storage[binding].buffer);
    glNamedBufferData(storage[binding].buffer, (GLsizeiptr)bytes, NULL, GL_DYNAMIC_DRAW);
    storage[binding].size = bytes;
  }
  if (data && copy) glNamedBufferSubData(storage[binding].buffer, 0, (GLsizeiptr)copy, data);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)binding, storage[binding].buffer);
}

static struct {
  GLuint buffer;
  size_t size;
} uniform_blocks[STORAGE_BINDINGS];

void lm_uniform_upload(int binding, const void *data, size_t bytes, size_t block) {
  if (binding < 1 || binding >= STORAGE_BINDINGS || block == 0) return;
  if (block != uniform_blocks[binding].size) {
    if (uniform_blocks[binding].buffer) glDeleteBuffers(1, &uniform_blocks[binding].buffer);
    glCreateBuffers(1, &uniform_blocks[binding].buffer);
    glNamedBufferData(uniform_blocks[binding].buffer, (GLsizeiptr)block, NULL, GL_DYNAMIC_DRAW);
    uniform_blocks[binding].size = block;
  }
  size_t copy = bytes < block ? bytes : block;
  glClearNamedBufferSubData(uniform_blocks[binding].buffer, GL_R8, (GLintptr)copy, (GLsizeiptr)(block - copy), GL_RED,
                            GL_UNSIGNED_BYTE, NULL);
  if (data && copy) glNamedBufferSubData(uniform_blocks[binding].buffer, 0, (GLsizeiptr)copy, data);
  glBindBufferBase(GL_UNIFORM_BUFFER, (GLuint)binding, uniform_blocks[binding].buffer);
}

float lm_scene_clear_depth(bool shadow_caster) { return shadow_caster ? 1.0f : 0.0f; }

void lm_set_scene_state(bool on, bool shadow_caster) {
  if (on && shadow_caster)
    glEnable(GL_DEPTH_CLAMP);
  else
    glDisable(GL_DEPTH_CLAMP);
  /* Camera views use reversed depth (lm_scene_frame_data's projection: near
   * 1, far 0) in a 0..1 clip range, so float depth keeps its precision;
   * shadow tiles keep the usual mapping their shaders read. */
  glClipControl(GL_LOWER_LEFT, on && !shadow_caster ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
  if (on) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(shadow_caster ? GL_LESS : GL_GREATER);
    glDepthMask(GL_TRUE);
    lm_set_cull_back_faces(!shadow_caster);
  } else {
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
  }
}

void lm_set_front_face_clockwise(bool clockwise) { glFrontFace(clockwise ? GL_CW : GL_CCW); }

void lm_set_cull_back_faces(bool on) {
  if (on) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
  } else {
    glDisable(GL_CULL_FACE);
  }
}

void lm_set_blend_state(bool on) {
  if (on) {
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_SRC1_COLOR);
  } else {
    glDisable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ZERO); /* llvmpipe keeps reading the second source while the factor names it */
  }
  glDepthMask(on ? GL_FALSE : GL_TRUE);
}

void lm_set_caster_layer(int transmit, int count, bool translucent) {
  for (int i = 0; i < count; i++) {
    GLboolean on = transmit < 0 || (i == transmit) == translucent;
    glColorMaski((GLuint)i, on, on, on, on);
  }
  if (!translucent) {
    glBlendEquation(GL_FUNC_ADD);
    lm_set_blend_state(false);
    return;
  }
  glDepthMask(GL_FALSE);
  glEnablei(GL_BLEND, (GLuint)transmit);
  glBlendEquationSeparatei((GLuint)transmit, GL_FUNC_ADD, GL_MIN);
  glBlendFuncSeparatei((GLuint)transmit, GL_ZERO, GL_SRC_COLOR, GL_ONE, GL_ONE);
}

/* ---- frame block ------------------------------------------------------- */
static GLuint frame_ubo;
static long flush_pending; /* triangles drawn this frame since the last flush (lm_mesh_draw_instances) */

void lm_frame_upload(const lm_frame_data *frame, const lm_light_data *lights, int light_count) {
  flush_pending = 0; /* a frame of fewer triangles never flushes */
  if (!frame_ubo) {
    glCreateBuffers(1, &frame_ubo);
    glNamedBufferData(frame_ubo, sizeof *frame, NULL, GL_DYNAMIC_DRAW);
  }
  glNamedBufferSubData(frame_ubo, 0, sizeof *frame, frame);
  glBindBufferBase(GL_UNIFORM_BUFFER, 0, frame_ubo);
  lm_storage_upload(1, lights, sizeof *lights * (size_t)(light_count > 0 ? light_count : 0));
}

/* ---- meshes ------------------------------------------------------------ */
/* llvmpipe or softpipe: the "GPU" is this process's CPU and memory. */
static bool software_rasterizer(void) {
  static int known = -1;
  const char *r = known < 0 ? lm_gl_renderer() : NULL;
  if (r) known = strstr(r, "llvmpipe") || strstr(r, "softpipe");
  return known > 0;
}

/* Bytes a vertex for m's formats: position, normal (4), uv. */
static int position_bytes(const lm_mesh *m) { return m->float_positions ? 12 : 8; }
static int vertex_stride(const lm_mesh *m) { return position_bytes(m) + 4 + (m->float_uvs ? 8 : 4); }

static uint16_t unorm16(float v) { return (uint16_t)(v > 0 ? (v < 1 ? v * 65535.0f + 0.5f : 65535.0f) : 0.0f); }

/* Vertices first .. first + count - 1 of `vertices` (8 floats each) into
 * `out` in m's formats; normals through meshoptimizer's octahedral encoder
 * (its first two snorm16 components are the octahedral x, y that
 * common.glsl's oct_decode reads). `scratch`: 8 floats a vertex. */
static void pack_vertices(const lm_mesh *m, const float *vertices, int count, unsigned char *out, float *scratch) {
  int stride = vertex_stride(m), pos = position_bytes(m);
  float inv = m->extent > 0 ? 1.0f / m->extent : 0.0f;
  int16_t *oct = (int16_t *)(scratch + 4 * (size_t)count);
  for (int i = 0; i < count; i++) {
    const float *v = vertices + 8 * (size_t)i;
    float *n = scratch + 4 * (size_t)i;
    n[0] = v[3], n[1] = v[4], n[2] = v[5], n[3] = 0;
  }
  meshopt_encodeFilterOct(oct, (size_t)count, 8, 16, scratch);
  for (int i = 0; i < count; i++) {
    const float *v = vertices + 8 * (size_t)i;
    unsigned char *o = out + (size_t)i * stride;
    if (m->float_positions) {
      memcpy(o, v, 12);
    } else {
      uint16_t q[4] = {0};
      for (int c = 0; c < 3; c++) q[c] = unorm16((v[c] - m->origin[c]) * inv);
      memcpy(o, q, 8);
    }
    memcpy(o + pos, oct + 4 * (size_t)i, 4);
    if (m->float_uvs) {
      memcpy(o + pos + 4, v + 6, 8);
    } else {
      uint16_t uv[2] = {unorm16(v[6]), unorm16(v[7])};
      memcpy(o + pos + 4, uv, 4);
    }
  }
}

/* Writes vertices (8 floats each) into m's buffer from vertex `first` on, a
 * block at a time: the packed copy is never whole in memory. */
static void upload_vertices(const lm_mesh *m, const float *vertices, int count) {
  enum { BLOCK = 4096 };
  int stride = vertex_stride(m);
  unsigned char *packed = lm_alloc((size_t)BLOCK * (size_t)stride);
  float *scratch = lm_alloc(sizeof(float) * 8 * BLOCK);
  for (int first = 0; first < count; first += BLOCK) {
    int n = count - first < BLOCK ? count - first : BLOCK;
    pack_vertices(m, vertices + 8 * (size_t)first, n, packed, scratch);
    glNamedBufferSubData(m->vbo, (GLintptr)first * stride, (GLsizeiptr)n * stride, packed);
  }
  free(scratch);
  free(packed);
}

void lm_mesh_create(lm_mesh *m, const float *vertices, int vertex_count, const float *tangents,
                    const uint32_t *indices, int index_count, bool deforms) {
  *m = (lm_mesh){.float_positions = deforms, .short_indices = vertex_count <= 65536};
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int i = 0; i < vertex_count; i++) {
    const float *v = vertices + 8 * (size_t)i;
    for (int c = 0; c < 3; c++) /* fminf, fmaxf: a non-finite coordinate leaves them */
      if (isfinite(v[c])) lo[c] = fminf(lo[c], v[c]), hi[c] = fmaxf(hi[c], v[c]);
    m->float_uvs = m->float_uvs || !(v[6] >= 0 && v[6] <= 1 && v[7] >= 0 && v[7] <= 1);
  }
  for (int c = 0; c < 3; c++) {
    m->origin[c] = lo[c] <= hi[c] ? lo[c] : 0;
    m->extent = fmaxf(m->extent, lo[c] <= hi[c] ? hi[c] - lo[c] : 0);
  }
  int stride = vertex_stride(m);
  glCreateVertexArrays(1, &m->vao);
  glCreateBuffers(1, &m->vbo);
  glCreateBuffers(1, &m->ibo);
  glNamedBufferData(m->vbo, (GLsizeiptr)vertex_count * stride, NULL, GL_STATIC_DRAW);
  upload_vertices(m, vertices, vertex_count);
  if (m->short_indices) {
    uint16_t *shorts = lm_alloc(sizeof *shorts * (size_t)(index_count > 0 ? index_count : 1));
    for (int i = 0; i < index_count; i++) shorts[i] = (uint16_t)indices[i];
    glNamedBufferData(m->ibo, (GLsizeiptr)index_count * 2, shorts, GL_STATIC_DRAW);
    free(shorts);
  } else {
    glNamedBufferData(m->ibo, (GLsizeiptr)index_count * 4, indices, GL_STATIC_DRAW);
  }
  glVertexArrayVertexBuffer(m->vao, 0, m->vbo, 0, stride);
  glVertexArrayElementBuffer(m->vao, m->ibo);
  int pos = position_bytes(m);
  glVertexArrayAttribFormat(m->vao, 0, 3, m->float_positions ? GL_FLOAT : GL_UNSIGNED_SHORT,
                            !m->float_positions, 0);
  glVertexArrayAttribFormat(m->vao, 1, 2, GL_SHORT, GL_TRUE, (GLuint)pos);
  glVertexArrayAttribFormat(m->vao, 2, 2, m->float_uvs ? GL_FLOAT : GL_UNSIGNED_SHORT, !m->float_uvs, (GLuint)pos + 4);
  for (int a = 0; a < 3; a++) {
    glEnableVertexArrayAttrib(m->vao, a);
    glVertexArrayAttribBinding(m->vao, a, 0);
  }
  /* Binding 1: lm_instance, one an instance (its buffer is bound at draw time):
   * model 3-6, normal 7-9, prev_model 11-14. */
  for (int a = 3; a < 15; a++) {
    if (a == 10) continue;
    bool normal = a >= 7 && a < 10;
    size_t offset = a < 7 ? offsetof(lm_instance, model) + (size_t)(a - 3) * 4 * sizeof(float)
                    : normal ? offsetof(lm_instance, normal) + (size_t)(a - 7) * 3 * sizeof(float)
                             : offsetof(lm_instance, prev_model) + (size_t)(a - 11) * 4 * sizeof(float);
    glEnableVertexArrayAttrib(m->vao, (GLuint)a);
    glVertexArrayAttribFormat(m->vao, (GLuint)a, normal ? 3 : 4, GL_FLOAT, GL_FALSE, (GLuint)offset);
    glVertexArrayAttribBinding(m->vao, (GLuint)a, 1);
  }
  glVertexArrayBindingDivisor(m->vao, 1, 1);
  if (tangents) { /* binding 2 */
    glCreateBuffers(1, &m->tbo);
    glNamedBufferData(m->tbo, (GLsizeiptr)vertex_count * 4 * sizeof(float), tangents, GL_STATIC_DRAW);
    glVertexArrayVertexBuffer(m->vao, 2, m->tbo, 0, 4 * sizeof(float));
    glEnableVertexArrayAttrib(m->vao, 10);
    glVertexArrayAttribFormat(m->vao, 10, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(m->vao, 10, 2);
  }
  m->index_count = index_count;
}

void lm_mesh_dequantize(const lm_mesh *m, const float model[16], float out[16]) {
  memcpy(out, model, sizeof(float) * 16);
  if (m->float_positions) return;
  for (int r = 0; r < 4; r++) {
    out[12 + r] = model[12 + r] + model[r] * m->origin[0] + model[4 + r] * m->origin[1] + model[8 + r] * m->origin[2];
    for (int c = 0; c < 3; c++) out[4 * c + r] = model[4 * c + r] * m->extent;
  }
}

/* The inverse of meshoptimizer's octahedral encoding (common.glsl's oct_decode). */
static void oct_decode(const int16_t q[2], float n[3]) {
  float x = fmaxf(q[0] / 32767.0f, -1.0f), y = fmaxf(q[1] / 32767.0f, -1.0f), z = 1.0f - fabsf(x) - fabsf(y);
  float t = fmaxf(-z, 0.0f);
  x += x >= 0 ? -t : t, y += y >= 0 ? -t : t;
  float len = sqrtf(x * x + y * y + z * z); /* at least 1 / sqrt(3) */
  n[0] = x / len, n[1] = y / len, n[2] = z / len;
}

void lm_mesh_read(const lm_mesh *m, float *vertices, int vertex_count, uint32_t *indices, int index_count) {
  int stride = vertex_stride(m), pos = position_bytes(m);
  unsigned char *packed = lm_alloc((size_t)(vertex_count > 0 ? vertex_count : 1) * (size_t)stride);
  glGetNamedBufferSubData(m->vbo, 0, (GLsizeiptr)vertex_count * stride, packed);
  for (int i = 0; i < vertex_count; i++) {
    const unsigned char *o = packed + (size_t)i * stride;
    float *v = vertices + 8 * (size_t)i;
    if (m->float_positions) {
      memcpy(v, o, 12);
    } else {
      uint16_t q[3];
      memcpy(q, o, 6);
      for (int c = 0; c < 3; c++) v[c] = m->origin[c] + m->extent * (q[c] / 65535.0f);
    }
    int16_t oct[2];
    memcpy(oct, o + pos, 4);
    oct_decode(oct, v + 3);
    if (m->float_uvs) {
      memcpy(v + 6, o + pos + 4, 8);
    } else {
      uint16_t uv[2];
      memcpy(uv, o + pos + 4, 4);
      v[6] = uv[0] / 65535.0f, v[7] = uv[1] / 65535.0f;
    }
  }
  free(packed);
  if (!m->short_indices) {
    glGetNamedBufferSubData(m->ibo, 0, (GLsizeiptr)index_count * 4, indices);
    return;
  }
  uint16_t *shorts = lm_alloc(sizeof *shorts * (size_t)(index_count > 0 ? index_count : 1));
  glGetNamedBufferSubData(m->ibo, 0, (GLsizeiptr)index_count * 2, shorts);
  for (int i = 0; i < index_count; i++) indices[i] = shorts[i];
  free(shorts);
}

void lm_mesh_update_vertices(lm_mesh *m, const float *vertices, int vertex_count) {
  upload_vertices(m, vertices, vertex_count);
}

void lm_mesh_set_prev_positions(lm_mesh *m, const float *positions, int vertex_count) {
  if (!positions) {
    if (m->prev) glDisableVertexArrayAttrib(m->vao, 15);
    m->prev = false;
    return;
  }
  GLsizeiptr bytes = (GLsizeiptr)vertex_count * 3 * sizeof(float);
  if (!m->pbo) { /* binding 3, made on the first deformation */
    glCreateBuffers(1, &m->pbo);
    glNamedBufferData(m->pbo, bytes, NULL, GL_DYNAMIC_DRAW);
    glVertexArrayVertexBuffer(m->vao, 3, m->pbo, 0, 3 * sizeof(float));
    glVertexArrayAttribFormat(m->vao, 15, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(m->vao, 15, 3);
  }
  if (m->float_positions) {
    glNamedBufferSubData(m->pbo, 0, bytes, positions);
  } else { /* in the quantized positions' space, which the instance matrices map (lm_mesh_dequantize) */
    float *local = lm_alloc((size_t)bytes), inv = m->extent > 0 ? 1.0f / m->extent : 0.0f;
    for (int i = 0; i < 3 * vertex_count; i++) local[i] = (positions[i] - m->origin[i % 3]) * inv;
    glNamedBufferSubData(m->pbo, 0, bytes, local);
    free(local);
  }
  if (!m->prev) glEnableVertexArrayAttrib(m->vao, 15);
  m->prev = true;
}

void lm_mesh_destroy(lm_mesh *m) {
  if (m->pbo) glDeleteBuffers(1, &m->pbo);
  if (m->vao) glDeleteVertexArrays(1, &m->vao);
  if (m->vbo) glDeleteBuffers(1, &m->vbo);
  if (m->tbo) glDeleteBuffers(1, &m->tbo);
  if (m->ibo) glDeleteBuffers(1, &m->ibo);
  *m = (lm_mesh){0};
}

static GLuint instance_vbo;
static size_t instance_capacity; /* instances */

void lm_instances_upload(const lm_instance *instances, int count) {
  if (count <= 0) return;
  if (!instance_vbo) glCreateBuffers(1, &instance_vbo);
  if ((size_t)count > instance_capacity) instance_capacity = (size_t)count + (size_t)count / 2;
  /* New storage each time (orphaning): draws already queued keep reading the old. */
  glNamedBufferData(instance_vbo, (GLsizeiptr)(instance_capacity * sizeof(lm_instance)), NULL, GL_STREAM_DRAW);
  glNamedBufferSubData(instance_vbo, 0, (GLsizeiptr)((size_t)count * sizeof(lm_instance)), instances);
}

void lm_mesh_draw_instances(const lm_mesh *m, int first_index, int index_count, int first, int count) {
  if (count <= 0 || !instance_vbo || first_index < 0 || index_count <= 0 || first_index + index_count > m->index_count)
    return;
  glVertexArrayVertexBuffer(m->vao, 1, instance_vbo, 0, sizeof(lm_instance));
  /* A disabled attribute reads the context's current value, not the VAO's:
   * (0, 0, 0, 0) tells the shader that the mesh has no previous positions. */
  if (!m->prev) glVertexAttrib4f(15, 0, 0, 0, 0);
  glBindVertexArray(m->vao);
  /* A software rasterizer keeps every triangle it has binned, in this
   * process, until a flush: a scene of millions of triangles drawn at once
   * would hold them all (the export in docs/benchmarks.md "Big files": 50
   * MiB at its first frame). A flush every LM_FLUSH_TRIANGLES of a frame bounds that. */
  flush_pending += (long)(index_count / 3) * count;
  if (flush_pending >= LM_FLUSH_TRIANGLES && software_rasterizer()) glFlush(), flush_pending = 0;
  size_t index_bytes = m->short_indices ? 2 : 4;
  glDrawElementsInstancedBaseInstance(GL_TRIANGLES, index_count, m->short_indices ? GL_UNSIGNED_SHORT : GL_UNSIGNED_INT,
                                      (const void *)((size_t)first_index * index_bytes), count, (GLuint)first);
}

/* ---- timers ------------------------------------------------------------ */
lm_clock lm_clock_choose(lm_clock wanted) {
  if (wanted != LM_CLOCK_AUTO) return wanted;
  const char *r = lm_gl_renderer();
  /* llvmpipe's GL_TIME_ELAPSED results were seen to be nonsense. */
  if (!r || software_rasterizer() || strstr(r, "SVGA3D")) return LM_CLOCK_CPU;
  return LM_CLOCK_GPU;
}

const char *lm_clock_name(lm_clock c) {
  return c == LM_CLOCK_GPU       ? "gpu (GL_TIME_ELAPSED queries)"
         : c == LM_CLOCK_PROCESS ? "process (glFinish + CLOCK_PROCESS_CPUTIME_ID, every thread's)"
                                 : "cpu (glFinish + CLOCK_MONOTONIC)";
}

void lm_timer_begin(lm_timer *t, lm_clock clock) {
  t->clock = clock;
  t->ms = -1;
  if (clock == LM_CLOCK_GPU) {
    if (!t->query) glCreateQueries(GL_TIME_ELAPSED, 1, &t->query);
    glBeginQuery(GL_TIME_ELAPSED, t->query);
  } else {
    glFinish();
    t->start_ms = clock == LM_CLOCK_PROCESS ? lm_cpu_ms() : lm_now_ms();
  }
}

void lm_timer_end(lm_timer *t) {
  if (t->clock == LM_CLOCK_GPU) {
    glEndQuery(GL_TIME_ELAPSED);
  } else {
    glFinish();
    t->ms = (t->clock == LM_CLOCK_PROCESS ? lm_cpu_ms() : lm_now_ms()) - t->start_ms;
  }
}

double lm_timer_read(lm_timer *t) {
  if (t->clock == LM_CLOCK_GPU && t->query && t->ms < 0) {
    GLuint64 ns = 0;
    glGetQueryObjectui64v(t->query, GL_QUERY_RESULT, &ns);
    t->ms = (double)ns * 1e-6;
  }
  return t->ms;
}

void lm_timer_destroy(lm_timer *t) {
  if (t->query) glDeleteQueries(1, &t->query);
  t->query = 0;
}

void lm_finish(void) { glFinish(); }

double lm_gpu_memory_used_mib(void) {
  if (!epoxy_has_gl_extension("GL_NVX_gpu_memory_info")) return -1;
  GLint total = 0, available = 0; /* KiB */
  glGetIntegerv(GL_GPU_MEMORY_INFO_DEDICATED_VIDMEM_NVX, &total);
  glGetIntegerv(GL_GPU_MEMORY_INFO_CURRENT_AVAILABLE_VIDMEM_NVX, &available);
  return total > 0 && available <= total ? (total - available) / 1024.0 : -1;
}

/* ---- readback ---------------------------------------------------------- */
void lm_texture_read(lm_texture tex, int width, int height, bool floats, void *out) {
  size_t texel = floats ? 16 : 4, row = (size_t)width * texel;
  size_t size = row * (size_t)height;
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(tex.id, 0, GL_RGBA, floats ? GL_FLOAT : GL_UNSIGNED_BYTE, (GLsizei)size, out);
  /* GL's first row is the bottom one; images want the top one first. */
  unsigned char *p = out, *tmp = lm_alloc(row);
  for (int y = 0; y < height / 2; y++) {
    unsigned char *a = p + (size_t)y * row, *b = p + (size_t)(height - 1 - y) * row;
    memcpy(tmp, a, row);
    memcpy(a, b, row);
    memcpy(b, tmp, row);
  }
  free(tmp);
}

void lm_readback_start(lm_readback *rb, lm_texture tex, int width, int height) {
  size_t size = sizeof(float) * 4 * (size_t)width * (size_t)height;
  if (!rb->buffer || rb->width != width || rb->height != height) {
    lm_readback_free(rb);
    glCreateBuffers(1, &rb->buffer);
    glNamedBufferStorage(rb->buffer, (GLsizeiptr)size, NULL, GL_MAP_READ_BIT);
  }
  if (rb->fence) glDeleteSync(rb->fence);
  rb->width = width, rb->height = height;
  glBindBuffer(GL_PIXEL_PACK_BUFFER, rb->buffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(tex.id, 0, GL_RGBA, GL_FLOAT, (GLsizei)size, NULL); /* into the buffer */
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  rb->fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
}

bool lm_readback_collect(lm_readback *rb, float *out) {
  if (!rb->fence) return false;
  /* Flushes, then waits: a second is far beyond a frame, and on expiry the
   * map below waits anyway. */
  glClientWaitSync(rb->fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000u);
  glDeleteSync(rb->fence);
  rb->fence = NULL;
  size_t size = sizeof(float) * 4 * (size_t)rb->width * (size_t)rb->height;
  glGetNamedBufferSubData(rb->buffer, 0, (GLsizeiptr)size, out);
  return true;
}

void lm_readback_free(lm_readback *rb) {
  if (rb->fence) glDeleteSync(rb->fence);
  if (rb->buffer) glDeleteBuffers(1, &rb->buffer);
  *rb = (lm_readback){0};
}

/* ---- uploads, copies and the window's framebuffer ---------------------- */
void lm_texture_upload(lm_texture tex, int width, int height, const uint8_t *rgba) {
  /* GL's row 0 is the image's last: flip into a copy, then one upload. */
  size_t row = (size_t)width * 4;
  uint8_t *flipped = lm_alloc(row * (size_t)height);
  for (int y = 0; y < height; y++) memcpy(flipped + (size_t)y * row, rgba + (size_t)(height - 1 - y) * row, row);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(tex.id, 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, flipped);
  free(flipped);
}

void lm_texture_upload_floats(lm_texture tex, int width, int height, const float *rgba) {
  size_t row = (size_t)width * 4;
  float *flipped = lm_alloc(row * (size_t)height * sizeof(float));
  for (int y = 0; y < height; y++)
    memcpy(flipped + (size_t)y * row, rgba + (size_t)(height - 1 - y) * row, row * sizeof(float));
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(tex.id, 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, flipped);
  free(flipped);
}

void lm_texture_copy(lm_texture dst, lm_texture src, int width, int height) {
  glCopyImageSubData(src.id, GL_TEXTURE_2D, 0, 0, 0, 0, dst.id, GL_TEXTURE_2D, 0, 0, 0, 0, width, height, 1);
}

void lm_texture_copy_rect(lm_texture dst, lm_texture src, int x, int y, int width, int height) {
  lm_texture_copy_moved(dst, x, y, src, x, y, width, height);
}

void lm_texture_copy_moved(lm_texture dst, int dx, int dy, lm_texture src, int sx, int sy, int width, int height) {
  glCopyImageSubData(src.id, GL_TEXTURE_2D, 0, sx, sy, 0, dst.id, GL_TEXTURE_2D, 0, dx, dy, 0, width, height, 1);
}

void lm_screen_bind(int width, int height) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, width, height);
}

bool lm_screen_blit(lm_texture src, int x, int y, int width, int height, lm_error *err) {
  lm_attachments att = {.color = {src}, .color_count = 1};
  GLuint fbo = framebuffer_for(&att, err);
  if (!fbo) return false;
  glDisable(GL_SCISSOR_TEST); /* it would clip the blit */
  glBlitNamedFramebuffer(fbo, 0, x, y, x + width, y + height, x, y, x + width, y + height, GL_COLOR_BUFFER_BIT,
                         GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return true;
}

void lm_screen_read(int width, int height, uint8_t *rgb) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  size_t row = (size_t)width * 3;
  for (int y = 0; y < height; y++) /* top row first */
    glReadPixels(0, height - 1 - y, width, 1, GL_RGB, GL_UNSIGNED_BYTE, rgb + (size_t)y * row);
}

/* ---- object counts ----------------------------------------------------- */
int lm_program_live_count(void); /* program.c */

lm_gfx_counts lm_gfx_stats(void) {
  return (lm_gfx_counts){live_textures, fbo_count, lm_program_live_count()};
}
