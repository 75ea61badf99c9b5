/* gen_scenes: writes the test scenes of data/scenes (GLB files, their camera
 * lists and the PNG textures they embed) and the reference set's scenes
 * under data/scenes/reference. Deterministic: no clock, no
 * libraries, a fixed pseudo-random sequence and fixed float formatting, so
 * that running it again gives the same bytes (tests/test_gen_scenes.sh
 * checks). Usage: gen_scenes OUTDIR
 * Each scene is a function of calls placing its materials, meshes, lights
 * and views: data written as code, so scenes read alike line by line. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define PI 3.14159265358979f

/* ---- growable byte buffers ------------------------------------------------ */
typedef struct buf {
  unsigned char *data;
  size_t len, cap;
} buf;

static void put(buf *b, const void *p, size_t n) {
  if (n == 0) return;
  if (b->len + n > b->cap) {
    b->cap = (b->len + n) * 2 + 256;
    b->data = realloc(b->data, b->cap);
    if (!b->data) abort();
  }
  memcpy(b->data + b->len, p, n);
  b->len += n;
}

__attribute__((format(printf, 2, 3))) static void putf(buf *b, const char *fmt, ...) {
  char tmp[4096];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
  va_end(ap);
  put(b, tmp, (size_t)n);
}

static void put_u32le(buf *b, uint32_t v) {
  unsigned char c[4] = {v & 255, (v >> 8) & 255, (v >> 16) & 255, v >> 24};
  put(b, c, 4);
}

static void put_u32be(buf *b, uint32_t v) {
  unsigned char c[4] = {v >> 24, (v >> 16) & 255, (v >> 8) & 255, v & 255};
  put(b, c, 4);
}

/* A fixed linear congruential sequence (same on every machine). */
static uint32_t rng_state = 12345;
static float rnd(void) {
  rng_state = rng_state * 1664525u + 1013904223u;
  return (float)(rng_state >> 8) / 16777216.0f;
}

/* ---- PNG: stored (uncompressed) deflate, so no zlib version matters ------- */
static uint32_t crc32_of(const unsigned char *p, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; i++) {
    c ^= p[i];
    for (int k = 0; k < 8; k++) c = c & 1 ? 0xedb88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xffffffffu;
}

static void png_chunk(buf *out, const char *type, const buf *body) {
  put_u32be(out, (uint32_t)body->len);
  buf t = {0};
  put(&t, type, 4);
  if (body->len) put(&t, body->data, body->len);
  put(out, t.data, t.len);
  put_u32be(out, crc32_of(t.data, t.len));
  free(t.data);
}

/* RGB8 pixels, rows top first. */
static void png_encode(buf *out, int w, int h, const unsigned char *rgb) {
  static const unsigned char sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  put(out, sig, 8);
  buf ihdr = {0};
  put_u32be(&ihdr, (uint32_t)w);
  put_u32be(&ihdr, (uint32_t)h);
  unsigned char rest[5] = {8, 2, 0, 0, 0}; /* 8 bit, RGB */
  put(&ihdr, rest, 5);
  png_chunk(out, "IHDR", &ihdr);
  buf raw = {0};
  for (int y = 0; y < h; y++) {
    unsigned char filter = 0;
    put(&raw, &filter, 1);
    put(&raw, rgb + (size_t)y * w * 3, (size_t)w * 3);
  }
  buf z = {0};
  unsigned char zh[2] = {0x78, 0x01};
  put(&z, zh, 2);
  uint32_t a = 1, b2 = 0;
  for (size_t i = 0; i < raw.len; i++) a = (a + raw.data[i]) % 65521, b2 = (b2 + a) % 65521;
  for (size_t at = 0; at < raw.len;) {
    size_t n = raw.len - at > 65535 ? 65535 : raw.len - at;
    unsigned char hd[5] = {at + n == raw.len, n & 255, n >> 8, ~n & 255, (~n >> 8) & 255};
    put(&z, hd, 5);
    put(&z, raw.data + at, n);
    at += n;
  }
  put_u32be(&z, (b2 << 16) | a);
  png_chunk(out, "IDAT", &z);
  buf none = {0};
  png_chunk(out, "IEND", &none);
  free(ihdr.data), free(raw.data), free(z.data);
}

/* ---- meshes ---------------------------------------------------------------- */
typedef struct mesh {
  float *v; /* position(3) normal(3) uv(2) */
  int nv, vcap;
  uint32_t *ix;
  int ni, icap;
} mesh;

static int vert(mesh *m, float x, float y, float z, float nx, float ny, float nz, float u, float v) {
  if (m->nv == m->vcap) m->vcap = m->vcap * 2 + 64, m->v = realloc(m->v, sizeof(float) * 8 * m->vcap);
  float *o = m->v + (size_t)m->nv * 8;
  o[0] = x, o[1] = y, o[2] = z, o[3] = nx, o[4] = ny, o[5] = nz, o[6] = u, o[7] = v;
  return m->nv++;
}

static void tri(mesh *m, int a, int b, int c) {
  if (m->ni + 3 > m->icap) m->icap = m->icap * 2 + 192, m->ix = realloc(m->ix, sizeof(uint32_t) * m->icap);
  m->ix[m->ni++] = (uint32_t)a, m->ix[m->ni++] = (uint32_t)b, m->ix[m->ni++] = (uint32_t)c;
}

static void cross(const float a[3], const float b[3], float o[3]) {
  o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}

static void normalize3(float v[3]) {
  float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (l > 1e-20f) v[0] /= l, v[1] /= l, v[2] /= l;
}

/* Quad from corner o along edges u and v (facing u x v); uv repeats us x vs times. */
static void quad(mesh *m, const float o[3], const float u[3], const float v[3], float us, float vs) {
  float n[3];
  cross(u, v, n);
  normalize3(n);
  int base = m->nv;
  for (int c = 0; c < 4; c++) {
    float a = (float)(c == 1 || c == 2), b = (float)(c >= 2);
    vert(m, o[0] + u[0] * a + v[0] * b, o[1] + u[1] * a + v[1] * b, o[2] + u[2] * a + v[2] * b, n[0], n[1],
         n[2], a * us, b * vs);
  }
  tri(m, base, base + 1, base + 2);
  tri(m, base, base + 2, base + 3);
}

/* Axis-aligned box centred at c with half sizes h, outward faces. */
static void box(mesh *m, float cx, float cy, float cz, float hx, float hy, float hz) {
  float x0 = cx - hx, x1 = cx + hx, y0 = cy - hy, y1 = cy + hy, z0 = cz - hz, z1 = cz + hz;
  float X = 2 * hx, Y = 2 * hy, Z = 2 * hz;
  quad(m, (float[]){x0, y0, z1}, (float[]){X, 0, 0}, (float[]){0, Y, 0}, 1, 1);  /* +z */
  quad(m, (float[]){x1, y0, z0}, (float[]){-X, 0, 0}, (float[]){0, Y, 0}, 1, 1); /* -z */
  quad(m, (float[]){x1, y0, z1}, (float[]){0, 0, -Z}, (float[]){0, Y, 0}, 1, 1); /* +x */
  quad(m, (float[]){x0, y0, z0}, (float[]){0, 0, Z}, (float[]){0, Y, 0}, 1, 1);  /* -x */
  quad(m, (float[]){x0, y1, z1}, (float[]){X, 0, 0}, (float[]){0, 0, -Z}, 1, 1); /* +y */
  quad(m, (float[]){x0, y0, z0}, (float[]){X, 0, 0}, (float[]){0, 0, Z}, 1, 1);  /* -y */
}

/* Cylinder along axis 'y' (or 'z' for wheels), radius r, from -h/2 to h/2, capped. */
static void cylinder(mesh *m, float r, float h, int seg, char axis) {
  for (int side = 0; side < 3; side++) {
    int centre = -1;
    if (side > 0) {
      float y = side == 1 ? h / 2 : -h / 2, ny = side == 1 ? 1.0f : -1.0f;
      centre = axis == 'y' ? vert(m, 0, y, 0, 0, ny, 0, 0.5f, 0.5f) : vert(m, 0, 0, y, 0, 0, ny, 0.5f, 0.5f);
    }
    int first = m->nv;
    for (int i = 0; i <= seg; i++) {
      float a = 2 * PI * (float)i / (float)seg, c = cosf(a), s = sinf(a);
      for (int k = 0; k < (side == 0 ? 2 : 1); k++) {
        float y = side == 0 ? (k ? h / 2 : -h / 2) : side == 1 ? h / 2 : -h / 2;
        float nx = side == 0 ? c : 0, ns = side == 0 ? s : 0, ny = side == 0 ? 0 : side == 1 ? 1.0f : -1.0f;
        if (axis == 'y') vert(m, r * c, y, r * s, nx, ny, ns, (float)i / (float)seg, (float)k);
        else vert(m, r * c, r * s, y, nx, ns, ny, (float)i / (float)seg, (float)k);
      }
    }
    for (int i = 0; i < seg; i++) {
      if (side == 0) {
        int a = first + i * 2;
        /* outward winding: (bottom i, top i, bottom i+1) seen from outside */
        if (axis == 'y') tri(m, a, a + 1, a + 3), tri(m, a, a + 3, a + 2);
        else tri(m, a, a + 2, a + 3), tri(m, a, a + 3, a + 1);
      } else {
        int a = first + i, b = first + i + 1;
        bool up = side == 1;
        if (axis == 'y') up ? tri(m, centre, b, a) : tri(m, centre, a, b);
        else up ? tri(m, centre, a, b) : tri(m, centre, b, a);
      }
    }
  }
}

static void cone(mesh *m, float r, float h, float y0, int seg) {
  float slope = r / h;
  int tip_first = m->nv;
  for (int i = 0; i < seg; i++) {
    float a = 2 * PI * ((float)i + 0.5f) / (float)seg;
    float n[3] = {cosf(a), slope, sinf(a)};
    normalize3(n);
    vert(m, 0, y0 + h, 0, n[0], n[1], n[2], 0.5f, 1);
  }
  int ring = m->nv;
  for (int i = 0; i <= seg; i++) {
    float a = 2 * PI * (float)i / (float)seg;
    float n[3] = {cosf(a), slope, sinf(a)};
    normalize3(n);
    vert(m, r * cosf(a), y0, r * sinf(a), n[0], n[1], n[2], (float)i / (float)seg, 0);
  }
  for (int i = 0; i < seg; i++) tri(m, ring + i, tip_first + i, ring + i + 1);
  int centre = vert(m, 0, y0, 0, 0, -1, 0, 0.5f, 0.5f);
  int bottom = m->nv;
  for (int i = 0; i <= seg; i++) {
    float a = 2 * PI * (float)i / (float)seg;
    vert(m, r * cosf(a), y0, r * sinf(a), 0, -1, 0, 0, 0);
  }
  for (int i = 0; i < seg; i++) tri(m, centre, bottom + i, bottom + i + 1);
}

static void sphere(mesh *m, float r, int seg, int rings) {
  int first = m->nv;
  for (int j = 0; j <= rings; j++) {
    float t = PI * (float)j / (float)rings;
    for (int i = 0; i <= seg; i++) {
      float p = 2 * PI * (float)i / (float)seg;
      float n[3] = {sinf(t) * cosf(p), cosf(t), sinf(t) * sinf(p)};
      vert(m, r * n[0], r * n[1], r * n[2], n[0], n[1], n[2], (float)i / (float)seg, (float)j / (float)rings);
    }
  }
  for (int j = 0; j < rings; j++)
    for (int i = 0; i < seg; i++) {
      int a = first + j * (seg + 1) + i, b = a + seg + 1;
      tri(m, a, a + 1, b + 1);
      tri(m, a, b + 1, b);
    }
}

static void mesh_free(mesh *m) { free(m->v), free(m->ix), memset(m, 0, sizeof *m); }

/* ---- the glTF document ---------------------------------------------------- */
typedef struct node {
  char name[64];
  int parent;
  float t[3], r[4], s[3];
  int mesh, camera, light, skin;
  int instances[3]; /* EXT_mesh_gpu_instancing's TRANSLATION, ROTATION, SCALE accessors; -1: none */
} node;

typedef struct doc {
  buf bin;
  buf views, accessors, meshes, materials, images, textures, cameras, lights, animations, skins;
  int view_count, accessor_count, mesh_count, material_count, image_count, camera_count, light_count;
  int animation_count, skin_count;
  node *nodes;
  int node_count, node_cap;
  buf cams; /* the camera list text */
} doc;

static void sep(buf *b, int count) {
  if (count) put(b, ",", 1);
}

static void align4(buf *b) {
  static const unsigned char zero[4] = {0};
  put(b, zero, (4 - b->len % 4) % 4);
}

static int add_view(doc *d, const void *data, size_t len, int target) {
  align4(&d->bin);
  size_t off = d->bin.len;
  put(&d->bin, data, len);
  sep(&d->views, d->view_count);
  putf(&d->views, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu", off, len);
  if (target) putf(&d->views, ",\"target\":%d", target);
  put(&d->views, "}", 1);
  return d->view_count++;
}

static int add_accessor(doc *d, int view, int ctype, int count, const char *type, const float *mn,
                        const float *mx) {
  sep(&d->accessors, d->accessor_count);
  putf(&d->accessors, "{\"bufferView\":%d,\"componentType\":%d,\"count\":%d,\"type\":\"%s\"", view, ctype,
       count, type);
  if (mn)
    putf(&d->accessors, ",\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]", mn[0], mn[1], mn[2], mx[0],
         mx[1], mx[2]);
  put(&d->accessors, "}", 1);
  return d->accessor_count++;
}

/* The primitive's JSON for one mesh part: attributes, indices, material;
 * joints and weights (4 a vertex) when skinned, else NULL. */
static void add_primitive(doc *d, buf *out, const mesh *m, int material, const uint8_t *joints,
                          const float *weights) {
  size_t nv = (size_t)m->nv;
  float *pos = malloc(nv * 12), *nrm = malloc(nv * 12), *uv = malloc(nv * 8);
  float mn[3] = {1e30f, 1e30f, 1e30f}, mx[3] = {-1e30f, -1e30f, -1e30f};
  for (size_t i = 0; i < nv; i++) {
    memcpy(pos + i * 3, m->v + i * 8, 12);
    memcpy(nrm + i * 3, m->v + i * 8 + 3, 12);
    memcpy(uv + i * 2, m->v + i * 8 + 6, 8);
    for (int k = 0; k < 3; k++) mn[k] = fminf(mn[k], pos[i * 3 + k]), mx[k] = fmaxf(mx[k], pos[i * 3 + k]);
  }
  int ap = add_accessor(d, add_view(d, pos, nv * 12, 34962), 5126, m->nv, "VEC3", mn, mx);
  int an = add_accessor(d, add_view(d, nrm, nv * 12, 34962), 5126, m->nv, "VEC3", NULL, NULL);
  int at = add_accessor(d, add_view(d, uv, nv * 8, 34962), 5126, m->nv, "VEC2", NULL, NULL);
  int ai;
  if (nv <= 65535) { /* u16 indices keep the files small */
    uint16_t *ix = malloc((size_t)m->ni * 2);
    for (int i = 0; i < m->ni; i++) ix[i] = (uint16_t)m->ix[i];
    ai = add_accessor(d, add_view(d, ix, (size_t)m->ni * 2, 34963), 5123, m->ni, "SCALAR", NULL, NULL);
    free(ix);
  } else {
    ai = add_accessor(d, add_view(d, m->ix, (size_t)m->ni * 4, 34963), 5125, m->ni, "SCALAR", NULL, NULL);
  }
  putf(out, "{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,\"TEXCOORD_0\":%d", ap, an, at);
  if (joints) {
    int aj = add_accessor(d, add_view(d, joints, nv * 4, 34962), 5121, m->nv, "VEC4", NULL, NULL);
    int aw = add_accessor(d, add_view(d, weights, nv * 16, 34962), 5126, m->nv, "VEC4", NULL, NULL);
    putf(out, ",\"JOINTS_0\":%d,\"WEIGHTS_0\":%d", aj, aw);
  }
  putf(out, "},\"indices\":%d,\"material\":%d}", ai, material);
  free(pos), free(nrm), free(uv);
}

/* A mesh of `n` parts, part i with materials[i]; skinned (joints and
 * weights of every part's vertices, parts in order) or not (NULL). */
static int add_skinned_mesh(doc *d, const char *name, mesh *parts, const int *materials, int n,
                            const uint8_t *joints, const float *weights) {
  sep(&d->meshes, d->mesh_count);
  putf(&d->meshes, "{\"name\":\"%s\",\"primitives\":[", name);
  for (int i = 0; i < n; i++) {
    if (i) put(&d->meshes, ",", 1);
    add_primitive(d, &d->meshes, &parts[i], materials[i], joints, weights);
    if (joints) joints += parts[i].nv * 4, weights += parts[i].nv * 4;
  }
  put(&d->meshes, "]}", 2);
  return d->mesh_count++;
}

static int add_mesh(doc *d, const char *name, mesh *parts, const int *materials, int n) {
  return add_skinned_mesh(d, name, parts, materials, n, NULL, NULL);
}

static int add_mesh1(doc *d, const char *name, mesh *m, int material) {
  int id = add_mesh(d, name, m, &material, 1);
  mesh_free(m);
  return id;
}

static int add_texture(doc *d, int w, int h, const unsigned char *rgb) {
  buf png = {0};
  png_encode(&png, w, h, rgb);
  int view = add_view(d, png.data, png.len, 0);
  free(png.data);
  sep(&d->images, d->image_count);
  putf(&d->images, "{\"bufferView\":%d,\"mimeType\":\"image/png\"}", view);
  sep(&d->textures, d->image_count);
  putf(&d->textures, "{\"source\":%d}", d->image_count);
  return d->image_count++;
}

/* texture -1: none. */
static int add_material(doc *d, const char *name, float r, float g, float b, float metallic, float rough,
                        int texture) {
  sep(&d->materials, d->material_count);
  putf(&d->materials,
       "{\"name\":\"%s\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[%.4g,%.4g,%.4g,1],"
       "\"metallicFactor\":%.4g,\"roughnessFactor\":%.4g",
       name, r, g, b, metallic, rough);
  if (texture >= 0) putf(&d->materials, ",\"baseColorTexture\":{\"index\":%d}", texture);
  put(&d->materials, "}}", 2);
  return d->material_count++;
}

static int add_node(doc *d, const char *name, int parent, float x, float y, float z) {
  if (d->node_count == d->node_cap)
    d->node_cap = d->node_cap * 2 + 64, d->nodes = realloc(d->nodes, sizeof *d->nodes * d->node_cap);
  node *n = &d->nodes[d->node_count];
  memset(n, 0, sizeof *n);
  snprintf(n->name, sizeof n->name, "%s", name);
  n->parent = parent;
  n->t[0] = x, n->t[1] = y, n->t[2] = z;
  n->r[3] = 1;
  n->s[0] = n->s[1] = n->s[2] = 1;
  n->mesh = n->camera = n->light = n->skin = -1;
  n->instances[0] = n->instances[1] = n->instances[2] = -1;
  return d->node_count++;
}

static int mesh_node(doc *d, const char *name, int parent, int mesh_id, float x, float y, float z,
                     float yaw_deg, float scale) {
  int i = add_node(d, name, parent, x, y, z);
  float a = yaw_deg * PI / 360.0f;
  d->nodes[i].r[1] = sinf(a), d->nodes[i].r[3] = cosf(a);
  d->nodes[i].s[0] = d->nodes[i].s[1] = d->nodes[i].s[2] = scale;
  d->nodes[i].mesh = mesh_id;
  return i;
}

/* Rotation whose -Z looks along dir (+Y up), as a quaternion. */
static void look_quat(const float dir_in[3], float q[4]) {
  float f[3] = {dir_in[0], dir_in[1], dir_in[2]}, up[3] = {0, 1, 0}, r[3], u[3];
  normalize3(f);
  if (fabsf(f[1]) > 0.999f) up[0] = 0, up[1] = 0, up[2] = -1;
  cross(f, up, r);
  normalize3(r);
  cross(r, f, u);
  float m00 = r[0], m11 = u[1], m22 = -f[2]; /* columns: r, u, -f */
  float tr = m00 + m11 + m22;
  if (tr > 0) {
    float s = sqrtf(tr + 1) * 2;
    q[3] = s / 4, q[0] = (u[2] + f[1]) / s, q[1] = (-f[0] - r[2]) / s, q[2] = (r[1] - u[0]) / s;
  } else if (m00 > m11 && m00 > m22) {
    float s = sqrtf(1 + m00 - m11 - m22) * 2;
    q[3] = (u[2] + f[1]) / s, q[0] = s / 4, q[1] = (u[0] + r[1]) / s, q[2] = (-f[0] + r[2]) / s;
  } else if (m11 > m22) {
    float s = sqrtf(1 + m11 - m00 - m22) * 2;
    q[3] = (-f[0] - r[2]) / s, q[0] = (u[0] + r[1]) / s, q[1] = s / 4, q[2] = (-f[1] + u[2]) / s;
  } else {
    float s = sqrtf(1 + m22 - m00 - m11) * 2;
    q[3] = (r[1] - u[0]) / s, q[0] = (-f[0] + r[2]) / s, q[1] = (-f[1] + u[2]) / s, q[2] = s / 4;
  }
}

/* Makes node n a glTF camera called `name`. */
static void camera(doc *d, int n, const char *name, float fov_deg, float zfar) {
  sep(&d->cameras, d->camera_count);
  putf(&d->cameras, "{\"name\":\"%s\",\"type\":\"perspective\",\"perspective\":{\"yfov\":%.6g,\"znear\":0.05,"
       "\"zfar\":%.6g}}", name, fov_deg * PI / 180.0f, zfar);
  d->nodes[n].camera = d->camera_count++;
}

/* A view: a glTF camera node (the first one is what `--scene FILE` shows) and a camera list line. */
static void view(doc *d, const char *name, float ex, float ey, float ez, float tx, float ty, float tz,
                 float fov_deg, float zfar) {
  int n = add_node(d, name, -1, ex, ey, ez);
  look_quat((float[]){tx - ex, ty - ey, tz - ez}, d->nodes[n].r);
  camera(d, n, name, fov_deg, zfar);
  putf(&d->cams, "%-10s %8.3f %8.3f %8.3f   %8.3f %8.3f %8.3f   %5.1f\n", name, ex, ey, ez, tx, ty, tz, fov_deg);
}

/* type: "point", "spot", "directional"; intensity in candela (point, spot) or
 * lux (directional), KHR_lights_punctual's units; range 0: none, so that the
 * light falls off as 1 / d^2 alone, which POV-Ray matches exactly. The
 * candela values below give about the light the scenes had under the seed's
 * window falloff at the surfaces each light faces (the floor below it):
 * old * (1 - (d/r)^2) * d^2 * 683 pi, engine/scene/gltf.h's exposure (the
 * Cornell box's less: its walls are near the light). */
static void light(doc *d, const char *name, const char *type, float x, float y, float z, const float dir[3],
                  float r, float g, float b, float intensity, float range) {
  int n = add_node(d, name, -1, x, y, z);
  if (dir) look_quat(dir, d->nodes[n].r);
  sep(&d->lights, d->light_count);
  putf(&d->lights, "{\"name\":\"%s\",\"type\":\"%s\",\"color\":[%.4g,%.4g,%.4g],\"intensity\":%.4g", name, type,
       r, g, b, intensity);
  if (range > 0) putf(&d->lights, ",\"range\":%.4g", range);
  if (!strcmp(type, "spot")) putf(&d->lights, ",\"spot\":{\"innerConeAngle\":0.5,\"outerConeAngle\":0.8}");
  put(&d->lights, "}", 1);
  d->nodes[n].light = d->light_count++;
}

/* ---- animation and skins ---------------------------------------------------- */
/* An animation being written: its channels' and samplers' JSON. */
typedef struct anim {
  buf channels, samplers;
  int count;
} anim;

/* A channel moving node's `path` (translation, rotation, scale) by `count`
 * keys at `times` (increasing; the input accessor's min and max are the
 * first and last) of `width` floats each, CUBICSPLINE's three a key
 * (in-tangent, value, out-tangent). */
static void channel(doc *d, anim *a, int node, const char *path, const char *interp, const float *times,
                    int count, const float *values, int width) {
  int view = add_view(d, times, (size_t)count * 4, 0);
  sep(&d->accessors, d->accessor_count);
  putf(&d->accessors, "{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"SCALAR\","
       "\"min\":[%.9g],\"max\":[%.9g]}", view, count, times[0], times[count - 1]);
  int input = d->accessor_count++;
  int per_key = !strcmp(interp, "CUBICSPLINE") ? 3 : 1;
  view = add_view(d, values, (size_t)count * per_key * width * 4, 0);
  int output = add_accessor(d, view, 5126, count * per_key, width == 4 ? "VEC4" : "VEC3", NULL, NULL);
  sep(&a->samplers, a->count);
  putf(&a->samplers, "{\"input\":%d,\"output\":%d,\"interpolation\":\"%s\"}", input, output, interp);
  sep(&a->channels, a->count);
  putf(&a->channels, "{\"sampler\":%d,\"target\":{\"node\":%d,\"path\":\"%s\"}}", a->count, node, path);
  a->count++;
}

static void add_animation(doc *d, const char *name, anim *a) {
  sep(&d->animations, d->animation_count++);
  putf(&d->animations, "{\"name\":\"%s\",\"channels\":[", name);
  put(&d->animations, a->channels.data, a->channels.len);
  putf(&d->animations, "],\"samplers\":[");
  put(&d->animations, a->samplers.data, a->samplers.len);
  put(&d->animations, "]}", 2);
  free(a->channels.data), free(a->samplers.data);
  memset(a, 0, sizeof *a);
}

/* The rotation by `deg` degrees about axis (x, y, z) (unit), x y z w. */
static void axis_quat(float x, float y, float z, float deg, float q[4]) {
  float h = deg * PI / 360.0f;
  q[0] = x * sinf(h), q[1] = y * sinf(h), q[2] = z * sinf(h), q[3] = cosf(h);
}

/* A skin of `n` joints (nodes) whose bind pose is a translation each
 * (their world positions `at`, 3 floats a joint). */
static int add_skin(doc *d, const int *joints, int n, const float *at) {
  float *ibm = calloc((size_t)n * 16, sizeof *ibm);
  for (int j = 0; j < n; j++) {
    float *m = ibm + j * 16;
    m[0] = m[5] = m[10] = m[15] = 1;
    m[12] = -at[j * 3], m[13] = -at[j * 3 + 1], m[14] = -at[j * 3 + 2];
  }
  int acc = add_accessor(d, add_view(d, ibm, (size_t)n * 64, 0), 5126, n, "MAT4", NULL, NULL);
  free(ibm);
  sep(&d->skins, d->skin_count);
  putf(&d->skins, "{\"inverseBindMatrices\":%d,\"skeleton\":%d,\"joints\":[", acc, joints[0]);
  for (int j = 0; j < n; j++) putf(&d->skins, j ? ",%d" : "%d", joints[j]);
  put(&d->skins, "]}", 2);
  return d->skin_count++;
}

static void write_file(const char *path, const void *data, size_t len) {
  FILE *f = fopen(path, "wb");
  if (!f || fwrite(data, 1, len, f) != len || fclose(f) != 0) {
    fprintf(stderr, "gen_scenes: cannot write %s\n", path);
    exit(1);
  }
}

static void finish(doc *d, const char *dir, const char *name) {
  buf j = {0};
  putf(&j, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"limn data/gen_scenes.c\"}");
  bool instanced = false;
  for (int i = 0; i < d->node_count; i++) instanced |= d->nodes[i].instances[0] >= 0;
  if (instanced) /* required: a reader without it would draw one copy of each mesh */
    putf(&j, ",\"extensionsUsed\":[%s\"EXT_mesh_gpu_instancing\"],\"extensionsRequired\":[\"EXT_mesh_gpu_instancing\"]",
         d->light_count ? "\"KHR_lights_punctual\"," : "");
  else if (d->light_count)
    putf(&j, ",\"extensionsUsed\":[\"KHR_lights_punctual\"]");
  putf(&j, ",\"scene\":0,\"scenes\":[{\"name\":\"%s\",\"nodes\":[", name);
  int first = 1;
  for (int i = 0; i < d->node_count; i++)
    if (d->nodes[i].parent < 0) putf(&j, first ? "%d" : ",%d", i), first = 0;
  put(&j, "]}],\"nodes\":[", 13);
  for (int i = 0; i < d->node_count; i++) {
    node *n = &d->nodes[i];
    putf(&j, "%s{\"name\":\"%s\"", i ? "," : "", n->name);
    if (n->t[0] || n->t[1] || n->t[2]) putf(&j, ",\"translation\":[%.6g,%.6g,%.6g]", n->t[0], n->t[1], n->t[2]);
    if (n->r[3] != 1) putf(&j, ",\"rotation\":[%.6g,%.6g,%.6g,%.6g]", n->r[0], n->r[1], n->r[2], n->r[3]);
    if (n->s[0] != 1 || n->s[1] != 1 || n->s[2] != 1) putf(&j, ",\"scale\":[%.6g,%.6g,%.6g]", n->s[0], n->s[1], n->s[2]);
    if (n->mesh >= 0) putf(&j, ",\"mesh\":%d", n->mesh);
    if (n->skin >= 0) putf(&j, ",\"skin\":%d", n->skin);
    if (n->camera >= 0) putf(&j, ",\"camera\":%d", n->camera);
    if (n->light >= 0) putf(&j, ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":%d}}", n->light);
    if (n->instances[0] >= 0)
      putf(&j, ",\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":{\"TRANSLATION\":%d,"
           "\"ROTATION\":%d,\"SCALE\":%d}}}", n->instances[0], n->instances[1], n->instances[2]);
    int kids = 0;
    for (int k = i + 1; k < d->node_count; k++)
      if (d->nodes[k].parent == i) putf(&j, kids++ ? ",%d" : ",\"children\":[%d", k);
    if (kids) put(&j, "]", 1);
    put(&j, "}", 1);
  }
  put(&j, "]", 1);
#define SECTION(key, b, count) \
  if (count) putf(&j, ",\"" key "\":["), put(&j, (b).data, (b).len), put(&j, "]", 1)
  SECTION("meshes", d->meshes, d->mesh_count);
  SECTION("materials", d->materials, d->material_count);
  SECTION("textures", d->textures, d->image_count);
  SECTION("images", d->images, d->image_count);
  SECTION("cameras", d->cameras, d->camera_count);
  SECTION("accessors", d->accessors, d->accessor_count);
  SECTION("bufferViews", d->views, d->view_count);
  SECTION("animations", d->animations, d->animation_count);
  SECTION("skins", d->skins, d->skin_count);
#undef SECTION
  if (d->light_count) {
    putf(&j, ",\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[");
    put(&j, d->lights.data, d->lights.len);
    put(&j, "]}}", 3);
  }
  align4(&d->bin);
  putf(&j, ",\"buffers\":[{\"byteLength\":%zu}]}", d->bin.len);
  while (j.len % 4) put(&j, " ", 1);

  buf glb = {0};
  put(&glb, "glTF", 4);
  put_u32le(&glb, 2);
  put_u32le(&glb, (uint32_t)(12 + 8 + j.len + 8 + d->bin.len));
  put_u32le(&glb, (uint32_t)j.len);
  put(&glb, "JSON", 4);
  put(&glb, j.data, j.len);
  put_u32le(&glb, (uint32_t)d->bin.len);
  put(&glb, "BIN\0", 4);
  put(&glb, d->bin.data, d->bin.len);

  char path[1024];
  snprintf(path, sizeof path, "%s/%s.glb", dir, name);
  write_file(path, glb.data, glb.len);
  buf cams = {0};
  if (d->cams.len > 0) { /* none: jobs take the file's cameras */
    putf(&cams, "# Views of %s.glb for capture jobs (written by data/gen_scenes.c).\n"
                "# name      eye (x y z)                  target (x y z)               fov_y (degrees)\n", name);
    put(&cams, d->cams.data, d->cams.len);
    snprintf(path, sizeof path, "%s/%s.cams", dir, name);
    write_file(path, cams.data, cams.len);
  }
  printf("%s: %zu bytes, %d nodes, %d meshes, %d textures\n", name, glb.len, d->node_count, d->mesh_count,
         d->image_count);
  free(j.data), free(glb.data), free(cams.data), free(d->bin.data), free(d->views.data);
  free(d->accessors.data), free(d->meshes.data), free(d->materials.data), free(d->images.data);
  free(d->textures.data), free(d->cameras.data), free(d->lights.data), free(d->nodes), free(d->cams.data);
  free(d->animations.data), free(d->skins.data);
  memset(d, 0, sizeof *d);
}

/* ---- procedural textures (RGB8, sRGB-encoded like any PNG) ---------------- */
static unsigned char *checker(int size, int cells, const unsigned char a[3], const unsigned char b[3]) {
  unsigned char *p = malloc((size_t)size * size * 3);
  for (int y = 0; y < size; y++)
    for (int x = 0; x < size; x++)
      memcpy(p + ((size_t)y * size + x) * 3, ((x * cells / size) + (y * cells / size)) % 2 ? a : b, 3);
  return p;
}

/* Planks: stripes of varying brown with dark seams and grain. */
static unsigned char *planks(int size) {
  unsigned char *p = malloc((size_t)size * size * 3);
  int rows = 8;
  float tone[8];
  for (int i = 0; i < rows; i++) tone[i] = 0.5f + 0.8f * rnd();
  for (int y = 0; y < size; y++)
    for (int x = 0; x < size; x++) {
      int row = y * rows / size;
      float seam = (y % (size / rows)) < 2 ? 0.3f : 1.0f;
      float grain = 0.85f + 0.15f * sinf((float)x * 0.9f + (float)row * 3.0f + sinf((float)y * 0.7f) * 2.0f);
      float k = tone[row] * seam * grain;
      unsigned char *o = p + ((size_t)y * size + x) * 3;
      o[0] = (unsigned char)fminf(255, 150 * k), o[1] = (unsigned char)fminf(255, 100 * k),
      o[2] = (unsigned char)fminf(255, 60 * k);
    }
  return p;
}

/* Blocks: large red bricks of varying tone with light mortar lines (bold
 * enough to survive a 96x72 capture). */
static unsigned char *bricks(int size) {
  unsigned char *p = malloc((size_t)size * size * 3);
  int bh = size / 4, bw = size / 2;
  for (int y = 0; y < size; y++)
    for (int x = 0; x < size; x++) {
      int row = y / bh, xo = (x + (row % 2) * bw / 2) % size;
      bool mortar = y % bh < 4 || xo % bw < 4;
      unsigned char *o = p + ((size_t)y * size + x) * 3;
      float v = 0.55f + 0.45f * (float)(((xo / bw) * 7 + row * 13) % 5) / 4.0f;
      if (mortar) o[0] = 210, o[1] = 205, o[2] = 195;
      else o[0] = (unsigned char)(170 * v), o[1] = (unsigned char)(60 * v), o[2] = (unsigned char)(40 * v);
    }
  return p;
}

/* ---- the scenes ------------------------------------------------------------- */
static const unsigned char WHITE8[3] = {230, 230, 230}, GREY8[3] = {60, 60, 70};

/* The Cornell box, its light and no views (cornell and turntable). */
static void cornell_box(doc *d) {
  int white = add_material(d, "white", 0.73f, 0.73f, 0.73f, 0, 1, -1);
  int red = add_material(d, "red", 0.63f, 0.065f, 0.05f, 0, 1, -1);
  int green = add_material(d, "green", 0.14f, 0.45f, 0.091f, 0, 1, -1);
  int boxm = add_material(d, "box", 0.73f, 0.73f, 0.73f, 0, 0.45f, -1);
  mesh m = {0};
  quad(&m, (float[]){-1, 0, 1}, (float[]){2, 0, 0}, (float[]){0, 0, -2}, 1, 1);   /* floor */
  quad(&m, (float[]){-1, 2, -1}, (float[]){2, 0, 0}, (float[]){0, 0, 2}, 1, 1);   /* ceiling */
  quad(&m, (float[]){-1, 0, -1}, (float[]){2, 0, 0}, (float[]){0, 2, 0}, 1, 1);   /* back */
  mesh_node(d, "walls", -1, add_mesh1(d, "walls", &m, white), 0, 0, 0, 0, 1);
  quad(&m, (float[]){-1, 0, 1}, (float[]){0, 0, -2}, (float[]){0, 2, 0}, 1, 1);
  mesh_node(d, "left", -1, add_mesh1(d, "left", &m, red), 0, 0, 0, 0, 1);
  quad(&m, (float[]){1, 0, -1}, (float[]){0, 0, 2}, (float[]){0, 2, 0}, 1, 1);
  mesh_node(d, "right", -1, add_mesh1(d, "right", &m, green), 0, 0, 0, 0, 1);
  box(&m, 0, 0.5f, 0, 0.5f, 0.5f, 0.5f);
  int cube = add_mesh1(d, "cube", &m, boxm);
  int s = mesh_node(d, "short_box", -1, cube, 0.35f, 0, 0.3f, -17, 1);
  d->nodes[s].s[0] = d->nodes[s].s[1] = d->nodes[s].s[2] = 0.6f;
  int t = mesh_node(d, "tall_box", -1, cube, -0.35f, 0, -0.35f, 17, 1);
  d->nodes[t].s[0] = 0.6f, d->nodes[t].s[1] = 1.2f, d->nodes[t].s[2] = 0.6f;
  light(d, "ceiling_light", "point", 0, 1.7f, 0, NULL, 1, 0.95f, 0.85f, 6000, 0);
}

static void cornell(const char *dir) {
  doc d = {0};
  cornell_box(&d);
  view(&d, "front", 0, 1, 3.4f, 0, 1, 0, 45, 20);
  view(&d, "left", -0.6f, 1.2f, 2.6f, 0.1f, 0.8f, 0, 50, 20);
  view(&d, "high", 0.3f, 1.8f, 2.2f, 0, 0.4f, 0, 55, 20);
  view(&d, "boxes", 0.2f, 0.7f, 1.6f, 0, 0.5f, 0, 40, 20);
  finish(&d, dir, "cornell");
}

/* A car-like object: a body and cabin, four wheels; one mesh, three primitives. */
static int car_mesh(doc *d, int paint, int glass, int tyre) {
  mesh parts[3] = {{0}};
  box(&parts[0], 0, 0.45f, 0, 1.0f, 0.25f, 0.45f);
  box(&parts[1], -0.1f, 0.9f, 0, 0.55f, 0.2f, 0.4f);
  for (int i = 0; i < 4; i++) {
    mesh w = {0};
    cylinder(&w, 0.22f, 0.16f, 16, 'z');
    float ox = i % 2 ? 0.62f : -0.62f, oz = i / 2 ? 0.42f : -0.42f;
    for (int v = 0; v < w.nv; v++) {
      float *p = w.v + v * 8;
      vert(&parts[2], p[0] + ox, p[1] + 0.22f, p[2] + oz, p[3], p[4], p[5], p[6], p[7]);
    }
    for (int k = 0; k < w.ni; k += 3) {
      int base = parts[2].nv - w.nv;
      tri(&parts[2], base + (int)w.ix[k], base + (int)w.ix[k + 1], base + (int)w.ix[k + 2]);
    }
    mesh_free(&w);
  }
  int mats[3] = {paint, glass, tyre};
  int id = add_mesh(d, "car", parts, mats, 3);
  for (int i = 0; i < 3; i++) mesh_free(&parts[i]);
  return id;
}

/* The cars' materials (the garage's and the night street's): three paints, glass, tyres. */
typedef struct car_paints { int paint[3], glass, tyre; } car_paints;

static car_paints car_materials(doc *d) {
  car_paints p; /* one statement each: the materials' order is the file's */
  p.paint[0] = add_material(d, "paint_blue", 0.1f, 0.2f, 0.7f, 0.3f, 0.35f, -1);
  p.paint[1] = add_material(d, "paint_white", 0.85f, 0.85f, 0.85f, 0.3f, 0.35f, -1);
  p.paint[2] = add_material(d, "paint_red", 0.7f, 0.08f, 0.06f, 0.3f, 0.35f, -1);
  p.glass = add_material(d, "glass", 0.15f, 0.2f, 0.25f, 0, 0.1f, -1);
  p.tyre = add_material(d, "tyre", 0.05f, 0.05f, 0.05f, 0, 0.9f, -1);
  return p;
}

static void primitives(const char *dir) {
  doc d = {0};
  unsigned char *tex = checker(64, 8, WHITE8, GREY8);
  int checker_tex = add_texture(&d, 64, 64, tex);
  free(tex);
  int ground = add_material(&d, "ground", 1, 1, 1, 0, 0.9f, checker_tex);
  int paint = add_material(&d, "paint", 0.8f, 0.1f, 0.08f, 0.3f, 0.35f, -1);
  int glass = add_material(&d, "glass", 0.15f, 0.2f, 0.25f, 0.0f, 0.1f, -1);
  int tyre = add_material(&d, "tyre", 0.05f, 0.05f, 0.05f, 0, 0.9f, -1);
  int blue = add_material(&d, "blue", 0.1f, 0.25f, 0.8f, 0, 0.5f, -1);
  int yellow = add_material(&d, "yellow", 0.9f, 0.75f, 0.1f, 0, 0.6f, -1);
  int green = add_material(&d, "green", 0.15f, 0.7f, 0.2f, 0, 0.7f, -1);
  int gold = add_material(&d, "gold", 1.0f, 0.77f, 0.34f, 1, 0.3f, -1);
  mesh m = {0};
  quad(&m, (float[]){-8, 0, 8}, (float[]){16, 0, 0}, (float[]){0, 0, -16}, 8, 8);
  mesh_node(&d, "ground", -1, add_mesh1(&d, "ground", &m, ground), 0, 0, 0, 0, 1);
  sphere(&m, 0.5f, 32, 16);
  mesh_node(&d, "sphere", -1, add_mesh1(&d, "sphere", &m, blue), -2.0f, 0.5f, 0.5f, 0, 1);
  box(&m, 0, 0.4f, 0, 0.4f, 0.4f, 0.4f);
  mesh_node(&d, "cube", -1, add_mesh1(&d, "cube", &m, yellow), 2.0f, 0, 0.8f, 30, 1);
  cylinder(&m, 0.35f, 1.2f, 24, 'y');
  mesh_node(&d, "cylinder", -1, add_mesh1(&d, "cylinder", &m, green), 1.2f, 0.6f, -1.6f, 0, 1);
  cone(&m, 0.45f, 1.0f, 0, 24);
  mesh_node(&d, "cone", -1, add_mesh1(&d, "cone", &m, gold), -1.5f, 0, -1.8f, 0, 1);
  /* The car: a parent node with the mesh, rotated; a child marks its roof. */
  int car = mesh_node(&d, "car", -1, car_mesh(&d, paint, glass, tyre), 0, 0, 0, 25, 1);
  sphere(&m, 0.08f, 12, 6);
  mesh_node(&d, "car_light", car, add_mesh1(&d, "beacon", &m, yellow), -0.1f, 1.15f, 0, 0, 1);
  light(&d, "sun", "directional", 0, 10, 0, (float[]){-0.4f, -1, -0.6f}, 1, 0.97f, 0.9f, 2575, 0);
  light(&d, "fill", "point", 2, 3, 3, NULL, 0.6f, 0.7f, 1, 36800, 0);
  view(&d, "front", 0, 2.2f, 6.5f, 0, 0.4f, 0, 45, 60);
  view(&d, "side", 6, 1.5f, 1, 0, 0.5f, 0, 45, 60);
  view(&d, "top", 0.5f, 8, 3, 0, 0, 0, 50, 60);
  view(&d, "car", 1.6f, 1.2f, 2.0f, 0, 0.6f, 0, 40, 60);
  view(&d, "low", -4, 0.4f, 4, 0, 0.6f, 0, 50, 60);
  finish(&d, dir, "primitives");
}

static void office(const char *dir) {
  doc d = {0};
  unsigned char *tex = planks(128);
  int wood_tex = add_texture(&d, 128, 128, tex);
  free(tex);
  int floor = add_material(&d, "floor", 1, 1, 1, 0, 0.6f, wood_tex);
  int wall = add_material(&d, "wall", 0.8f, 0.78f, 0.72f, 0, 1, -1);
  int desk = add_material(&d, "desk", 0.45f, 0.3f, 0.18f, 0, 0.5f, wood_tex);
  int metal = add_material(&d, "metal", 0.6f, 0.6f, 0.62f, 1, 0.35f, -1);
  int fabric = add_material(&d, "fabric", 0.15f, 0.25f, 0.45f, 0, 0.9f, -1);
  int screen = add_material(&d, "screen", 0.02f, 0.02f, 0.03f, 0, 0.2f, -1);
  int books[3] = {add_material(&d, "book_red", 0.6f, 0.1f, 0.1f, 0, 0.8f, -1),
                  add_material(&d, "book_green", 0.1f, 0.45f, 0.15f, 0, 0.8f, -1),
                  add_material(&d, "book_cream", 0.85f, 0.8f, 0.6f, 0, 0.8f, -1)};
  mesh m = {0};
  float W = 3, D = 3, H = 2.6f; /* room x in [-W, W], z in [-D, D] */
  quad(&m, (float[]){-W, 0, D}, (float[]){2 * W, 0, 0}, (float[]){0, 0, -2 * D}, 2, 2);
  mesh_node(&d, "floor", -1, add_mesh1(&d, "floor", &m, floor), 0, 0, 0, 0, 1);
  quad(&m, (float[]){-W, H, -D}, (float[]){2 * W, 0, 0}, (float[]){0, 0, 2 * D}, 1, 1);
  quad(&m, (float[]){-W, 0, -D}, (float[]){2 * W, 0, 0}, (float[]){0, H, 0}, 1, 1);
  quad(&m, (float[]){-W, 0, D}, (float[]){0, 0, -2 * D}, (float[]){0, H, 0}, 1, 1);
  quad(&m, (float[]){W, 0, -D}, (float[]){0, 0, 2 * D}, (float[]){0, H, 0}, 1, 1);
  quad(&m, (float[]){W, 0, D}, (float[]){-2 * W, 0, 0}, (float[]){0, H, 0}, 1, 1);
  mesh_node(&d, "walls", -1, add_mesh1(&d, "walls", &m, wall), 0, 0, 0, 0, 1);
  box(&m, 0, 0.74f, 0, 0.8f, 0.03f, 0.4f);
  int top = add_mesh1(&d, "desk_top", &m, desk);
  for (int i = 0; i < 4; i++) box(&m, i % 2 ? 0.75f : -0.75f, 0.36f, i / 2 ? 0.35f : -0.35f, 0.03f, 0.36f, 0.03f);
  int legs = add_mesh1(&d, "desk_legs", &m, metal);
  box(&m, 0, 0.45f, 0, 0.25f, 0.04f, 0.25f);
  box(&m, 0, 0.75f, -0.23f, 0.25f, 0.3f, 0.03f);
  int seat = add_mesh1(&d, "chair", &m, fabric);
  cylinder(&m, 0.03f, 0.42f, 8, 'y');
  int post = add_mesh1(&d, "chair_post", &m, metal);
  box(&m, 0, 0.2f, 0, 0.3f, 0.15f, 0.02f);
  int mon = add_mesh1(&d, "monitor", &m, screen);
  for (int k = 0; k < 4; k++) { /* four desks with chairs and monitors */
    float x = k % 2 ? 1.5f : -1.5f, z = k / 2 ? 1.2f : -1.2f;
    char nm[64];
    snprintf(nm, sizeof nm, "desk%d", k);
    int dk = mesh_node(&d, nm, -1, top, x, 0, z, 0, 1);
    snprintf(nm, sizeof nm, "desk%d_legs", k);
    mesh_node(&d, nm, dk, legs, 0, 0, 0, 0, 1);
    snprintf(nm, sizeof nm, "desk%d_monitor", k);
    mesh_node(&d, nm, dk, mon, 0, 0.77f, -0.25f, 0, 1);
    snprintf(nm, sizeof nm, "chair%d", k);
    int ch = mesh_node(&d, nm, -1, seat, x + 0.1f, 0, z + 0.7f, 180 + 10 * (float)k, 1);
    snprintf(nm, sizeof nm, "chair%d_post", k);
    mesh_node(&d, nm, ch, post, 0, 0.21f, 0, 0, 1);
  }
  /* A shelf of books on the back wall. */
  box(&m, 0, 0.9f, 0, 1.0f, 0.9f, 0.02f);
  box(&m, 0, 0.6f, 0.15f, 1.0f, 0.02f, 0.15f);
  box(&m, 0, 1.2f, 0.15f, 1.0f, 0.02f, 0.15f);
  int shelf = mesh_node(&d, "shelf", -1, add_mesh1(&d, "shelf", &m, desk), 0, 0, -D + 0.02f, 0, 1);
  for (int b = 0; b < 3; b++) {
    for (int i = 0; i < 24; i++) {
      float h = 0.18f + 0.08f * rnd(), x = -0.95f + (float)i * 0.08f;
      if (i % 3 != b) continue;
      box(&m, x, 0.62f + h / 2 + (i % 2 ? 0.6f : 0), 0.15f, 0.035f, h / 2, 0.1f);
    }
    char nm[32];
    snprintf(nm, sizeof nm, "books%d", b);
    mesh_node(&d, nm, shelf, add_mesh1(&d, nm, &m, books[b]), 0, 0, 0, 0, 1);
  }
  light(&d, "lamp_a", "point", -1.5f, 2.1f, 0, NULL, 1, 0.95f, 0.85f, 8700, 0);
  light(&d, "lamp_b", "point", 1.5f, 2.1f, 0, NULL, 1, 0.95f, 0.85f, 8700, 0);
  light(&d, "window", "directional", 0, 2, 0, (float[]){0.3f, -0.8f, -0.5f}, 0.9f, 0.95f, 1, 644, 0);
  view(&d, "door", 0, 1.6f, 2.9f, 0, 0.8f, -1, 60, 30);
  view(&d, "corner", -2.8f, 2.2f, 2.8f, 0.5f, 0.5f, -0.5f, 60, 30);
  view(&d, "desk", 1.4f, 1.2f, 2.3f, 1.5f, 0.7f, 1.0f, 50, 30);
  view(&d, "shelf", 0.3f, 1.3f, -0.5f, 0, 0.9f, -3, 55, 30);
  finish(&d, dir, "office");
}

static void garage(const char *dir) {
  doc d = {0};
  unsigned char *tex = bricks(128);
  int brick_tex = add_texture(&d, 128, 128, tex);
  free(tex);
  int concrete = add_material(&d, "concrete", 0.5f, 0.5f, 0.5f, 0, 0.9f, -1);
  int brick = add_material(&d, "brick", 1, 1, 1, 0, 0.9f, brick_tex);
  int pillar = add_material(&d, "pillar", 0.7f, 0.7f, 0.65f, 0, 0.8f, -1);
  int stripe = add_material(&d, "stripe", 0.9f, 0.8f, 0.1f, 0, 0.7f, -1);
  car_paints paints = car_materials(&d);
  float W = 4, L = 20, H = 3; /* corridor x in [-W, W], z in [-L, 0] */
  mesh m = {0};
  quad(&m, (float[]){-W, 0, 0}, (float[]){2 * W, 0, 0}, (float[]){0, 0, -L}, 1, 1);
  quad(&m, (float[]){-W, H, -L}, (float[]){2 * W, 0, 0}, (float[]){0, 0, L}, 1, 1);
  mesh_node(&d, "slabs", -1, add_mesh1(&d, "slabs", &m, concrete), 0, 0, 0, 0, 1);
  quad(&m, (float[]){-W, 0, 0}, (float[]){0, 0, -L}, (float[]){0, H, 0}, 10, 1);
  quad(&m, (float[]){W, 0, -L}, (float[]){0, 0, L}, (float[]){0, H, 0}, 10, 1);
  quad(&m, (float[]){-W, 0, -L}, (float[]){2 * W, 0, 0}, (float[]){0, H, 0}, 4, 1);
  mesh_node(&d, "walls", -1, add_mesh1(&d, "walls", &m, brick), 0, 0, 0, 0, 1);
  for (int i = 0; i < 8; i++) box(&m, 0, 0.002f, -1.25f - 2.5f * (float)i, 0.05f, 0.002f, 0.6f);
  mesh_node(&d, "stripes", -1, add_mesh1(&d, "stripes", &m, stripe), 0, 0, 0, 0, 1);
  box(&m, 0, H / 2, 0, 0.2f, H / 2, 0.2f);
  int col = add_mesh1(&d, "pillar", &m, pillar);
  int cars[3];
  for (int k = 0; k < 3; k++) cars[k] = car_mesh(&d, paints.paint[k], paints.glass, paints.tyre);
  for (int i = 0; i < 5; i++) {
    char nm[32];
    float z = -2 - 4 * (float)i;
    snprintf(nm, sizeof nm, "pillar_l%d", i);
    mesh_node(&d, nm, -1, col, -1.8f, 0, z, 0, 1);
    snprintf(nm, sizeof nm, "pillar_r%d", i);
    mesh_node(&d, nm, -1, col, 1.8f, 0, z, 0, 1);
  }
  for (int i = 0; i < 6; i++) { /* parked cars along both walls, nose in */
    char nm[32];
    snprintf(nm, sizeof nm, "car%d", i);
    float z = -4 - 3 * (float)i;
    mesh_node(&d, nm, -1, cars[i % 3], i % 2 ? 2.9f : -2.9f, 0, z, i % 2 ? 0 : 180, 1);
  }
  for (int i = 0; i < 4; i++) {
    char nm[32];
    snprintf(nm, sizeof nm, "spot%d", i);
    light(&d, nm, "spot", 0, H - 0.1f, -2.5f - 5 * (float)i, (float[]){0, -1, 0.0001f}, 1, 0.9f, 0.75f, 22400, 0);
  }
  for (int i = 0; i < 3; i++) { /* wall washers, so the brick shows */
    char nm[32];
    snprintf(nm, sizeof nm, "wash%d", i);
    light(&d, nm, "point", i % 2 ? 2.8f : -2.8f, 2.6f, -3 - 6 * (float)i, NULL, 1, 0.85f, 0.7f, 13000, 0);
  }
  view(&d, "entrance", 0, 1.6f, -0.5f, 0, 1.2f, -20, 60, 40);
  view(&d, "cars", -0.5f, 1.8f, -6, 3, 0.6f, -9, 55, 40);
  view(&d, "end", 1, 2.2f, -19, -1, 0.8f, -8, 55, 40);
  view(&d, "low", -1, 0.5f, -3, 2.5f, 0.5f, -8, 60, 40);
  finish(&d, dir, "garage");
}

static float height(float x, float z) {
  return 2.5f * sinf(x * 0.08f) * cosf(z * 0.07f) + 1.2f * sinf(x * 0.23f + z * 0.17f) +
         0.4f * cosf(x * 0.5f - z * 0.41f);
}

static void outdoor(const char *dir) {
  doc d = {0};
  int grass = add_material(&d, "grass", 0.3f, 0.5f, 0.18f, 0, 0.95f, -1);
  int bark = add_material(&d, "bark", 0.35f, 0.22f, 0.12f, 0, 0.9f, -1);
  int leaves = add_material(&d, "leaves", 0.12f, 0.4f, 0.12f, 0, 0.8f, -1);
  int rock = add_material(&d, "rock", 0.5f, 0.48f, 0.45f, 0, 0.8f, -1);
  /* Terrain: a 180 x 180 grid (64.8k triangles) over 160 m, normals from the height field. */
  int N = 180;
  float S = 160, step = S / (float)N;
  mesh m = {0};
  for (int j = 0; j <= N; j++)
    for (int i = 0; i <= N; i++) {
      float x = -S / 2 + (float)i * step, z = -S / 2 + (float)j * step, e = 0.5f;
      float n[3] = {height(x - e, z) - height(x + e, z), 2 * e, height(x, z - e) - height(x, z + e)};
      normalize3(n);
      vert(&m, x, height(x, z), z, n[0], n[1], n[2], (float)i / 8, (float)j / 8);
    }
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++) {
      int a = j * (N + 1) + i, b = a + N + 1;
      tri(&m, a, b, a + 1);
      tri(&m, a + 1, b, b + 1);
    }
  mesh_node(&d, "terrain", -1, add_mesh1(&d, "terrain", &m, grass), 0, 0, 0, 0, 1);
  /* One tree mesh (trunk + two crowns, 200 triangles), placed 2000 times by node instancing. */
  mesh parts[2] = {{0}};
  cylinder(&parts[0], 0.15f, 1.6f, 10, 'y');
  for (int v = 0; v < parts[0].nv; v++) parts[0].v[v * 8 + 1] += 0.8f;
  cone(&parts[1], 1.1f, 2.2f, 1.2f, 20);
  cone(&parts[1], 0.8f, 1.8f, 2.4f, 20);
  int tm[2] = {bark, leaves};
  int tree = add_mesh(&d, "tree", parts, tm, 2);
  mesh_free(&parts[0]), mesh_free(&parts[1]);
  sphere(&m, 1, 10, 6);
  int boulder = add_mesh1(&d, "boulder", &m, rock);
  int forest = add_node(&d, "forest", -1, 0, 0, 0);
  for (int k = 0; k < 2000; k++) {
    float x = (rnd() - 0.5f) * S * 0.9f, z = (rnd() - 0.5f) * S * 0.9f;
    char nm[32];
    snprintf(nm, sizeof nm, "tree%d", k);
    mesh_node(&d, nm, forest, tree, x, height(x, z) - 0.1f, z, rnd() * 360, 0.7f + 0.8f * rnd());
  }
  for (int k = 0; k < 200; k++) {
    float x = (rnd() - 0.5f) * S * 0.9f, z = (rnd() - 0.5f) * S * 0.9f;
    char nm[32];
    snprintf(nm, sizeof nm, "boulder%d", k);
    int b = mesh_node(&d, nm, forest, boulder, x, height(x, z), z, rnd() * 360, 1);
    float s = 0.3f + 0.6f * rnd();
    d.nodes[b].s[0] = s * 1.4f, d.nodes[b].s[1] = s * 0.7f, d.nodes[b].s[2] = s;
  }
  light(&d, "sun", "directional", 0, 50, 0, (float[]){-0.5f, -0.7f, -0.3f}, 1, 0.95f, 0.85f, 2789, 0);
  light(&d, "sky", "directional", 0, 50, 0, (float[]){0.3f, -1, 0.4f}, 0.4f, 0.5f, 0.7f, 751, 0);
  view(&d, "overview", 0, 40, 85, 0, 0, 0, 60, 400);
  view(&d, "valley", -60, 12, 60, 10, 0, -10, 70, 400);
  view(&d, "ground", 5, 4, 20, 0, 2, 0, 60, 400);
  view(&d, "above", 0, 120, 1, 0, 0, 0, 60, 400);
  finish(&d, dir, "outdoor");
}

/* ---- the reference set (data/jobs/reference.lua) ---------------------------
 * Scenes where indirect light is a large share of the image, lit only by
 * lights that limn export-pov matches exactly (directional lights), so that
 * POV-Ray's radiosity gives each view's reference. No ambient term: the job
 * sets ambient = 0. Written under OUTDIR/reference/. Sun intensities are
 * lux: SUN * 683 pi is SUN in the engine's units (engine/scene/gltf.h). */
#define LUX (683 * PI)

/* A wall in the plane x = x0 facing +x (sign 1) or -x (sign -1), z in [z0, z1], y in [y0, y1]. */
static void wall_x(mesh *m, float x0, float sign, float z0, float z1, float y0, float y1) {
  if (sign > 0) quad(m, (float[]){x0, y0, z1}, (float[]){0, 0, z0 - z1}, (float[]){0, y1 - y0, 0}, 1, 1);
  else quad(m, (float[]){x0, y0, z0}, (float[]){0, 0, z1 - z0}, (float[]){0, y1 - y0, 0}, 1, 1);
}

/* A wall in the plane z = z0 facing +z (sign 1) or -z (sign -1), x in [x0, x1], y in [y0, y1]. */
static void wall_z(mesh *m, float z0, float sign, float x0, float x1, float y0, float y1) {
  if (sign > 0) quad(m, (float[]){x0, y0, z0}, (float[]){x1 - x0, 0, 0}, (float[]){0, y1 - y0, 0}, 1, 1);
  else quad(m, (float[]){x1, y0, z0}, (float[]){x0 - x1, 0, 0}, (float[]){0, y1 - y0, 0}, 1, 1);
}

/* A floor (facing up, at y) or a ceiling (facing down) over x in [x0, x1], z in [z0, z1]. */
static void slab(mesh *m, float y, bool up, float x0, float x1, float z0, float z1) {
  if (up) quad(m, (float[]){x0, y, z1}, (float[]){x1 - x0, 0, 0}, (float[]){0, 0, z0 - z1}, 1, 1);
  else quad(m, (float[]){x0, y, z0}, (float[]){x1 - x0, 0, 0}, (float[]){0, 0, z1 - z0}, 1, 1);
}

static int diffuse(doc *d, const char *name, float r, float g, float b) {
  return add_material(d, name, r, g, b, 0, 1, -1);
}

/* A closed room, 4 x 2.5 x 4, lit only by a sun through a window in its
 * left wall: a bright patch on the floor, everything else bounce light. */
static void ref_room(const char *dir) {
  doc d = {0};
  int wall = diffuse(&d, "plaster", 0.8f, 0.78f, 0.74f), floor = diffuse(&d, "floor", 0.6f, 0.42f, 0.28f);
  int ceiling = diffuse(&d, "ceiling", 0.85f, 0.85f, 0.85f), sofa = diffuse(&d, "sofa", 0.2f, 0.3f, 0.65f);
  int chest = diffuse(&d, "chest", 0.75f, 0.45f, 0.12f), shelf = diffuse(&d, "shelf", 0.25f, 0.55f, 0.3f);
  float W = 2, H = 2.5f, D = 2; /* x in [-W, W], z in [-D, D] */
  float wz0 = -0.9f, wz1 = 0.9f, wy0 = 0.8f, wy1 = 2.1f; /* the window in the x = -W wall */
  mesh m = {0};
  slab(&m, 0, true, -W, W, -D, D);
  mesh_node(&d, "floor", -1, add_mesh1(&d, "floor", &m, floor), 0, 0, 0, 0, 1);
  slab(&m, H, false, -W, W, -D, D);
  mesh_node(&d, "ceiling", -1, add_mesh1(&d, "ceiling", &m, ceiling), 0, 0, 0, 0, 1);
  wall_x(&m, -W, 1, -D, D, 0, wy0);      /* under the window */
  wall_x(&m, -W, 1, -D, D, wy1, H);      /* over it */
  wall_x(&m, -W, 1, -D, wz0, wy0, wy1);  /* beside it */
  wall_x(&m, -W, 1, wz1, D, wy0, wy1);
  wall_x(&m, W, -1, -D, D, 0, H);
  wall_z(&m, -D, 1, -W, W, 0, H);
  wall_z(&m, D, -1, -W, W, 0, H);
  mesh_node(&d, "walls", -1, add_mesh1(&d, "walls", &m, wall), 0, 0, 0, 0, 1);
  box(&m, 0.3f, 0.25f, -1.55f, 0.9f, 0.25f, 0.4f);
  box(&m, 0.3f, 0.6f, -1.88f, 0.9f, 0.35f, 0.08f);
  mesh_node(&d, "sofa", -1, add_mesh1(&d, "sofa", &m, sofa), 0, 0, 0, 0, 1);
  box(&m, 0.4f, 0.3f, 0.5f, 0.35f, 0.3f, 0.3f);
  mesh_node(&d, "chest", -1, add_mesh1(&d, "chest", &m, chest), 0, 0, 0, 0, 1);
  box(&m, 1.8f, 0.9f, 1.2f, 0.2f, 0.9f, 0.6f);
  mesh_node(&d, "shelf", -1, add_mesh1(&d, "shelf", &m, shelf), 0, 0, 0, 0, 1);
  light(&d, "sun", "directional", -6, 5, 0, (float[]){1, -0.7f, 0.25f}, 1, 0.96f, 0.9f, 3 * LUX, 0);
  view(&d, "window", 1.2f, 1.5f, 1.8f, -1.2f, 0.8f, -0.4f, 60, 20);
  view(&d, "back", -1.6f, 1.4f, 1.5f, 0.6f, 0.9f, -1.2f, 60, 20);
  view(&d, "ceiling", 1.5f, 0.4f, -1.5f, -0.5f, 2.3f, 0.8f, 65, 20);
  view(&d, "corner", -1.2f, 1.6f, -1.2f, 1.5f, 1.0f, 1.5f, 60, 20);
  finish(&d, dir, "room");
}

/* A street of coloured walls open to a black sky: the sun lights the right
 * wall and a strip of road; the left wall and the rest of the road are in
 * shade and see the sunlit wall. */
static void ref_street(const char *dir) {
  doc d = {0};
  int road = diffuse(&d, "road", 0.5f, 0.5f, 0.5f), left = diffuse(&d, "terracotta", 0.75f, 0.4f, 0.25f);
  int right = diffuse(&d, "ochre", 0.85f, 0.75f, 0.4f), crate = diffuse(&d, "crate", 0.3f, 0.45f, 0.7f);
  int bench = diffuse(&d, "bench", 0.8f, 0.8f, 0.8f);
  float W = 3, L = 24, H = 4; /* x in [-W, W], z in [-L, 0] */
  mesh m = {0};
  slab(&m, 0, true, -W, W, -L, 0);
  mesh_node(&d, "road", -1, add_mesh1(&d, "road", &m, road), 0, 0, 0, 0, 1);
  wall_x(&m, -W, 1, -L, 0, 0, H);
  mesh_node(&d, "left", -1, add_mesh1(&d, "left", &m, left), 0, 0, 0, 0, 1);
  wall_x(&m, W, -1, -L, 0, 0, H);
  wall_z(&m, -L, 1, -W, W, 0, H);
  mesh_node(&d, "right", -1, add_mesh1(&d, "right", &m, right), 0, 0, 0, 0, 1);
  box(&m, -2.3f, 0.4f, -6, 0.4f, 0.4f, 0.4f);
  box(&m, 2.2f, 0.5f, -11, 0.5f, 0.5f, 0.6f);
  box(&m, -2.5f, 0.3f, -14, 0.3f, 0.3f, 0.3f);
  mesh_node(&d, "crates", -1, add_mesh1(&d, "crates", &m, crate), 0, 0, 0, 0, 1);
  box(&m, -2.6f, 0.25f, -9, 0.25f, 0.25f, 1.2f);
  mesh_node(&d, "bench", -1, add_mesh1(&d, "bench", &m, bench), 0, 0, 0, 0, 1);
  light(&d, "sun", "directional", 0, 20, 0, (float[]){0.6f, -0.8f, -0.25f}, 1, 0.96f, 0.9f, 2 * LUX, 0);
  view(&d, "along", 0, 1.7f, 1.5f, 0, 1.2f, -12, 60, 60);
  view(&d, "shade", 1.5f, 1.6f, -4, -3, 1.4f, -9, 60, 60);
  view(&d, "sunny", -1.5f, 1.6f, -5, 3, 1.6f, -10, 60, 60);
  view(&d, "end", 1, 2.5f, -14, -0.5f, 1.0f, -24, 60, 60);
  finish(&d, dir, "street");
}

/* Coloured blocks on a bright ground under a low sun and a black sky. */
static void ref_blocks(const char *dir) {
  doc d = {0};
  int ground = diffuse(&d, "ground", 0.75f, 0.75f, 0.72f), red = diffuse(&d, "red", 0.75f, 0.12f, 0.1f);
  int blue = diffuse(&d, "blue", 0.12f, 0.25f, 0.75f), yellow = diffuse(&d, "yellow", 0.85f, 0.7f, 0.15f);
  int green = diffuse(&d, "green", 0.15f, 0.6f, 0.2f);
  mesh m = {0};
  slab(&m, 0, true, -8, 8, -8, 8);
  mesh_node(&d, "ground", -1, add_mesh1(&d, "ground", &m, ground), 0, 0, 0, 0, 1);
  box(&m, -1.2f, 0.6f, 0, 0.6f, 0.6f, 0.6f);
  mesh_node(&d, "red", -1, add_mesh1(&d, "red", &m, red), 0, 0, 0, 0, 1);
  box(&m, 0, 1.2f, -1.5f, 0.5f, 1.2f, 0.5f);
  mesh_node(&d, "blue", -1, add_mesh1(&d, "blue", &m, blue), 0, 0, 0, 0, 1);
  sphere(&m, 0.55f, 24, 12);
  mesh_node(&d, "yellow", -1, add_mesh1(&d, "yellow", &m, yellow), 1.0f, 0.55f, 0.4f, 0, 1);
  box(&m, 0.2f, 0.35f, 1.5f, 1.4f, 0.35f, 0.3f);
  mesh_node(&d, "green", -1, add_mesh1(&d, "green", &m, green), 0, 0, 0, 0, 1);
  light(&d, "sun", "directional", 0, 20, 0, (float[]){-0.7f, -0.55f, -0.45f}, 1, 0.96f, 0.9f, 2 * LUX, 0);
  view(&d, "front", 0.5f, 2.2f, 5.5f, 0, 0.6f, 0, 45, 60);
  view(&d, "shaded", -4, 1.6f, -3.5f, 0, 0.6f, 0, 45, 60);
  view(&d, "low", 3.5f, 0.6f, 2.5f, -0.5f, 0.7f, -0.5f, 55, 60);
  finish(&d, dir, "blocks");
}

/* ---- held-out scenes (data/jobs/holdout.lua) --------------------------------
 * Two scenes of kinds the reference set lacks, written after the GI
 * techniques' defaults were chosen and never tuned against: they tell how the
 * figures hold on scenes the project has not seen. Written under
 * OUTDIR/holdout/. */

/* A loft, 6 x 3 x 5, lit by a sun through a skylight and an open door: a
 * patch of sun on the table and the floor, an alcove behind a partition and
 * the ceiling lit by bounce light only. Its shell is of boxes T thick that
 * overlap at the corners, so that no shadow leaks along an edge. */
static void holdout_loft(const char *dir) {
  doc d = {0};
  int wall = diffuse(&d, "limewash", 0.82f, 0.8f, 0.75f), floor = diffuse(&d, "oak", 0.55f, 0.38f, 0.22f);
  int ceiling = diffuse(&d, "ceiling", 0.88f, 0.88f, 0.86f), table = diffuse(&d, "table", 0.7f, 0.25f, 0.15f);
  int cabinet = diffuse(&d, "cabinet", 0.2f, 0.5f, 0.45f), rug = diffuse(&d, "rug", 0.75f, 0.65f, 0.2f);
  int partition = diffuse(&d, "partition", 0.3f, 0.35f, 0.7f);
  float W = 3, H = 3, D = 2.5f, T = 0.2f;               /* inside: x in [-W, W], z in [-D, D] */
  float sx0 = -0.6f, sx1 = 0.6f, sz0 = 0, sz1 = 1.2f;   /* the skylight in the ceiling */
  float dx0 = -2.2f, dx1 = -1.2f, dy1 = 2.2f;           /* the door in the z = D wall */
  float X = W + T, Z = D + T;                           /* outside */
  mesh m = {0};
  box(&m, 0, -T / 2, 0, X, T / 2, Z);
  mesh_node(&d, "floor", -1, add_mesh1(&d, "floor", &m, floor), 0, 0, 0, 0, 1);
  box(&m, 0, H + T / 2, (sz0 - Z) / 2, X, T / 2, (sz0 + Z) / 2);
  box(&m, 0, H + T / 2, (sz1 + Z) / 2, X, T / 2, (Z - sz1) / 2);
  box(&m, (sx0 - X) / 2, H + T / 2, (sz0 + sz1) / 2, (sx0 + X) / 2, T / 2, (sz1 - sz0) / 2);
  box(&m, (sx1 + X) / 2, H + T / 2, (sz0 + sz1) / 2, (X - sx1) / 2, T / 2, (sz1 - sz0) / 2);
  mesh_node(&d, "ceiling", -1, add_mesh1(&d, "ceiling", &m, ceiling), 0, 0, 0, 0, 1);
  box(&m, -W - T / 2, H / 2, 0, T / 2, H / 2, Z);
  box(&m, W + T / 2, H / 2, 0, T / 2, H / 2, Z);
  box(&m, 0, H / 2, -D - T / 2, X, H / 2, T / 2);
  box(&m, (dx0 - X) / 2, H / 2, D + T / 2, (dx0 + X) / 2, H / 2, T / 2); /* beside the door */
  box(&m, (dx1 + X) / 2, H / 2, D + T / 2, (X - dx1) / 2, H / 2, T / 2);
  box(&m, (dx0 + dx1) / 2, (dy1 + H) / 2, D + T / 2, (dx1 - dx0) / 2, (H - dy1) / 2, T / 2); /* over it */
  mesh_node(&d, "walls", -1, add_mesh1(&d, "walls", &m, wall), 0, 0, 0, 0, 1);
  box(&m, 2.4f, 1.1f, -0.45f, 0.6f, 1.1f, 0.05f); /* the alcove's partition, x > 1.8, z < -0.5 */
  mesh_node(&d, "partition", -1, add_mesh1(&d, "partition", &m, partition), 0, 0, 0, 0, 1);
  box(&m, -1.0f, 0.74f, -1.2f, 0.7f, 0.03f, 0.45f);
  box(&m, -1.0f, 0.36f, -1.2f, 0.1f, 0.35f, 0.1f);
  mesh_node(&d, "table", -1, add_mesh1(&d, "table", &m, table), 0, 0, 0, 0, 1);
  box(&m, -2.65f, 0.9f, -1.6f, 0.3f, 0.9f, 0.6f);
  box(&m, 2.6f, 0.45f, -2.1f, 0.35f, 0.45f, 0.35f); /* in the alcove */
  mesh_node(&d, "cabinets", -1, add_mesh1(&d, "cabinets", &m, cabinet), 0, 0, 0, 0, 1);
  box(&m, 0.2f, 0.01f, 0.9f, 1.0f, 0.01f, 0.7f);
  mesh_node(&d, "rug", -1, add_mesh1(&d, "rug", &m, rug), 0, 0, 0, 0, 1);
  light(&d, "sun", "directional", 0, 10, 0, (float[]){-0.3f, -0.8f, -0.5f}, 1, 0.95f, 0.88f, 3 * LUX, 0);
  view(&d, "entry", -1.7f, 1.6f, 2.1f, 0.5f, 1.0f, -1.5f, 65, 20);
  view(&d, "up", -1.5f, 0.5f, 1.5f, 0.8f, 3.0f, -1.0f, 65, 20);
  view(&d, "alcove", 0.5f, 1.5f, 1.8f, 2.6f, 1.0f, -2.0f, 60, 20);
  view(&d, "back", 2.5f, 1.7f, 2.2f, -1.5f, 0.8f, -1.5f, 65, 20);
  finish(&d, dir, "loft");
}

/* A courtyard under a low sun behind its back building (jobs add the sky):
 * the back facade and a portico in shade, lit by the sunlit side building,
 * the ground and the sky; a mirror-like steel sphere, a brushed steel bench
 * and a copper door for glossy indirect light (materials = pbr). */
static void holdout_yard(const char *dir) {
  doc d = {0};
  int ground = diffuse(&d, "paving", 0.6f, 0.58f, 0.54f), back = diffuse(&d, "stucco", 0.85f, 0.82f, 0.75f);
  int side = diffuse(&d, "brick", 0.7f, 0.35f, 0.22f), stone = diffuse(&d, "stone", 0.75f, 0.72f, 0.65f);
  int planter = diffuse(&d, "planter", 0.2f, 0.45f, 0.25f);
  int steel = add_material(&d, "steel", 0.9f, 0.9f, 0.92f, 1, 0.05f, -1);
  int brushed = add_material(&d, "brushed", 0.7f, 0.7f, 0.72f, 1, 0.35f, -1);
  int copper = add_material(&d, "copper", 0.95f, 0.64f, 0.54f, 1, 0.2f, -1);
  mesh m = {0};
  slab(&m, 0, true, -20, 20, -20, 20);
  mesh_node(&d, "ground", -1, add_mesh1(&d, "ground", &m, ground), 0, 0, 0, 0, 1);
  box(&m, 0, 3, -8, 8, 3, 3);       /* back building: its +z facade at z = -5 */
  mesh_node(&d, "back", -1, add_mesh1(&d, "back", &m, back), 0, 0, 0, 0, 1);
  box(&m, -7, 2.5f, -1, 2, 2.5f, 5); /* side building: its +x facade at x = -5 */
  mesh_node(&d, "side", -1, add_mesh1(&d, "side", &m, side), 0, 0, 0, 0, 1);
  box(&m, 0, 3.1f, -4, 4, 0.1f, 1);  /* the portico's roof on four pillars */
  for (int k = 0; k < 4; k++) box(&m, -3.7f + 2.47f * (float)k, 1.5f, -3.2f, 0.15f, 1.5f, 0.15f);
  box(&m, 1.5f, 0.15f, -0.5f, 0.6f, 0.15f, 0.6f); /* the sphere's plinth */
  mesh_node(&d, "stone", -1, add_mesh1(&d, "stone", &m, stone), 0, 0, 0, 0, 1);
  box(&m, 5, 0.4f, -2, 0.6f, 0.4f, 2);
  mesh_node(&d, "planter", -1, add_mesh1(&d, "planter", &m, planter), 0, 0, 0, 0, 1);
  sphere(&m, 0.8f, 48, 24);
  mesh_node(&d, "sphere", -1, add_mesh1(&d, "sphere", &m, steel), 1.5f, 1.1f, -0.5f, 0, 1);
  box(&m, -2.5f, 0.25f, 1.5f, 1.2f, 0.25f, 0.3f);
  mesh_node(&d, "bench", -1, add_mesh1(&d, "bench", &m, brushed), 0, 0, 0, 0, 1);
  box(&m, 2.5f, 1.2f, -4.97f, 0.6f, 1.2f, 0.03f);
  mesh_node(&d, "door", -1, add_mesh1(&d, "door", &m, copper), 0, 0, 0, 0, 1);
  light(&d, "sun", "directional", 0, 20, 0, (float[]){-0.55f, -0.6f, 0.58f}, 1, 0.95f, 0.86f, 3 * LUX, 0);
  view(&d, "court", 0.5f, 1.7f, 9, 0, 1.5f, -4, 60, 80);
  view(&d, "portico", -2.8f, 1.5f, -0.5f, 0.5f, 1.4f, -5, 65, 80);
  view(&d, "sphere", 3.8f, 1.4f, 2.5f, 1.5f, 1.0f, -0.5f, 45, 80);
  view(&d, "facade", 3.5f, 1.6f, 3, -1.5f, 2.2f, -5, 60, 80);
  finish(&d, dir, "yard");
}

/* A street at night: 16 lamps with a range (KHR_lights_punctual's), each
 * casting shadows, along 80 m between blocks of houses, under a dim moon.
 * Lamps far down the street cover few pixels: their shadow tiles are small
 * (engine/shadow's screen coverage), and light culling lists each lamp only
 * where its range reaches. */
static void night(const char *dir) {
  doc d = {0};
  int asphalt = add_material(&d, "asphalt", 0.12f, 0.12f, 0.13f, 0, 0.9f, -1);
  int paving = add_material(&d, "paving", 0.45f, 0.43f, 0.4f, 0, 0.85f, -1);
  int plaster = add_material(&d, "plaster", 0.7f, 0.62f, 0.5f, 0, 0.9f, -1);
  int iron = add_material(&d, "iron", 0.2f, 0.2f, 0.22f, 0, 0.6f, -1);
  car_paints paints = car_materials(&d);
  float L = 80; /* the street runs from z = 0 to -L */
  mesh m = {0};
  quad(&m, (float[]){-4, 0, 0}, (float[]){8, 0, 0}, (float[]){0, 0, -L}, 4, 40);
  mesh_node(&d, "road", -1, add_mesh1(&d, "road", &m, asphalt), 0, 0, 0, 0, 1);
  box(&m, -5.5f, 0.075f, -L / 2, 1.5f, 0.075f, L / 2);
  box(&m, 5.5f, 0.075f, -L / 2, 1.5f, 0.075f, L / 2);
  mesh_node(&d, "sidewalks", -1, add_mesh1(&d, "sidewalks", &m, paving), 0, 0, 0, 0, 1);
  for (int i = 0; i < 10; i++) /* houses of 6 to 14 m, 8 m wide, both sides */
    for (int side = 0; side < 2; side++) {
      float h = 6 + (float)((i * 7 + side * 3) % 5) * 2, x = side ? 11 : -11;
      box(&m, x, h / 2, -4 - 8 * (float)i, 4, h / 2, 3.9f);
    }
  mesh_node(&d, "houses", -1, add_mesh1(&d, "houses", &m, plaster), 0, 0, 0, 0, 1);
  mesh parts[1] = {{0}};
  cylinder(&parts[0], 0.08f, 5, 8, 'y');
  for (int v = 0; v < parts[0].nv; v++) parts[0].v[v * 8 + 1] += 2.5f;
  box(&parts[0], 0.35f, 5.0f, 0, 0.45f, 0.06f, 0.12f);
  int post = add_mesh(&d, "lamp_post", parts, &iron, 1);
  mesh_free(&parts[0]);
  for (int i = 0; i < 8; i++)
    for (int side = 0; side < 2; side++) {
      char nm[32];
      float x = side ? 5.2f : -5.2f, z = -5 - 10 * (float)i - (side ? 5 : 0);
      snprintf(nm, sizeof nm, "post%d%c", i, side ? 'r' : 'l');
      mesh_node(&d, nm, -1, post, x, 0.15f, z, side ? 180 : 0, 1);
      snprintf(nm, sizeof nm, "lamp%d%c", i, side ? 'r' : 'l');
      light(&d, nm, "point", side ? x - 0.5f : x + 0.5f, 4.85f, z, NULL, 1, 0.8f, 0.55f, 40000, 14);
    }
  int cars[3];
  for (int k = 0; k < 3; k++) cars[k] = car_mesh(&d, paints.paint[k], paints.glass, paints.tyre);
  for (int i = 0; i < 7; i++) { /* parked along both kerbs */
    char nm[32];
    snprintf(nm, sizeof nm, "car%d", i);
    mesh_node(&d, nm, -1, cars[i % 3], i % 2 ? 3.1f : -3.1f, 0, -9 - 10 * (float)i, i % 2 ? 90 : -90, 1);
  }
  light(&d, "moon", "directional", 0, 30, 0, (float[]){0.3f, -0.8f, 0.5f}, 0.6f, 0.7f, 1, 40, 0);
  view(&d, "street", 0.5f, 1.7f, 2, -0.5f, 1.6f, -40, 60, 150);
  view(&d, "kerb", 4.2f, 1.6f, -22, -1.5f, 1.0f, -34, 60, 150);
  view(&d, "above", -2, 22, -20, 0.5f, 0, -42, 55, 150);
  view(&d, "far", 0, 1.7f, -78, 0, 2.5f, -20, 50, 150);
  finish(&d, dir, "night");
}

/* ---- scenes that move (data/jobs/motion.lua) ---------------------------------
 * glTF animations: LINEAR and CUBICSPLINE channels, a skin; each a few
 * hundred triangles. Loaded by tests/test_scenes_gen.sh's checks. */

/* The Cornell box seen from a camera that orbits it once in 4 s: a rotation
 * channel (LINEAR, a key every quarter turn) on a pivot at the box's centre,
 * the camera its child 3.4 in front. No camera list: a job over it renders
 * the file's own cameras, the orbit first. */
static void turntable(const char *dir) {
  doc d = {0};
  cornell_box(&d);
  int pivot = add_node(&d, "pivot", -1, 0, 1, 0);
  camera(&d, add_node(&d, "orbit", pivot, 0, 0, 3.4f), "orbit", 45, 20);
  view(&d, "front", 0, 1, 3.4f, 0, 1, 0, 45, 20);
  d.cams.len = 0; /* the front view stays a glTF camera, not a list line */
  float times[5], q[5][4];
  for (int k = 0; k < 5; k++) times[k] = (float)k, axis_quat(0, 1, 0, 90.0f * (float)k, q[k]);
  anim a = {0};
  channel(&d, &a, pivot, "rotation", "LINEAR", times, 5, q[0], 4);
  add_animation(&d, "orbit", &a);
  finish(&d, dir, "turntable");
}

/* A room, 4 x 2.5 x 4, with a doorway in its left wall (x = -2) and a door
 * that swings open 90 degrees into the room about its hinge from 0.5 s to
 * 1.5 s (CUBICSPLINE with zero tangents: it eases in and out), letting in a
 * sun it shut out; a dim lamp lights the room before. */
static void door(const char *dir) {
  doc d = {0};
  int wall = diffuse(&d, "plaster", 0.8f, 0.78f, 0.74f), floor = diffuse(&d, "floor", 0.6f, 0.42f, 0.28f);
  int ceiling = diffuse(&d, "ceiling", 0.85f, 0.85f, 0.85f), wood = diffuse(&d, "door", 0.45f, 0.25f, 0.12f);
  float W = 2, H = 2.5f, D = 2, z0 = -0.5f, z1 = 0.5f, top = 2; /* the doorway: z in [z0, z1], y below top */
  mesh m = {0};
  slab(&m, 0, true, -W, W, -D, D);
  mesh_node(&d, "floor", -1, add_mesh1(&d, "floor", &m, floor), 0, 0, 0, 0, 1);
  slab(&m, H, false, -W, W, -D, D);
  mesh_node(&d, "ceiling", -1, add_mesh1(&d, "ceiling", &m, ceiling), 0, 0, 0, 0, 1);
  wall_x(&m, -W, 1, -D, z0, 0, H); /* beside the doorway */
  wall_x(&m, -W, 1, z1, D, 0, H);
  wall_x(&m, -W, 1, z0, z1, top, H); /* over it */
  wall_x(&m, W, -1, -D, D, 0, H);
  wall_z(&m, -D, 1, -W, W, 0, H);
  wall_z(&m, D, -1, -W, W, 0, H);
  mesh_node(&d, "walls", -1, add_mesh1(&d, "walls", &m, wall), 0, 0, 0, 0, 1);
  /* 1 wide, 2 high, 6 cm thick, its hinge edge on the hinge node's y axis. */
  box(&m, 0.03f, top / 2, (z1 - z0) / 2, 0.03f, top / 2, (z1 - z0) / 2);
  int hinge = add_node(&d, "hinge", -1, -W, 0, z0);
  mesh_node(&d, "door", hinge, add_mesh1(&d, "door", &m, wood), 0, 0, 0, 0, 1);
  light(&d, "sun", "directional", -6, 4, 0, (float[]){1, -0.45f, 0.15f}, 1, 0.96f, 0.9f, 3 * LUX, 0);
  light(&d, "lamp", "point", 0.5f, 2.3f, 0.5f, NULL, 1, 0.9f, 0.8f, 800, 0);
  view(&d, "inside", 1.6f, 1.5f, 1.6f, -1.5f, 0.7f, -0.3f, 60, 20);
  float times[2] = {0.5f, 1.5f}, keys[2][3][4] = {{{0}}};
  axis_quat(0, 1, 0, 0, keys[0][1]);
  axis_quat(0, 1, 0, 90, keys[1][1]);
  anim a = {0};
  channel(&d, &a, hinge, "rotation", "CUBICSPLINE", times, 2, keys[0][0], 4);
  add_animation(&d, "open", &a);
  finish(&d, dir, "door");
}

/* A skinned tube on a floor under a lamp: radius 0.2, 2 high, 13 rings of 16
 * sides (a cap on top) about two joints, `base` on the floor and `bend` 1 up;
 * vertices from 0.75 to 1.25 high blend the two so that the bend stays round.
 * `bend` turns 90 degrees about z over 2 s (LINEAR, keys at 0, 1, 2 s). */
static void bending_tube(const char *dir) {
  enum { RINGS = 12, SIDES = 16 };
  doc d = {0};
  int floor = diffuse(&d, "floor", 0.7f, 0.7f, 0.68f), paint = diffuse(&d, "tube", 0.2f, 0.45f, 0.8f);
  mesh m = {0};
  slab(&m, 0, true, -4, 4, -4, 4);
  mesh_node(&d, "floor", -1, add_mesh1(&d, "floor", &m, floor), 0, 0, 0, 0, 1);
  float R = 0.2f, L = 2;
  for (int j = 0; j <= RINGS; j++)
    for (int i = 0; i <= SIDES; i++) {
      float a = 2 * PI * (float)i / SIDES, c = cosf(a), s = sinf(a);
      vert(&m, R * c, L * (float)j / RINGS, R * s, c, 0, s, (float)i / SIDES, (float)j / RINGS);
    }
  for (int j = 0; j < RINGS; j++)
    for (int i = 0; i < SIDES; i++) {
      int a = j * (SIDES + 1) + i, b = a + SIDES + 1;
      tri(&m, a, b, a + 1), tri(&m, a + 1, b, b + 1);
    }
  int centre = vert(&m, 0, L, 0, 0, 1, 0, 0.5f, 0.5f), rim = m.nv;
  for (int i = 0; i <= SIDES; i++) {
    float a = 2 * PI * (float)i / SIDES;
    vert(&m, R * cosf(a), L, R * sinf(a), 0, 1, 0, 0.5f + 0.5f * cosf(a), 0.5f + 0.5f * sinf(a));
  }
  for (int i = 0; i < SIDES; i++) tri(&m, centre, rim + i + 1, rim + i);
  uint8_t *joints = calloc((size_t)m.nv * 4, 1);
  float *weights = calloc((size_t)m.nv * 4, sizeof *weights);
  for (int v = 0; v < m.nv; v++) {
    float w = fminf(1, fmaxf(0, (m.v[v * 8 + 1] - 0.75f) / 0.5f)); /* bend's share */
    joints[v * 4 + 1] = w > 0; /* an unused influence names joint 0 */
    weights[v * 4] = 1 - w, weights[v * 4 + 1] = w;
  }
  int base = add_node(&d, "base", -1, 0, 0, 0), bend = add_node(&d, "bend", base, 0, 1, 0);
  int skin = add_skin(&d, (int[]){base, bend}, 2, (float[]){0, 0, 0, 0, 1, 0});
  int tube = mesh_node(&d, "tube", -1, add_skinned_mesh(&d, "tube", &m, &paint, 1, joints, weights), 0, 0, 0, 0, 1);
  d.nodes[tube].skin = skin;
  mesh_free(&m), free(joints), free(weights);
  light(&d, "lamp", "point", 1.5f, 3.5f, 1.5f, NULL, 1, 0.95f, 0.85f, 20000, 0);
  view(&d, "side", 0.5f, 1.4f, 4.2f, -0.3f, 0.9f, 0, 50, 30);
  float times[3] = {0, 1, 2}, q[3][4];
  for (int k = 0; k < 3; k++) axis_quat(0, 0, 1, 45.0f * (float)k, q[k]);
  anim a = {0};
  channel(&d, &a, bend, "rotation", "LINEAR", times, 3, q[0], 4);
  add_animation(&d, "bend", &a);
  finish(&d, dir, "bending_tube");
}

/* A closed room with three boxes and a point light that crosses it from
 * left to right, 2 m high, in 3 s (LINEAR translation keys at 0 and 3 s):
 * the boxes' shadows sweep over the floor. */
static void moving_light(const char *dir) {
  doc d = {0};
  int wall = diffuse(&d, "plaster", 0.8f, 0.78f, 0.74f), floor = diffuse(&d, "floor", 0.6f, 0.42f, 0.28f);
  int boxes = diffuse(&d, "boxes", 0.25f, 0.55f, 0.3f);
  float W = 2, H = 2.5f, D = 2;
  mesh m = {0};
  slab(&m, 0, true, -W, W, -D, D);
  mesh_node(&d, "floor", -1, add_mesh1(&d, "floor", &m, floor), 0, 0, 0, 0, 1);
  slab(&m, H, false, -W, W, -D, D);
  wall_x(&m, -W, 1, -D, D, 0, H);
  wall_x(&m, W, -1, -D, D, 0, H);
  wall_z(&m, -D, 1, -W, W, 0, H);
  wall_z(&m, D, -1, -W, W, 0, H);
  mesh_node(&d, "walls", -1, add_mesh1(&d, "walls", &m, wall), 0, 0, 0, 0, 1);
  box(&m, -0.8f, 0.4f, -0.6f, 0.3f, 0.4f, 0.3f);
  box(&m, 0.7f, 0.6f, -0.9f, 0.25f, 0.6f, 0.25f);
  box(&m, 0.125f, 0.25f, 0.5f, 0.375f, 0.25f, 0.25f); /* binary fractions: exact bounds */
  mesh_node(&d, "boxes", -1, add_mesh1(&d, "boxes", &m, boxes), 0, 0, 0, 0, 1);
  int lamp = d.node_count;
  light(&d, "lamp", "point", -1.5f, 2, 0, NULL, 1, 0.95f, 0.85f, 6000, 0);
  view(&d, "front", 0, 1.4f, 1.9f, 0, 0.9f, -1, 65, 20);
  float times[2] = {0, 3}, path[2][3] = {{-1.5f, 2, 0}, {1.5f, 2, 0}};
  anim a = {0};
  channel(&d, &a, lamp, "translation", "LINEAR", times, 2, path[0], 3);
  add_animation(&d, "cross", &a);
  finish(&d, dir, "moving_light");
}

/* ---- the big scene (benchmarks; tests take its small size) -------------------
 * Spheres in a square grid on a ground plane, each a node of one of four
 * shared sphere meshes (a material each) with its own yaw and scale, under a
 * sun and eight point lights, all casting shadows. Written under OUTDIR/big/,
 * where the capture test of every scene does not look: big (20 x 20 spheres
 * of 64 x 30 quads: 3,840 triangles each, 1.54 M drawn, 415 kB as the meshes
 * are shared) for benchmarks; big_small (8 x 8 of 16 x 8: 16.4 k triangles)
 * for tests, and big_small_instanced, the same spheres as one node a mesh
 * carrying EXT_mesh_gpu_instancing (it must draw the same image). */
typedef struct big_size {
  const char *name;
  int side, seg, rings;
} big_size;

static void big(const char *dir, const big_size *z, bool instanced) {
  enum { MESHES = 4 };
  rng_state = 4242; /* its own sequence: every size and form places the spheres alike */
  doc d = {0};
  float spacing = 3, H = (float)z->side * spacing / 2; /* the grid's half width */
  int ground = diffuse(&d, "ground", 0.55f, 0.53f, 0.5f);
  mesh m = {0};
  slab(&m, 0, true, -H - 4, H + 4, -H - 4, H + 4);
  mesh_node(&d, "ground", -1, add_mesh1(&d, "ground", &m, ground), 0, 0, 0, 0, 1);
  static const float colors[MESHES][3] = {{0.8f, 0.25f, 0.2f}, {0.25f, 0.6f, 0.3f}, {0.25f, 0.35f, 0.8f},
                                          {0.85f, 0.75f, 0.3f}};
  int meshes[MESHES];
  for (int k = 0; k < MESHES; k++) {
    char nm[32];
    snprintf(nm, sizeof nm, "sphere%d", k);
    int mat = add_material(&d, nm, colors[k][0], colors[k][1], colors[k][2], 0, 0.5f + 0.1f * (float)k, -1);
    sphere(&m, 1, z->seg, z->rings);
    meshes[k] = add_mesh1(&d, nm, &m, mat);
  }
  int count = z->side * z->side, per[MESHES] = {0};
  float *t = malloc(sizeof(float) * 3 * (size_t)count * MESHES), *r = malloc(sizeof(float) * 4 * (size_t)count * MESHES);
  float *sc = malloc(sizeof(float) * 3 * (size_t)count * MESHES);
  for (int k = 0; k < count; k++) {
    int i = k % z->side, j = k / z->side, which = (int)(rnd() * MESHES) % MESHES;
    float s = 0.5f + 0.5f * rnd(), yaw = rnd() * 360;
    float x = -H + spacing * ((float)i + 0.5f) + (rnd() - 0.5f), zz = -H + spacing * ((float)j + 0.5f) + (rnd() - 0.5f);
    if (!instanced) {
      char nm[32];
      snprintf(nm, sizeof nm, "ball%d", k);
      mesh_node(&d, nm, -1, meshes[which], x, s, zz, yaw, s);
      continue;
    }
    int at = which * count + per[which]++;
    float *tt = t + at * 3, *rr = r + at * 4, *ss = sc + at * 3;
    tt[0] = x, tt[1] = s, tt[2] = zz;
    axis_quat(0, 1, 0, yaw, rr);
    ss[0] = ss[1] = ss[2] = s;
  }
  for (int k = 0; instanced && k < MESHES; k++) {
    if (!per[k]) continue;
    char nm[32];
    snprintf(nm, sizeof nm, "balls%d", k);
    int n = mesh_node(&d, nm, -1, meshes[k], 0, 0, 0, 0, 1);
    int *acc = d.nodes[n].instances;
    acc[0] = add_accessor(&d, add_view(&d, t + k * count * 3, (size_t)per[k] * 12, 0), 5126, per[k], "VEC3", NULL, NULL);
    acc[1] = add_accessor(&d, add_view(&d, r + k * count * 4, (size_t)per[k] * 16, 0), 5126, per[k], "VEC4", NULL, NULL);
    acc[2] = add_accessor(&d, add_view(&d, sc + k * count * 3, (size_t)per[k] * 12, 0), 5126, per[k], "VEC3", NULL, NULL);
  }
  free(t), free(r), free(sc);
  light(&d, "sun", "directional", 0, 30, 0, (float[]){0.5f, -0.75f, -0.35f}, 1, 0.96f, 0.9f, 2 * LUX, 0);
  for (int k = 0; k < 8; k++) { /* four inside the grid, four over its edges' middles */
    float a = (float)k * PI / 4, rad = k % 2 ? H * 0.5f * 1.41f : H * 0.9f, y = k % 2 ? 4 : 5;
    char nm[32];
    snprintf(nm, sizeof nm, "lamp%d", k);
    light(&d, nm, "point", rad * cosf(a), y, rad * sinf(a), NULL, 1, 0.9f - 0.05f * (float)(k % 3), 0.8f, 1500,
          3 * spacing * 2);
  }
  view(&d, "overview", 0, H * 0.8f, H * 1.5f, 0, 0, 0, 50, H * 6);
  view(&d, "street", -H - 2, 2, spacing * 0.5f, H, 1, spacing * 0.5f, 60, H * 6);
  view(&d, "corner", H * 1.1f, 6, H * 1.1f, 0, 0.5f, 0, 55, H * 6);
  char name[64];
  snprintf(name, sizeof name, "%s%s", z->name, instanced ? "_instanced" : "");
  finish(&d, dir, name);
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: gen_scenes OUTDIR\n");
    return 2;
  }
  cornell(argv[1]);
  primitives(argv[1]);
  office(argv[1]);
  garage(argv[1]);
  outdoor(argv[1]);
  char ref[1024], bigdir[1024];
  snprintf(ref, sizeof ref, "%s/reference", argv[1]);
  snprintf(bigdir, sizeof bigdir, "%s/big", argv[1]);
  if ((mkdir(ref, 0777) != 0 && errno != EEXIST) || (mkdir(bigdir, 0777) != 0 && errno != EEXIST)) {
    fprintf(stderr, "gen_scenes: cannot make %s and %s: %s\n", ref, bigdir, strerror(errno));
    return 1;
  }
  ref_room(ref);
  ref_street(ref);
  ref_blocks(ref);
  night(argv[1]); /* it draws no random number, but stays after those that do */
  turntable(argv[1]);
  door(argv[1]);
  bending_tube(argv[1]);
  moving_light(argv[1]);
  static const big_size full = {"big", 20, 64, 30}, small = {"big_small", 8, 16, 8};
  big(bigdir, &full, false); /* its own random sequence: the scenes above stay as they were */
  big(bigdir, &small, false);
  big(bigdir, &small, true);
  char holdout[1024];
  snprintf(holdout, sizeof holdout, "%s/holdout", argv[1]);
  if (mkdir(holdout, 0777) != 0 && errno != EEXIST) {
    fprintf(stderr, "gen_scenes: cannot make %s: %s\n", holdout, strerror(errno));
    return 1;
  }
  holdout_loft(holdout);
  holdout_yard(holdout);
  return 0;
}
