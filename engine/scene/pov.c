/* POV-Ray 3.7 export of one view (see pov.h for how each part matches). */
#include "scene/pov.h"

#include <cglm/cglm.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lm_pov_radiosity_defaults(lm_pov_radiosity *r) {
  *r = (lm_pov_radiosity){.count = 250, .error_bound = 0.25, .pretrace_start = 0.08,
                          .pretrace_end = 0.01, .recursion_limit = 2, .brightness = 1.0};
}

const char *lm_pov_radiosity_check(const lm_pov_radiosity *r) {
  /* POV-Ray 3.7's own limits: count up to 1600 directions, recursion 1..20,
   * pretrace sizes in (0, 1] with the end no larger than the start. */
  if (r->count < 1 || r->count > 1600) return "count (1..1600)";
  if (!(r->error_bound > 0) || !isfinite(r->error_bound)) return "error_bound (> 0)";
  if (!(r->pretrace_start > 0 && r->pretrace_start <= 1)) return "pretrace_start (0 < s <= 1)";
  if (!(r->pretrace_end > 0 && r->pretrace_end <= r->pretrace_start))
    return "pretrace_end (0 < e <= pretrace_start)";
  if (r->recursion_limit < 1 || r->recursion_limit > 20) return "recursion_limit (1..20)";
  if (!(r->brightness >= 0) || !isfinite(r->brightness)) return "brightness (>= 0)";
  return NULL;
}

typedef struct pov_ctx {
  const lm_pov_desc *desc;
  lm_buf *out, *warnings;
  lm_error *err;
  char nonfinite[160]; /* the first element that wrote Inf or NaN (POV-Ray cannot parse them) */
} pov_ctx;

/* Something the engine does that POV-Ray cannot: refused when strict, else a warning. */
static bool mismatch(pov_ctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static bool mismatch(pov_ctx *c, const char *fmt, ...) {
  char msg[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  if (c->desc->strict) {
    lm_error_set(c->err, "%s", msg);
    return false;
  }
  if (c->warnings) lm_buf_printf(c->warnings, "%s\n", msg);
  return true;
}

/* `what` names the element in the error should a number not be finite. */
static void put_vec(pov_ctx *c, const double v[3], const char *what) {
  if (!c->nonfinite[0] && !(isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2])))
    snprintf(c->nonfinite, sizeof c->nonfinite, "%s", what);
  lm_buf_printf(c->out, "<%.9g, %.9g, %.9g>", v[0], v[1], v[2]);
}

static double clamp01(double x) { return x > 0 ? (x < 1 ? x : 1) : 0; } /* NaN -> 0 */

/* World-space bounds of every mesh node (a unit box around the origin when
 * there is none), for placing parallel lights outside the scene. */
static void scene_bounds(const lm_scene *s, double center[3], double *radius) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->mesh < 0 || n->mesh >= s->mesh_count) continue;
    const lm_scene_mesh *m = &s->meshes[n->mesh];
    for (int v = 0; v < m->vertex_count; v++) {
      const float *p = m->vertices + (size_t)v * 8;
      for (int r = 0; r < 3; r++) {
        double w = n->world[r] * p[0] + n->world[4 + r] * p[1] + n->world[8 + r] * p[2] + n->world[12 + r];
        lo[r] = fmin(lo[r], w), hi[r] = fmax(hi[r], w);
      }
    }
  }
  if (!(lo[0] <= hi[0])) {
    for (int r = 0; r < 3; r++) lo[r] = -1, hi[r] = 1;
  }
  double d2 = 0;
  for (int r = 0; r < 3; r++) {
    center[r] = 0.5 * (lo[r] + hi[r]);
    d2 += (hi[r] - lo[r]) * (hi[r] - lo[r]);
  }
  *radius = 0.5 * sqrt(d2);
}

static void write_header(pov_ctx *c, const lm_scene *s) {
  const lm_pov_desc *d = c->desc;
  lm_buf *b = c->out;
  lm_buf_printf(b,
                "// Limn export of scene '%s', camera %d, for %dx%d (engine/scene/pov.h says how it matches).\n"
                "// Render linear OpenEXR, one sample a pixel as the engine does:\n"
                "//   povray -D -V +I<this file> +O<image>.exr +FE +W%d +H%d -A\n"
                "#version 3.7;\n\n"
                "global_settings {\n"
                "  assumed_gamma 1\n"
                "  max_trace_level 5\n",
                s->name, d->camera, d->width, d->height, d->width, d->height);
  if (d->radiosity) {
    const lm_pov_radiosity *r = &d->rad;
    lm_buf_printf(b,
                  "  radiosity {\n"
                  "    count %d\n"
                  "    error_bound %.9g\n"
                  "    pretrace_start %.9g\n"
                  "    pretrace_end %.9g\n"
                  "    recursion_limit %d\n"
                  "    brightness %.9g\n"
                  "  }\n",
                  r->count, r->error_bound, r->pretrace_start, r->pretrace_end, r->recursion_limit,
                  r->brightness);
  }
  lm_buf_printf(b, "}\n\nbackground { rgb 0 }\n\n");
  if (d->has_sky) {
    const lm_sky *k = &d->sky;
    float h[3], z[3];
    for (int i = 0; i < 3; i++) h[i] = k->intensity * k->horizon[i], z[i] = k->intensity * k->zenith[i];
    lm_buf_printf(b,
                  "// The sky (scene/sky.h): radiance horizon + (zenith - horizon) * max(y, 0).\n"
                  "sky_sphere {\n"
                  "  pigment { function { max(y, 0) }\n"
                  "    color_map { [0 rgb <%.9g, %.9g, %.9g>] [1 rgb <%.9g, %.9g, %.9g>] } }\n"
                  "}\n\n",
                  h[0], h[1], h[2], z[0], z[1], z[2]);
  }
}

/* The engine's own rays (lm_scene_frame_data): POV-Ray's ray for image
 * position (x, y) in [0, 1]^2, y down, is direction + (x - 1/2) right +
 * (1/2 - y) up; the engine's is frustum_o + u frustum_u + v frustum_v with
 * v up. Equal when direction = o + (u + v) / 2, right = u, up = v. */
static void write_camera(pov_ctx *c, const lm_scene *s) {
  lm_frame_data f;
  lm_scene_frame_data(s, c->desc->camera, c->desc->width, c->desc->height, &f);
  double loc[3], dir[3], right[3], up[3];
  for (int i = 0; i < 3; i++) {
    loc[i] = f.camera_pos[i];
    dir[i] = f.frustum_o[i] + 0.5 * (f.frustum_u[i] + f.frustum_v[i]);
    right[i] = f.frustum_u[i];
    up[i] = f.frustum_v[i];
  }
  const char *name = c->desc->camera < s->camera_count ? s->cameras[c->desc->camera].name : "default";
  char what[128];
  snprintf(what, sizeof what, "camera '%s'", name);
  lm_buf_printf(c->out, "// camera '%s'\ncamera {\n  perspective\n  location ", name);
  put_vec(c, loc, what);
  lm_buf_printf(c->out, "\n  direction ");
  put_vec(c, dir, what);
  lm_buf_printf(c->out, "\n  right ");
  put_vec(c, right, what);
  lm_buf_printf(c->out, "\n  up ");
  put_vec(c, up, what);
  lm_buf_printf(c->out, "\n}\n\n");
}

static bool write_light(pov_ctx *c, const lm_light *l, const lm_light_data *ld, const double center[3],
                        double radius) {
  lm_buf *b = c->out;
  double pos[3], dir[3], col[3];
  for (int i = 0; i < 3; i++) pos[i] = ld->position[i], dir[i] = ld->direction[i], col[i] = ld->color[i];
  int type = (int)lroundf(ld->position[3]);
  int falloff = (int)lroundf(ld->params[1]);
  /* Without shadows at all the meshes are no_shadow instead (write_mesh_node):
   * POV-Ray 3.7 drops a shadowless spotlight's cone, and lights everything. */
  bool shadowless = !l->casts_shadows;
  if (shadowless && type == LM_LIGHT_SPOT &&
      !mismatch(c, "light '%s': a spot that casts no shadows: POV-Ray 3.7 ignores the cone of a "
                   "shadowless spotlight", l->name))
    return false;
  bool fade = false;
  /* relative to the scene, so that every unit gets the same accuracy */
  double fade_distance = LM_POV_FADE_FRACTION * (radius > 0 && isfinite(radius) ? radius : 1.0);
  if (type != LM_LIGHT_DIRECTIONAL) {
    double range = ld->color[3];
    if (falloff == LM_FALLOFF_RANGE && range > 0) {
      /* No POV-Ray light fades to zero at a distance; the window is 1 to
       * within LM_POV_RANGE_EXACT wherever the scene's bounding sphere
       * reaches, or the light is refused. */
      double far = 0;
      for (int i = 0; i < 3; i++) far += (pos[i] - center[i]) * (pos[i] - center[i]);
      far = sqrt(far) + radius;
      double q = far / range, window = 1.0 - q * q * q * q;
      if (window < 1.0 - LM_POV_RANGE_EXACT &&
          !mismatch(c, "light '%s': range %.6g: the KHR_lights_punctual window clamp(1 - (d/range)^4, 0, 1) "
                       "falls to %.3g within the scene (which reaches %.6g from the light), and no POV-Ray "
                       "light fades to zero at a distance; drop the range or make it at least %.6g "
                       "(--approximate writes it without the window)",
                    l->name, range, window > 0 ? window : 0.0, far, far * pow(LM_POV_RANGE_EXACT, -0.25)))
        return false;
    }
    if (falloff == LM_FALLOFF_INVERSE_SQUARE || falloff == LM_FALLOFF_RANGE) {
      fade = true;
      for (int i = 0; i < 3; i++) col[i] /= 2.0 * fade_distance * fade_distance;
    } else if (falloff != LM_FALLOFF_NONE &&
               !mismatch(c, "light '%s': the window falloff saturate(1 - (d/r)^2) (seed 000 eq 16) has no "
                            "POV-Ray form; give the light falloff none or inverse-square "
                            "(--approximate writes it without falloff)", l->name)) {
      return false;
    }
  }
  char what[128];
  snprintf(what, sizeof what, "light '%s'", l->name);
  lm_buf_printf(b, "// light '%s'\nlight_source {\n  ", l->name);
  if (type == LM_LIGHT_DIRECTIONAL) {
    /* A parallel light's shadow rays end at the plane through its location:
     * put it well outside the scene. */
    double loc[3], at[3];
    for (int i = 0; i < 3; i++) {
      loc[i] = center[i] - dir[i] * (2.0 * radius + 1.0);
      at[i] = loc[i] + dir[i];
    }
    put_vec(c, loc, what);
    lm_buf_printf(b, "\n  color rgb ");
    put_vec(c, col, what);
    lm_buf_printf(b, "\n  parallel\n  point_at ");
    put_vec(c, at, what);
  } else {
    put_vec(c, pos, what);
    lm_buf_printf(b, "\n  color rgb ");
    put_vec(c, col, what);
    if (type == LM_LIGHT_SPOT) {
      /* POV-Ray: pow(cos, tightness) * cubic_spline(cos falloff, cos radius, cos),
       * the spline being smoothstep; tightness 0 leaves the smoothstep alone.
       * It only holds for cones under 90 degrees (POV-Ray drops cos <= 0 and
       * the spline when cos radius <= 0). */
      /* The engine only sees the cosines, so a negative angle acts as its size. */
      double inner = fabs(l->inner_cone), outer = fabs(l->outer_cone);
      if (!(outer < GLM_PI_2) &&
          !mismatch(c, "light '%s': spot cone of %.6g degrees: POV-Ray's spotlight only matches cones "
                       "under 90 degrees", l->name, glm_deg((float)outer)))
        return false;
      /* inner >= outer: the engine's smoothstep spans 1e-4 in cosine, a hard
       * edge at the outer cone, which is what radius = falloff gives. */
      if (inner > outer) inner = outer;
      double at[3];
      for (int i = 0; i < 3; i++) at[i] = pos[i] + dir[i];
      lm_buf_printf(b, "\n  spotlight\n  radius %.9g\n  falloff %.9g\n  tightness 0\n  point_at ",
                    glm_deg((float)inner), glm_deg((float)outer));
      put_vec(c, at, what);
    }
    if (fade) lm_buf_printf(b, "\n  fade_distance %.9g\n  fade_power 2", fade_distance);
  }
  lm_buf_printf(b, "%s\n}\n\n", shadowless ? "\n  shadowless" : "");
  return true;
}

/* The pbr technique's material as POV-Ray's closest finish (pov.h), with a
 * warning that says what is approximated. */
/* A material's pigment (pov.h): rgb, or rgbft for a blended one. */
static void put_pigment(pov_ctx *c, const lm_material_pbr *p, const double col[3]) {
  if (p->alpha_mode != LM_ALPHA_BLEND) {
    lm_buf_printf(c->out, "  pigment { rgb <%.9g, %.9g, %.9g> }\n", col[0], col[1], col[2]);
    return;
  }
  double a = clamp01(p->alpha);
  lm_buf_printf(c->out, "  pigment { rgbft <%.9g, %.9g, %.9g, %.9g, %.9g> }\n", col[0], col[1], col[2],
                a * clamp01(p->transmission), 1.0 - a);
}

/* Does a blended material absorb in its volume (KHR_materials_volume)? */
static bool absorbs(const lm_material_pbr *p) {
  return p->alpha_mode == LM_ALPHA_BLEND && p->transmission > 0 && p->thickness > 0 && p->attenuation_distance > 0;
}

/* The texture's closing brace, then the absorption (pov.h) as <id>_interior. */
static void end_material(pov_ctx *c, const lm_material_pbr *p, const char *id) {
  lm_buf_printf(c->out, "}\n\n");
  if (absorbs(p))
    lm_buf_printf(c->out, "#declare %s_interior = interior {\n  fade_power 1001 fade_distance %.9g "
                  "fade_color rgb <%.9g, %.9g, %.9g>\n}\n\n", id, p->attenuation_distance,
                  clamp01(p->attenuation_color[0]), clamp01(p->attenuation_color[1]), clamp01(p->attenuation_color[2]));
}

static void write_pbr_material(pov_ctx *c, const lm_material *m, const lm_material_pbr *p, const char *id) {
  double metal = clamp01(p->metallic), rough = p->roughness > 0.08 ? clamp01(p->roughness) : 0.08;
  double f0 = 0.04, r4 = rough * rough * rough * rough, s = 2.0 / r4 - 2.0;
  for (int i = 0; i < 3; i++) f0 = fmax(f0, 0.04 + (clamp01(m->color[i]) - 0.04) * metal);
  if (c->warnings)
    lm_buf_printf(c->warnings, "material '%s': metallic-roughness written as POV-Ray's closest finish (Blinn "
                  "specular of the matching exponent, no Fresnel rise or Smith shadowing, no textures)\n", m->name);
  lm_buf_printf(c->out,
                "// material '%s' (metallic %.3g, roughness %.3g: approximated)\n#declare %s = texture {\n",
                m->name, metal, rough, id);
  put_pigment(c, p, (double[3]){clamp01(m->color[0]), clamp01(m->color[1]), clamp01(m->color[2])});
  lm_buf_printf(c->out,
                "  finish { ambient 0 emission rgb <%.9g, %.9g, %.9g> diffuse %.9g brilliance 1 specular %.9g "
                "roughness %.9g metallic %.9g }\n",
                p->emissive[0], p->emissive[1], p->emissive[2], 1.0 - metal, f0 * (s + 2.0) / 8.0, 1.0 / fmax(s, 1.0),
                metal);
  end_material(c, p, id);
}

static bool write_material(pov_ctx *c, const lm_material *m, const lm_material_pbr *p, const char *id) {
  double col[3], kd = clamp01(m->kd), ks = clamp01(m->ks);
  bool clamped = kd != m->kd || ks != m->ks;
  for (int i = 0; i < 3; i++) {
    col[i] = clamp01(m->color[i]);
    clamped |= col[i] != m->color[i];
  }
  /* The G-buffer stores colour and k in [0, 1] (8 bits each): what it keeps is what we write. */
  if (clamped && !mismatch(c, "material '%s': colour, kd or ks outside [0, 1]; the engine clamps them "
                              "and so does the export", m->name))
    return false;
  double size = m->shininess >= 1 ? m->shininess : 1; /* the engine's max(shininess, 1) */
  double refl = clamp01(m->reflectivity);
  if (refl != m->reflectivity &&
      !mismatch(c, "material '%s': reflectivity outside [0, 1]; the export clamps it", m->name))
    return false;
  char reflection[64] = "";
  if (refl > 0) snprintf(reflection, sizeof reflection, " reflection %.9g", refl);
  lm_buf_printf(c->out,
                "// material '%s'\n#declare %s = texture {\n", m->name, id);
  put_pigment(c, p, col);
  lm_buf_printf(c->out, "  finish { ambient 0 emission 0 diffuse %.9g brilliance 1 phong %.9g phong_size %.9g%s }\n",
                kd, ks, size, reflection);
  end_material(c, p, id);
  return true;
}

static void material_id(const lm_scene *s, const lm_node *n, char *out, size_t cap) {
  if (n->material >= 0 && n->material < s->material_count) snprintf(out, cap, "limn_material_%d", n->material);
  else snprintf(out, cap, "limn_material_default");
}

/* One mesh2 in world space; false when an index is out of range. */
static bool write_mesh_node(pov_ctx *c, const lm_scene *s, const lm_node *n) {
  const lm_scene_mesh *m = &s->meshes[n->mesh];
  lm_buf *b = c->out;
  for (int i = 0; i < m->index_count; i++)
    if (m->indices[i] >= (uint32_t)m->vertex_count) {
      lm_error_set(c->err, "node '%s': mesh '%s': index %d is %u, past its %d vertices", n->name, m->name, i,
                   m->indices[i], m->vertex_count);
      return false;
    }
  mat4 w, inv;
  memcpy(w, n->world, sizeof w); /* aligned copy for cglm */
  glm_mat4_inv(w, inv);
  double *wp = lm_alloc(sizeof(double) * 3 * (size_t)(m->vertex_count > 0 ? m->vertex_count : 1));
  for (int v = 0; v < m->vertex_count; v++) {
    const float *p = m->vertices + (size_t)v * 8;
    for (int r = 0; r < 3; r++)
      wp[v * 3 + r] = w[0][r] * p[0] + w[1][r] * p[1] + w[2][r] * p[2] + w[3][r];
  }
  /* Zero-area triangles: POV-Ray drops them itself, and fails on a mesh with none left. */
  int tri = 0, total = m->index_count / 3;
  bool *keep = lm_alloc(sizeof(bool) * (size_t)(total > 0 ? total : 1));
  for (int t = 0; t < total; t++) {
    const double *a = wp + m->indices[t * 3] * 3, *bb = wp + m->indices[t * 3 + 1] * 3,
                 *cc = wp + m->indices[t * 3 + 2] * 3;
    double e1[3] = {bb[0] - a[0], bb[1] - a[1], bb[2] - a[2]}, e2[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
    double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2], z = e1[0] * e2[1] - e1[1] * e2[0];
    keep[t] = sqrt(x * x + y * y + z * z) > 1e-9;
    tri += keep[t];
  }
  if (tri > 0) {
    char id[64], what[160];
    snprintf(what, sizeof what, "node '%s'", n->name);
    material_id(s, n, id, sizeof id);
    lm_buf_printf(b, "// node '%s', mesh '%s'\nmesh2 {\n  vertex_vectors {\n    %d", n->name, m->name, m->vertex_count);
    for (int v = 0; v < m->vertex_count; v++) {
      lm_buf_printf(b, ",\n    ");
      put_vec(c, wp + v * 3, what);
    }
    lm_buf_printf(b, "\n  }\n  normal_vectors {\n    %d", m->vertex_count);
    for (int v = 0; v < m->vertex_count; v++) {
      const float *nn = m->vertices + (size_t)v * 8 + 3;
      double wn[3], len = 0;
      for (int r = 0; r < 3; r++) { /* inverse transpose: (inv^T)_{r,k} = inv[r][k] in cglm's columns */
        wn[r] = inv[r][0] * nn[0] + inv[r][1] * nn[1] + inv[r][2] * nn[2];
        len += wn[r] * wn[r];
      }
      len = sqrt(len);
      if (len > 1e-20 && isfinite(len)) {
        for (int r = 0; r < 3; r++) wn[r] /= len;
      } else { /* the engine's safe_normalize falls back to +Y */
        wn[0] = 0, wn[1] = 1, wn[2] = 0;
      }
      lm_buf_printf(b, ",\n    ");
      put_vec(c, wn, what);
    }
    lm_buf_printf(b, "\n  }\n  face_indices {\n    %d", tri);
    for (int t = 0; t < total; t++)
      if (keep[t])
        lm_buf_printf(b, ",\n    <%u, %u, %u>", m->indices[t * 3], m->indices[t * 3 + 1], m->indices[t * 3 + 2]);
    lm_material_pbr p = lm_scene_material_pbr(s, n->material, lm_scene_node_material(s, n));
    char interior[96] = "";
    if (absorbs(&p)) snprintf(interior, sizeof interior, "  interior { %s_interior }\n", id);
    lm_buf_printf(b, "\n  }\n  texture { %s }\n%s%s}\n\n", id, interior, c->desc->shadows ? "" : "  no_shadow\n");
  }
  free(keep);
  free(wp);
  return true;
}

bool lm_pov_export(const lm_scene *s, const lm_pov_desc *desc, lm_buf *out, lm_buf *warnings,
                   lm_error *err) {
  pov_ctx c = {.desc = desc, .out = out, .warnings = warnings, .err = err};
  if (desc->width < 1 || desc->height < 1) {
    lm_error_set(err, "output size %dx%d: both must be at least 1", desc->width, desc->height);
    return false;
  }
  if (desc->camera < 0 || (desc->camera > 0 && desc->camera >= s->camera_count)) {
    lm_error_set(err, "camera %d: scene '%s' has %d camera(s)", desc->camera, s->name, s->camera_count);
    return false;
  }
  if (!lm_scene_camera_check(s, desc->camera, err)) return false;
  const char *bad = desc->radiosity ? lm_pov_radiosity_check(&desc->rad) : NULL;
  if (bad) {
    lm_error_set(err, "radiosity setting out of range: %s", bad);
    return false;
  }
  write_header(&c, s);
  write_camera(&c, s);

  double center[3], radius;
  scene_bounds(s, center, &radius);
  lm_light_data *ld = lm_alloc(sizeof *ld * (size_t)(s->light_count > 0 ? s->light_count : 1));
  int n = lm_scene_light_data(s, ld, s->light_count);
  bool ok = true;
  for (int i = 0; i < n && ok; i++) ok = write_light(&c, &s->lights[i], &ld[i], center, radius);
  free(ld);

  /* Declare each material that a mesh node uses, once. */
  bool *declared = lm_alloc(sizeof(bool) * (size_t)(s->material_count + 1));
  for (int i = 0; i < s->node_count && ok; i++) {
    const lm_node *nd = &s->nodes[i];
    if (nd->mesh < 0 || nd->mesh >= s->mesh_count) continue;
    int slot = nd->material >= 0 && nd->material < s->material_count ? nd->material : s->material_count;
    if (declared[slot]) continue;
    declared[slot] = true;
    char id[64];
    material_id(s, nd, id, sizeof id);
    const lm_material *m = lm_scene_node_material(s, nd);
    lm_material_pbr p = lm_scene_material_pbr(s, nd->material, m);
    if (desc->pbr_materials) write_pbr_material(&c, m, &p, id);
    else ok = write_material(&c, m, &p, id);
  }
  free(declared);
  for (int i = 0; i < s->node_count && ok; i++) {
    const lm_node *nd = &s->nodes[i];
    if (nd->mesh >= 0 && nd->mesh < s->mesh_count) ok = write_mesh_node(&c, s, nd);
  }
  if (ok && c.nonfinite[0]) {
    lm_error_set(err, "%s: a coordinate or colour is not finite (Inf or NaN)", c.nonfinite);
    ok = false;
  }
  return ok;
}
