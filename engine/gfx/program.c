/* Programs: compile, link, cache by (files, defines), and reflect uniforms. */
#include "gfx/gfx.h"

#include <ctype.h>
#include <epoxy/gl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct cached_program {
  char key[1024];
  lm_program *program;
  bool stale;  /* its files changed: rebuild on next use */
  char *error; /* why the last rebuild failed (the old program stays) */
  double build_ms; /* wall time of its builds, rebuilds included */
} cached_program;
static cached_program *cache;
static int cache_count, cache_cap;

const char *lm_shader_dir(void) {
  static char dir[1024];
  snprintf(dir, sizeof dir, "%s/shaders", lm_root_dir());
  return dir;
}

static const struct {
  const char *glsl;
  lm_uniform_type type;
  int components;
} uniform_types[] = {
    {"float", LM_UNIFORM_FLOAT, 1}, {"vec2", LM_UNIFORM_VEC2, 2},   {"vec3", LM_UNIFORM_VEC3, 3},
    {"vec4", LM_UNIFORM_VEC4, 4},   {"int", LM_UNIFORM_INT, 1},     {"ivec2", LM_UNIFORM_IVEC2, 2},
    {"ivec3", LM_UNIFORM_IVEC3, 3}, {"ivec4", LM_UNIFORM_IVEC4, 4}, {"bool", LM_UNIFORM_BOOL, 1},
    {"mat3", LM_UNIFORM_MAT3, 9},   {"mat4", LM_UNIFORM_MAT4, 16},
};

const char *lm_uniform_type_name(lm_uniform_type t) {
  for (size_t i = 0; i < sizeof uniform_types / sizeof *uniform_types; i++)
    if (uniform_types[i].type == t) return uniform_types[i].glsl;
  return t == LM_UNIFORM_SAMPLER ? "sampler" : t == LM_UNIFORM_SAMPLER_SHADOW ? "shadow sampler" : "other";
}

int lm_uniform_type_components(lm_uniform_type t) {
  for (size_t i = 0; i < sizeof uniform_types / sizeof *uniform_types; i++)
    if (uniform_types[i].type == t) return uniform_types[i].components;
  return 0;
}

static lm_uniform_type parse_type(const char *word) {
  for (size_t i = 0; i < sizeof uniform_types / sizeof *uniform_types; i++)
    if (!strcmp(uniform_types[i].glsl, word)) return uniform_types[i].type;
  if (!strncmp(word, "sampler", 7) || !strncmp(word, "isampler", 8) || !strncmp(word, "usampler", 8))
    return strstr(word, "Shadow") ? LM_UNIFORM_SAMPLER_SHADOW : LM_UNIFORM_SAMPLER;
  return LM_UNIFORM_OTHER;
}

static const char *skip_space_and_comments(const char *p) {
  for (;;) {
    while (isspace((unsigned char)*p)) p++;
    if (p[0] == '/' && p[1] == '/') {
      while (*p && *p != '\n') p++;
    } else if (p[0] == '/' && p[1] == '*') {
      const char *end = strstr(p + 2, "*/");
      p = end ? end + 2 : p + strlen(p);
    } else {
      return p;
    }
  }
}

static int read_word(const char *p, char *out, int cap) {
  int n = 0;
  while ((isalnum((unsigned char)p[n]) || p[n] == '_') && n < cap - 1) out[n] = p[n], n++;
  out[n] = '\0';
  return n;
}

static bool is_int_type(lm_uniform_type t) {
  return t == LM_UNIFORM_INT || t == LM_UNIFORM_BOOL || (t >= LM_UNIFORM_IVEC2 && t <= LM_UNIFORM_IVEC4);
}

static void add_uniform(lm_program *prog, const char *name, lm_uniform_type type) {
  for (int i = 0; i < prog->uniform_count; i++)
    if (!strcmp(prog->uniforms[i].name, name)) return;
  lm_uniform *u = LM_PUSH(prog->uniforms, prog->uniform_count, prog->uniform_cap);
  snprintf(u->name, sizeof u->name, "%s", name);
  u->type = type;
  u->location = -1;
  u->unit = -1;
  memset(&u->initial, 0, sizeof u->initial);
}

/* Every `uniform TYPE NAME` declared in the text (blocks are skipped). The
 * compiler drops unused uniforms, so reflection alone cannot tell an unused
 * name from a misspelled one; the declarations can. */
static void scan_uniforms(lm_program *prog, const char *text) {
  for (const char *p = text; (p = skip_space_and_comments(p)) && *p;) {
    char word[64];
    int n = read_word(p, word, sizeof word);
    if (n == 0) {
      p++;
      continue;
    }
    bool boundary = p == text || !(isalnum((unsigned char)p[-1]) || p[-1] == '_');
    p += n;
    if (!boundary || strcmp(word, "uniform")) continue;
    const char *q = skip_space_and_comments(p);
    char type[64], name[64];
    q += read_word(q, type, sizeof type);
    q = skip_space_and_comments(q);
    if (*q == '{') continue; /* uniform block */
    for (;;) {             /* "uniform float a, b;" declares several */
      q += read_word(q, name, sizeof name);
      if (!name[0]) break;
      add_uniform(prog, name, parse_type(type));
      q = skip_space_and_comments(q);
      while (*q && *q != ',' && *q != ';') q++;
      if (*q != ',') break;
      q = skip_space_and_comments(q + 1);
    }
    p = q;
  }
}

static GLuint compile(GLenum stage, const lm_shader_source *src, lm_error *err) {
  GLuint s = glCreateShader(stage);
  const char *text = src->text.data;
  glShaderSource(s, 1, &text, NULL);
  glCompileShader(s);
  GLint ok = 0, len = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (ok) return s;
  glGetShaderiv(s, GL_INFO_LOG_LENGTH, &len);
  char *log = lm_alloc((size_t)len + 1);
  glGetShaderInfoLog(s, len, NULL, log);
  lm_buf mapped = {0};
  lm_shader_map_log(src, log, &mapped);
  while (mapped.len > 0 && mapped.data[mapped.len - 1] == '\n') mapped.data[--mapped.len] = '\0';
  lm_error_set(err, "%s", mapped.data ? mapped.data : "shader compile failed (no log)");
  lm_buf_free(&mapped);
  free(log);
  glDeleteShader(s);
  return 0;
}

static int live_programs; /* GL program objects, for lm_gfx_stats */
int lm_program_live_count(void);
int lm_program_live_count(void) { return live_programs; }

static void program_free(lm_program *p) {
  if (p->id) glDeleteProgram(p->id), live_programs--;
  free(p->uniforms);
  free(p);
}

static lm_program *build(const char *vert, const char *frag, const char *defines, lm_error *err) {
  const char *dir = lm_shader_dir();
  char vpath[1024], fpath[1024];
  snprintf(vpath, sizeof vpath, "%s/%s", dir, vert);
  snprintf(fpath, sizeof fpath, "%s/%s", dir, frag);
  lm_shader_source vs, fs;
  if (!lm_shader_source_load(&vs, vpath, dir, defines, err)) return NULL;
  if (!lm_shader_source_load(&fs, fpath, dir, defines, err)) {
    lm_shader_source_free(&vs);
    return NULL;
  }
  lm_program *prog = lm_alloc(sizeof *prog);
  snprintf(prog->label, sizeof prog->label, "shaders/%s%s%s%s", frag, defines && *defines ? " [" : "",
           defines ? defines : "", defines && *defines ? "]" : "");
  GLuint v = compile(GL_VERTEX_SHADER, &vs, err), f = v ? compile(GL_FRAGMENT_SHADER, &fs, err) : 0;
  if (v && f) {
    prog->id = glCreateProgram();
    live_programs++;
    glAttachShader(prog->id, v);
    glAttachShader(prog->id, f);
    glLinkProgram(prog->id);
    GLint ok = 0;
    glGetProgramiv(prog->id, GL_LINK_STATUS, &ok);
    if (!ok) {
      char log[2048] = "";
      glGetProgramInfoLog(prog->id, sizeof log, NULL, log);
      lm_error_set(err, "shaders/%s + shaders/%s: link failed: %s", vert, frag, log);
    } else {
      scan_uniforms(prog, vs.text.data);
      scan_uniforms(prog, fs.text.data);
    }
  }
  if (v) glDeleteShader(v);
  if (f) glDeleteShader(f);
  lm_shader_source_free(&vs);
  lm_shader_source_free(&fs);
  GLint linked = 0;
  if (prog->id) glGetProgramiv(prog->id, GL_LINK_STATUS, &linked);
  if (!linked) {
    program_free(prog);
    return NULL;
  }
  int unit = 0;
  for (int i = 0; i < prog->uniform_count; i++) {
    lm_uniform *u = &prog->uniforms[i];
    u->location = glGetUniformLocation(prog->id, u->name);
    if (u->location < 0) continue;
    if (u->type == LM_UNIFORM_SAMPLER || u->type == LM_UNIFORM_SAMPLER_SHADOW) {
      u->unit = unit++;
      glProgramUniform1i(prog->id, u->location, u->unit);
    } else if (is_int_type(u->type)) {
      glGetUniformiv(prog->id, u->location, u->initial.i);
    } else if (u->type != LM_UNIFORM_OTHER) {
      glGetUniformfv(prog->id, u->location, u->initial.f);
    }
  }
  GLint outputs = 0;
  glGetProgramInterfaceiv(prog->id, GL_PROGRAM_OUTPUT, GL_ACTIVE_RESOURCES, &outputs);
  /* A dual-source blending output (index 1) writes its location's target: count those of index 0. */
  prog->output_count = 0;
  for (GLint i = 0; i < outputs; i++) {
    const GLenum prop = GL_LOCATION_INDEX;
    GLint index = 0;
    glGetProgramResourceiv(prog->id, GL_PROGRAM_OUTPUT, (GLuint)i, 1, &prop, 1, NULL, &index);
    prog->output_count += index == 0;
  }
  return prog;
}

lm_program *lm_program_get(const char *vert, const char *frag, const char *defines, lm_error *err) {
  char key[1024];
  snprintf(key, sizeof key, "%s|%s|%s", vert, frag, defines ? defines : "");
  for (int i = 0; i < cache_count; i++) {
    cached_program *c = &cache[i];
    if (strcmp(c->key, key)) continue;
    if (c->stale) {
      /* Rebuilt once per invalidation; a failure keeps the last good program running. */
      c->stale = false;
      lm_error why;
      double t0 = lm_now_ms();
      lm_program *p = build(vert, frag, defines, &why);
      c->build_ms += lm_now_ms() - t0;
      if (p) {
        program_free(c->program);
        c->program = p;
      } else {
        c->error = lm_strdup(why.msg);
      }
    }
    return c->program;
  }
  double t0 = lm_now_ms();
  lm_program *p = build(vert, frag, defines, err);
  if (!p) return NULL;
  cached_program *c = LM_PUSH(cache, cache_count, cache_cap);
  snprintf(c->key, sizeof c->key, "%s", key);
  c->program = p;
  c->build_ms = lm_now_ms() - t0;
  return p;
}

static unsigned generation;

unsigned lm_programs_generation(void) { return generation; }

void lm_programs_invalidate(void) {
  generation++;
  for (int i = 0; i < cache_count; i++) {
    cache[i].stale = true;
    free(cache[i].error);
    cache[i].error = NULL;
  }
}

const char *lm_programs_error(void) {
  for (int i = 0; i < cache_count; i++)
    if (cache[i].error) return cache[i].error;
  return NULL;
}

const lm_uniform *lm_program_uniform(const lm_program *p, const char *name) {
  for (int i = 0; i < p->uniform_count; i++)
    if (!strcmp(p->uniforms[i].name, name)) return &p->uniforms[i];
  return NULL;
}

void lm_program_use(const lm_program *p) { glUseProgram(p->id); }

void lm_program_set(const lm_program *p, const lm_uniform *u, const float *v) {
  if (u->location < 0) return;
  GLuint id = p->id;
  GLint loc = u->location;
  switch (u->type) {
  case LM_UNIFORM_FLOAT: glProgramUniform1fv(id, loc, 1, v); break;
  case LM_UNIFORM_VEC2: glProgramUniform2fv(id, loc, 1, v); break;
  case LM_UNIFORM_VEC3: glProgramUniform3fv(id, loc, 1, v); break;
  case LM_UNIFORM_VEC4: glProgramUniform4fv(id, loc, 1, v); break;
  case LM_UNIFORM_MAT3: glProgramUniformMatrix3fv(id, loc, 1, GL_FALSE, v); break;
  case LM_UNIFORM_MAT4: glProgramUniformMatrix4fv(id, loc, 1, GL_FALSE, v); break;
  default: break;
  }
}

void lm_program_set_int(const lm_program *p, const lm_uniform *u, const int *v) {
  if (u->location < 0) return;
  switch (u->type) {
  case LM_UNIFORM_INT:
  case LM_UNIFORM_BOOL: glProgramUniform1iv(p->id, u->location, 1, v); break;
  case LM_UNIFORM_IVEC2: glProgramUniform2iv(p->id, u->location, 1, v); break;
  case LM_UNIFORM_IVEC3: glProgramUniform3iv(p->id, u->location, 1, v); break;
  case LM_UNIFORM_IVEC4: glProgramUniform4iv(p->id, u->location, 1, v); break;
  default: break;
  }
}

void lm_program_reset(const lm_program *p) {
  for (int i = 0; i < p->uniform_count; i++) {
    const lm_uniform *u = &p->uniforms[i];
    if (is_int_type(u->type)) lm_program_set_int(p, u, u->initial.i);
    else lm_program_set(p, u, u->initial.f); /* samplers and others: nothing */
  }
}

void lm_program_bind_texture(const lm_uniform *u, lm_texture tex) {
  if (u->location >= 0 && u->unit >= 0) glBindTextureUnit((GLuint)u->unit, tex.id);
}

void lm_programs_clear(void) {
  for (int i = 0; i < cache_count; i++) {
    program_free(cache[i].program);
    free(cache[i].error);
  }
  free(cache);
  cache = NULL;
  cache_count = cache_cap = 0;
}

int lm_program_count(void) { return cache_count; }

/* Does the defines part of a cache key ("vert|frag|A;B=1") name `define`? */
static bool key_defines(const char *key, const char *define) {
  const char *p = strrchr(key, '|');
  size_t n = strlen(define);
  for (p = p ? p + 1 : key; *p;) {
    size_t len = strcspn(p, "=;");
    if (len == n && !strncmp(p, define, n)) return true;
    p += strcspn(p, ";");
    if (*p == ';') p++;
  }
  return false;
}

int lm_programs_stats(const char *define, double *build_ms) {
  int n = 0;
  double ms = 0;
  for (int i = 0; i < cache_count; i++)
    if (!define || key_defines(cache[i].key, define)) n++, ms += cache[i].build_ms;
  if (build_ms) *build_ms = ms;
  return n;
}
