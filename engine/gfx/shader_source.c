/* GLSL source assembly: #include expansion with #line directives so that a
 * compiler message points at the original file and line. Pure text, no GL. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "gfx/gfx.h"

#include <ctype.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A path relative to the engine root when it lies under it. */
static const char *display_name(const char *path) {
  char root[PATH_MAX];
  if (!realpath(lm_root_dir(), root)) snprintf(root, sizeof root, "%s", lm_root_dir());
  size_t n = strlen(root);
  if (!strncmp(path, root, n) && path[n] == '/') return path + n + 1;
  return path;
}

static int add_file(lm_shader_source *src, const char *path) {
  char **slot = LM_PUSH(src->files, src->file_count, src->file_cap);
  *slot = lm_strdup(path);
  return src->file_count - 1;
}

static bool append_defines(lm_buf *out, const char *defines, lm_error *err) {
  for (const char *p = defines; p && *p;) {
    const char *end = strchr(p, ';');
    int n = end ? (int)(end - p) : (int)strlen(p);
    const char *eq = memchr(p, '=', (size_t)n);
    int name_len = eq ? (int)(eq - p) : n;
    for (int i = 0; i < name_len; i++) {
      if (!(isalnum((unsigned char)p[i]) || p[i] == '_') || (i == 0 && isdigit((unsigned char)p[i]))) {
        lm_error_set(err, "define '%.*s' is not a GLSL identifier", name_len, p);
        return false;
      }
    }
    if (name_len > 0) {
      lm_buf_printf(out, "#define %.*s", name_len, p);
      if (eq) lm_buf_printf(out, " %.*s", n - name_len - 1, eq + 1);
      lm_buf_append(out, "\n", 1);
    }
    p += n;
    if (*p == ';') p++;
  }
  return true;
}

/* Parses `#include "name"` (spaces allowed); returns false when the line is
 * not an include. *name gets the quoted part. */
static bool parse_include(const char *line, int len, char *name, size_t cap, bool *malformed) {
  int i = 0;
  while (i < len && (line[i] == ' ' || line[i] == '\t')) i++;
  if (i >= len || line[i] != '#') return false;
  i++;
  while (i < len && (line[i] == ' ' || line[i] == '\t')) i++;
  if (len - i < 7 || strncmp(line + i, "include", 7)) return false;
  i += 7;
  while (i < len && (line[i] == ' ' || line[i] == '\t')) i++;
  *malformed = true;
  if (i >= len || (line[i] != '"' && line[i] != '<')) return true;
  char close = line[i] == '"' ? '"' : '>';
  const char *start = line + i + 1, *end = memchr(start, close, (size_t)(len - i - 1));
  if (!end || (size_t)(end - start) >= cap || end == start) return true;
  snprintf(name, cap, "%.*s", (int)(end - start), start);
  *malformed = false;
  return true;
}

static bool is_version_line(const char *line, int len) {
  int i = 0;
  while (i < len && (line[i] == ' ' || line[i] == '\t')) i++;
  return len - i >= 8 && !strncmp(line + i, "#version", 8);
}

/* Does the line end or switch a conditional group (#else, #elif, #endif)?
 * An #include inside a group that is skipped still adds its lines, and the
 * #line after it is skipped too: the line after the group sets it again. */
static bool is_group_switch(const char *line, int len) {
  int i = 0;
  while (i < len && (line[i] == ' ' || line[i] == '\t')) i++;
  if (i == len || line[i] != '#') return false;
  for (i++; i < len && (line[i] == ' ' || line[i] == '\t'); i++) {}
  return (len - i >= 4 && (!strncmp(line + i, "else", 4) || !strncmp(line + i, "elif", 4))) ||
         (len - i >= 5 && !strncmp(line + i, "endif", 5));
}

static bool expand(lm_shader_source *src, const char *given, const char *include_dir, int depth,
                   lm_error *err) {
  char path[PATH_MAX]; /* canonical, so "lib/../a.glsl" and "a.glsl" are one file */
  if (!realpath(given, path)) snprintf(path, sizeof path, "%s", given);
  if (depth > 32) {
    lm_error_set(err, "%s: includes nest deeper than 32 levels", display_name(path));
    return false;
  }
  for (int i = 0; i < src->file_count; i++)
    if (!strcmp(src->files[i], path)) return true; /* each file once, like #pragma once */
  lm_error read_err;
  char *text = lm_read_file(path, NULL, &read_err);
  if (!text) {
    lm_error_set(err, "%s", read_err.msg);
    return false;
  }
  int id = add_file(src, path);
  char dir[1024];
  lm_dirname(path, dir, sizeof dir);
  lm_buf_printf(&src->text, "#line 1 %d\n", id);
  int line_no = 1;
  bool ok = true;
  for (const char *p = text; *p && ok; line_no++) {
    const char *nl = strchr(p, '\n');
    int len = nl ? (int)(nl - p) : (int)strlen(p);
    char name[512];
    bool malformed = false;
    if (parse_include(p, len, name, sizeof name, &malformed)) {
      if (malformed) {
        lm_error_set(err, "%s:%d: malformed #include (write #include \"file.glsl\")",
                     display_name(path), line_no);
        ok = false;
        break;
      }
      char full[2048];
      snprintf(full, sizeof full, "%s/%s", dir, name);
      if (!lm_file_exists(full)) snprintf(full, sizeof full, "%s/%s", include_dir, name);
      if (!lm_file_exists(full)) {
        lm_error_set(err, "%s:%d: #include \"%s\": no such file (looked in %s and %s)",
                     display_name(path), line_no, name, display_name(dir), display_name(include_dir));
        ok = false;
        break;
      }
      ok = expand(src, full, include_dir, depth + 1, err);
      lm_buf_printf(&src->text, "#line %d %d\n", line_no + 1, id);
    } else if (is_version_line(p, len)) {
      lm_buf_append(&src->text, "// #version is set by the engine\n", -1);
    } else {
      lm_buf_append(&src->text, p, len);
      lm_buf_append(&src->text, "\n", 1);
      if (is_group_switch(p, len)) lm_buf_printf(&src->text, "#line %d %d\n", line_no + 1, id);
    }
    p += len + (nl ? 1 : 0);
  }
  free(text);
  return ok;
}

bool lm_shader_source_load(lm_shader_source *src, const char *path, const char *include_dir,
                           const char *defines, lm_error *err) {
  *src = (lm_shader_source){0};
  lm_buf_append(&src->text, "#version 450 core\n", -1);
  if (!append_defines(&src->text, defines, err)) {
    lm_error_prefix(err, "%s", display_name(path));
    lm_shader_source_free(src);
    return false;
  }
  if (!expand(src, path, include_dir, 0, err)) {
    lm_shader_source_free(src);
    return false;
  }
  return true;
}

void lm_shader_source_free(lm_shader_source *src) {
  lm_buf_free(&src->text);
  for (int i = 0; i < src->file_count; i++) free(src->files[i]);
  free(src->files);
  *src = (lm_shader_source){0};
}

/* "S:L(C): msg" (Mesa) or "S(L) : msg" (NVIDIA) -> file, line, rest. */
static bool parse_log_line(const char *s, int len, int *file, int *line, const char **rest) {
  char *end;
  long f = strtol(s, &end, 10);
  if (end == s || end - s >= len) return false;
  long l;
  if (*end == ':') {
    const char *q = end + 1;
    l = strtol(q, &end, 10);
    if (end == q) return false;
    if (*end == '(') end = strchr(end, ')') ? strchr(end, ')') + 1 : end;
  } else if (*end == '(') {
    const char *q = end + 1;
    l = strtol(q, &end, 10);
    if (end == q || *end != ')') return false;
    end++;
  } else {
    return false;
  }
  while (*end == ' ' || *end == ':') end++;
  *file = (int)f;
  *line = (int)l;
  *rest = end;
  return true;
}

void lm_shader_map_log(const lm_shader_source *src, const char *log, lm_buf *out) {
  for (const char *p = log; p && *p;) {
    const char *nl = strchr(p, '\n');
    int len = nl ? (int)(nl - p) : (int)strlen(p);
    int file, line;
    const char *rest;
    if (len > 0 && parse_log_line(p, len, &file, &line, &rest) && file >= 0 && file < src->file_count) {
      lm_buf_printf(out, "%s:%d: %.*s\n", display_name(src->files[file]), line,
                    (int)(p + len - rest), rest);
    } else if (len > 0) {
      lm_buf_printf(out, "%.*s\n", len, p);
    }
    p += len + (nl ? 1 : 0);
  }
}
