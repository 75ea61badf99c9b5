// Bridge to tinygltf; the engine sees only scene/gltf.h. tinygltf parses the
// JSON and resolves buffers; this file turns its Model into an lm_scene and
// trusts none of its numbers: every index is range-checked and every
// accessor's bytes are proven to lie inside their buffer before one is read.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE       // images go through our loader, not stb
#define TINYGLTF_NO_STB_IMAGE_WRITE // we never write glTF
#include <tiny_gltf.h>

#include "image/image.h"
#include "scene/gltf.h"
#include "scene/gltf_decode.h"
#include "scene/scene_internal.h"

#include <fcntl.h>
#include <strings.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <vector>

namespace {

// ---- the file's bytes --------------------------------------------------------

// A file mapped read-only. tinygltf would read the file into memory and copy
// each buffer out of it again; mapped, its bytes are the page cache's, read
// where they lie and dropped when the load ends (and after each mesh, by
// release, so that the file's pages and the meshes read from them are not
// resident together).
struct Mapping {
  void *addr = MAP_FAILED;
  size_t len = 0;
  Mapping() = default;
  Mapping(const Mapping &) = delete;
  Mapping &operator=(const Mapping &) = delete;
  ~Mapping() {
    if (addr != MAP_FAILED) munmap(addr, len);
  }
  const unsigned char *bytes() const { return addr == MAP_FAILED ? nullptr : (const unsigned char *)addr; }
  // Drops the pages read so far from this process (they stay in the page
  // cache: a later read maps them again without reading the disk).
  void release() const {
    if (addr != MAP_FAILED) madvise(addr, len, MADV_DONTNEED);
  }
};

// Maps regular file `path`; false with "path: why" in err.
bool map_file(const char *path, Mapping &m, lm_error *err) {
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return lm_error_set(err, "%s: cannot open: %s", path, strerror(errno)), false;
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    close(fd);
    return lm_error_set(err, "%s: not a regular file", path), false;
  }
  m.len = (size_t)st.st_size;
  if (m.len) m.addr = mmap(nullptr, m.len, PROT_READ, MAP_PRIVATE, fd, 0);
  int why = errno;
  close(fd);
  if (m.len && m.addr == MAP_FAILED) return lm_error_set(err, "%s: cannot map: %s", path, strerror(why)), false;
  return true;
}

// A glTF buffer's bytes where they lie: in the GLB's BIN chunk or a mapped
// .bin file, or decoded from a data URI into `owned`. An
// EXT_meshopt_compression fallback buffer has no bytes, only its size.
struct Buffer {
  const unsigned char *data = nullptr;
  size_t size = 0;
  bool fallback = false;
};

// An image as the file names it; its bytes are read when a texture uses it.
struct ImageRef {
  std::string name, uri;
  int buffer_view = -1;
};

// What the file's buffers and images come from; tinygltf sees only the
// rest of the JSON.
struct Source {
  std::string dir;
  Mapping file;
  std::vector<std::unique_ptr<Mapping>> bins;
  std::vector<std::unique_ptr<std::vector<unsigned char>>> owned;
  std::vector<Buffer> buffers;
  std::vector<ImageRef> images;
  // [mesh, primitive] -> the indices accessor of a KHR_draco_mesh_compression
  // primitive, kept from tinygltf, which refuses an indices accessor without
  // a bufferView (as Draco's are)
  std::map<std::pair<size_t, size_t>, int> draco_indices;
};

// An image decoded ahead of its first use (decode_images), until the scene
// takes its pixels.
struct Pending {
  bool wanted = false, done = false, ok = false;
  int width = 0, height = 0;
  unsigned char *rgba = nullptr;
  std::string error;
  Pending() = default;
  Pending(const Pending &) = delete;
  Pending &operator=(const Pending &) = delete;
  Pending(Pending &&o) noexcept : wanted(o.wanted), done(o.done), ok(o.ok), width(o.width), height(o.height),
                                  rgba(o.rgba), error(std::move(o.error)) { o.rgba = nullptr; }
  ~Pending() { free(rgba); }
};

// Bytes decoded from compressed data, read as an accessor's or a
// bufferView's own: `type` is the component type they hold.
struct Decoded {
  std::vector<unsigned char> bytes;
  int type = 0;
  bool done = false;
};

struct Loader {
  const char *path;
  const tinygltf::Model &m;
  lm_scene *s;
  lm_error *err;
  std::vector<std::vector<int>> meshes; // [mesh][primitive] -> lm mesh; -1 not yet, -2 skipped
  std::vector<int> materials;           // [material] -> lm material; -1 not yet
  std::vector<int> textures;            // [image * 2 + linear] -> lm texture; -1 not yet
  std::vector<int> nodes;               // [node] -> lm node; -1 not in the scene
  int skipped = 0;                      // point and line primitives, warned about once
  std::string first_skipped;            // "mesh M primitive P (mode K)"
  std::vector<std::vector<int>> holders; // [node] -> the lm nodes holding its mesh's primitives
  // What is skipped or mended with one warning a file: the count and the first case.
  int skipped_channels = 0, ignored_targets = 0, mended_weights = 0;
  std::string first_channel, first_target, first_weights;
  const Source *src;                   // the buffers and images
  std::vector<Decoded> views;          // [bufferView] -> EXT_meshopt_compression's bytes, once decoded
  std::map<int, Decoded> draco;        // [accessor] -> the current primitive's Draco-decoded elements
  std::vector<Pending> decoded;        // [image] -> decoded by decode_images
  std::vector<std::string> warned_glass; // glass extension fields not read, each warned about once
  // [geometry_hash] -> an lm mesh of a primitive that does not deform and the [mesh, primitive] it came from
  std::unordered_multimap<size_t, std::pair<int, std::pair<int, int>>> loaded;
  int shared = 0;                        // primitives given an identical one's lm mesh
};

// Every failure goes through here: "path: what".
__attribute__((format(printf, 2, 3))) bool fail(Loader &L, const char *fmt, ...) {
  char what[1536];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  lm_error_set(L.err, "%s: %s", L.path, what);
  return false;
}

bool finite_all(const std::vector<double> &v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

float clamp01(double x) { return (float)(x < 0 ? 0 : x > 1 ? 1 : x); }

// LM_PUSH for C++, which wants lm_grow's void * cast: a new zeroed slot.
template <typename T> T *push(T *&items, int &count, int &cap) {
  items = (T *)lm_grow(items, &cap, count + 1, sizeof(T));
  return &items[count++];
}

// ---- accessors -------------------------------------------------------------

int component_size(int type) {
  switch (type) {
  case TINYGLTF_COMPONENT_TYPE_BYTE:
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
  case TINYGLTF_COMPONENT_TYPE_SHORT:
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
  case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
  default: return 0;
  }
}

int component_count(int type) {
  switch (type) {
  case TINYGLTF_TYPE_SCALAR: return 1;
  case TINYGLTF_TYPE_VEC2: return 2;
  case TINYGLTF_TYPE_VEC3: return 3;
  case TINYGLTF_TYPE_VEC4: return 4;
  case TINYGLTF_TYPE_MAT4: return 16; // a skin's inverse bind matrices
  default: return 0; // other matrices: nothing we read
  }
}

// An accessor proven readable: element i's components start at base + i * stride.
struct View {
  const unsigned char *base; // NULL: no bufferView, every value 0 (glTF's rule)
  size_t stride, count;
  int type, ncomp;
  bool normalized;
};

// An unsigned integer `key` of extension object `o` into *out (`fallback` when absent).
bool ext_size(const tinygltf::Value &o, const char *key, size_t fallback, size_t *out) {
  if (!o.Has(key)) return *out = fallback, true;
  const tinygltf::Value &v = o.Get(key);
  double x = v.IsNumber() ? v.GetNumberAsDouble() : -1;
  if (!(x >= 0 && x <= 9e15) || x != std::floor(x)) return false;
  *out = (size_t)x;
  return true;
}

// Bytes [offset, offset + length) of buffer `index` (for `what`); false
// (error set) when they are not all there.
bool buffer_range(Loader &L, const char *what, int index, size_t offset, size_t length, const unsigned char **data) {
  const std::vector<Buffer> &buffers = L.src->buffers;
  if (index < 0 || (size_t)index >= buffers.size())
    return fail(L, "%s: buffer %d does not exist (the file has %zu)", what, index, buffers.size());
  const Buffer &b = buffers[index];
  if (b.fallback)
    return fail(L, "%s: buffer %d is EXT_meshopt_compression's fallback, which holds no data", what, index);
  if (offset > b.size || length > b.size - offset)
    return fail(L, "%s (%zu bytes from %zu) runs past the end of buffer %d (%zu bytes)", what, length, offset, index,
                b.size);
  *data = b.data + offset;
  return true;
}

// The bytes of bufferView `index` (for `what`, "mesh 0 primitive 1:
// POSITION: accessor 3"), decoded first (once) when EXT_meshopt_compression
// compressed them; false (error set) when they are not all in their buffer
// or do not decode.
bool view_bytes(Loader &L, const char *what, int index, const unsigned char **data, size_t *size) {
  const tinygltf::Model &m = L.m;
  if (index < 0 || (size_t)index >= m.bufferViews.size())
    return fail(L, "%s: bufferView %d does not exist (the file has %zu)", what, index, m.bufferViews.size());
  const tinygltf::BufferView &bv = m.bufferViews[index];
  char at[256];
  snprintf(at, sizeof at, "%s: bufferView %d", what, index);
  *size = bv.byteLength;
  auto ext = bv.extensions.find("EXT_meshopt_compression");
  if (ext == bv.extensions.end()) return buffer_range(L, at, bv.buffer, bv.byteOffset, bv.byteLength, data);

  Decoded &d = L.views[index];
  if (!d.done) {
    const tinygltf::Value &o = ext->second;
    size_t buffer, offset, length, stride, count;
    if (!o.IsObject() || !ext_size(o, "buffer", SIZE_MAX, &buffer) || !ext_size(o, "byteOffset", 0, &offset) ||
        !ext_size(o, "byteLength", SIZE_MAX, &length) || !ext_size(o, "byteStride", SIZE_MAX, &stride) ||
        !ext_size(o, "count", SIZE_MAX, &count) || buffer > INT32_MAX || length == SIZE_MAX ||
        stride == SIZE_MAX || count == SIZE_MAX || !o.Get("mode").IsString() ||
        (o.Has("filter") && !o.Get("filter").IsString()))
      return fail(L, "%s: EXT_meshopt_compression wants buffer, byteLength, byteStride, count (integers) and mode",
                  at);
    const unsigned char *compressed;
    if (!buffer_range(L, at, (int)buffer, offset, length, &compressed)) return false;
    std::string filter = o.Has("filter") ? o.Get("filter").Get<std::string>() : "NONE";
    std::string why = lm_meshopt_decode(compressed, length, count, stride, o.Get("mode").Get<std::string>(), filter,
                                        d.bytes);
    if (!why.empty()) return fail(L, "%s: EXT_meshopt_compression: %s", at, why.c_str());
    d.done = true;
  }
  if (bv.byteLength > d.bytes.size())
    return fail(L, "%s: byteLength %zu is more than EXT_meshopt_compression's %zu decoded bytes", at, bv.byteLength,
                d.bytes.size());
  *data = d.bytes.data();
  return true;
}

// Checks accessor `index` (for `what`, e.g. "mesh 0 primitive 1: POSITION")
// down to the buffer's last byte.
bool accessor_view(Loader &L, const char *what, int index, int ncomp, View *v) {
  const tinygltf::Model &m = L.m;
  if (index < 0 || (size_t)index >= m.accessors.size())
    return fail(L, "%s: accessor %d does not exist (the file has %zu)", what, index,
                m.accessors.size());
  const tinygltf::Accessor &a = m.accessors[index];
  if (a.sparse.isSparse) return fail(L, "%s: accessor %d is sparse (not supported)", what, index);
  if (component_count(a.type) != ncomp)
    return fail(L, "%s: accessor %d has %d components per element, want %d", what, index,
                component_count(a.type), ncomp);
  int csize = component_size(a.componentType);
  if (!csize)
    return fail(L, "%s: accessor %d has component type %d, not a glTF one", what, index,
                a.componentType);
  if (a.count == 0) return fail(L, "%s: accessor %d is empty", what, index);
  if (a.count > (size_t)LM_GLTF_MAX_ELEMENTS)
    return fail(L, "%s: accessor %d has %zu elements, more than %d", what, index, a.count,
                LM_GLTF_MAX_ELEMENTS);
  size_t elem = (size_t)csize * (size_t)ncomp;
  *v = View{nullptr, elem, a.count, a.componentType, ncomp, a.normalized};
  auto decoded = L.draco.find(index);
  if (decoded != L.draco.end()) { // KHR_draco_mesh_compression's: tightly packed, its own type
    v->type = decoded->second.type;
    v->stride = (size_t)component_size(v->type) * (size_t)ncomp;
    v->base = decoded->second.bytes.data();
    if (decoded->second.bytes.size() != v->stride * a.count)
      return fail(L, "%s: accessor %d has %zu elements, but its Draco data %zu", what, index, a.count,
                  decoded->second.bytes.size() / v->stride);
    return true;
  }
  if (a.bufferView < 0) return true;

  char at[192];
  snprintf(at, sizeof at, "%s: accessor %d", what, index);
  const unsigned char *bytes;
  size_t room;
  if (!view_bytes(L, at, a.bufferView, &bytes, &room)) return false;
  const tinygltf::BufferView &bv = m.bufferViews[a.bufferView];
  size_t stride = bv.byteStride ? bv.byteStride : elem;
  if (stride < elem || stride % (size_t)csize)
    return fail(L, "%s: accessor %d: bufferView %d has byteStride %zu, which does not fit "
                "%zu-byte elements", what, index, a.bufferView, bv.byteStride, elem);
  // The last element ends at byteOffset + stride * (count - 1) + elem; divide, never overflow.
  if (a.byteOffset > room || room - a.byteOffset < elem ||
      (a.count - 1) > (room - a.byteOffset - elem) / stride)
    return fail(L, "%s: accessor %d: %zu elements of %zu bytes (stride %zu) from byteOffset %zu "
                "run past the end of bufferView %d (%zu bytes)", what, index, a.count, elem,
                stride, a.byteOffset, a.bufferView, room);
  v->base = bytes + a.byteOffset;
  v->stride = stride;
  return true;
}

// Component c of element i as a double (normalized integers to [0, 1] or [-1, 1]).
double view_get(const View &v, size_t i, int c) {
  if (!v.base) return 0;
  const unsigned char *p = v.base + i * v.stride + (size_t)c * (size_t)component_size(v.type);
  switch (v.type) {
  case TINYGLTF_COMPONENT_TYPE_BYTE: {
    int8_t x;
    memcpy(&x, p, 1);
    return v.normalized ? std::fmax(x / 127.0, -1.0) : x;
  }
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return v.normalized ? p[0] / 255.0 : p[0];
  case TINYGLTF_COMPONENT_TYPE_SHORT: {
    int16_t x;
    memcpy(&x, p, 2);
    return v.normalized ? std::fmax(x / 32767.0, -1.0) : x;
  }
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
    uint16_t x;
    memcpy(&x, p, 2);
    return v.normalized ? x / 65535.0 : x;
  }
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
    uint32_t x;
    memcpy(&x, p, 4);
    return x;
  }
  default: {
    float x;
    memcpy(&x, p, 4);
    return x;
  }
  }
}

// Component c of element i of accessor `index` into *out; fails naming it
// (`what`, the accessor, `noun` i) when it is non-finite or beyond
// LM_GLTF_MAX_COORD.
bool read_coord(Loader &L, const View &v, const char *what, int index, const char *noun, size_t i, int c,
                float *out) {
  double x = view_get(v, i, c);
  if (!std::isfinite(x) || std::fabs(x) > LM_GLTF_MAX_COORD)
    return fail(L, "%s: accessor %d: %s %zu has a non-finite or huge value (%g)", what, index, noun, i, x);
  *out = (float)x;
  return true;
}

// Copies attribute `name` of the primitive into slots [at, at + ncomp) of the
// 8-float vertices; false when absent (*present = false) or bad (error set).
bool read_attribute(Loader &L, const char *where, const tinygltf::Primitive &p, const char *name,
                    int ncomp, int at, int stride, std::vector<float> &verts, size_t count, bool *present) {
  auto it = p.attributes.find(name);
  *present = it != p.attributes.end();
  if (!*present) return true;
  char what[160];
  snprintf(what, sizeof what, "%s: %s", where, name);
  View v;
  if (!accessor_view(L, what, it->second, ncomp, &v)) return false;
  if (v.count != count)
    return fail(L, "%s: accessor %d has %zu elements, but POSITION has %zu", what, it->second,
                v.count, count);
  verts.resize(count * (size_t)stride);
  for (size_t i = 0; i < count; i++)
    for (int c = 0; c < ncomp; c++)
      if (!read_coord(L, v, what, it->second, "element", i, c, &verts[i * (size_t)stride + at + c])) return false;
  return true;
}

bool read_indices(Loader &L, const char *where, int index, size_t vertex_count,
                  std::vector<uint32_t> &out) {
  char what[160];
  snprintf(what, sizeof what, "%s: indices", where);
  // The type first: a float index buffer is a clearer mistake than its length.
  bool exists = index >= 0 && (size_t)index < L.m.accessors.size();
  int type = exists ? L.m.accessors[index].componentType : 0;
  if (exists && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    return fail(L, "%s: accessor %d has component type %d; indices are unsigned byte, short or int",
                what, index, type);
  View v;
  if (!accessor_view(L, what, index, 1, &v)) return false;
  out.resize(v.count);
  for (size_t i = 0; i < v.count; i++) {
    double x = view_get(v, i, 0);
    if (x >= (double)vertex_count)
      return fail(L, "%s: index %zu is %.0f, past the %zu vertices", what, i, x, vertex_count);
    out[i] = (uint32_t)x;
  }
  return true;
}

// ---- primitives ------------------------------------------------------------

// Area-weighted vertex normals: the cross product of two edges is twice the
// triangle's area long, so summing unnormalized ones weights by area. Doubles
// keep coordinates up to LM_GLTF_MAX_COORD from overflowing.
void compute_normals(std::vector<float> &verts, const std::vector<uint32_t> &idx) {
  size_t n = verts.size() / 8;
  std::vector<double> acc(n * 3, 0.0);
  for (size_t t = 0; t + 2 < idx.size(); t += 3) {
    const float *a = &verts[(size_t)idx[t] * 8], *b = &verts[(size_t)idx[t + 1] * 8],
                *c = &verts[(size_t)idx[t + 2] * 8];
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) e1[k] = (double)b[k] - a[k], e2[k] = (double)c[k] - a[k];
    double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0]};
    for (int j = 0; j < 3; j++)
      for (int k = 0; k < 3; k++) acc[(size_t)idx[t + j] * 3 + k] += cr[k];
  }
  for (size_t i = 0; i < n; i++) {
    double *a = &acc[i * 3];
    double len = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    float *o = &verts[i * 8 + 3];
    if (len > 0 && std::isfinite(len)) {
      for (int k = 0; k < 3; k++) o[k] = (float)(a[k] / len);
    } else { // only zero-area triangles (or none) here: +Z, never NaN
      o[0] = 0, o[1] = 0, o[2] = 1;
    }
  }
}

// Normals from the file are normalized too; a zero one gets +Z.
void normalize_normals(std::vector<float> &verts) {
  for (size_t i = 0; i < verts.size(); i += 8) {
    float *o = &verts[i + 3];
    double len = std::sqrt((double)o[0] * o[0] + (double)o[1] * o[1] + (double)o[2] * o[2]);
    if (len > 0) {
      for (int k = 0; k < 3; k++) o[k] = (float)(o[k] / len);
    } else {
      o[0] = 0, o[1] = 0, o[2] = 1;
    }
  }
}

// Tangents as the shaders take them: xyz of unit length (a zero one stays
// zero: that vertex falls back to a frame from screen derivatives) and the
// handedness w as +-1.
void normalize_tangents(std::vector<float> &t) {
  for (size_t i = 0; i < t.size(); i += 4) {
    double len = std::sqrt((double)t[i] * t[i] + (double)t[i + 1] * t[i + 1] + (double)t[i + 2] * t[i + 2]);
    for (int k = 0; k < 3; k++) t[i + k] = len > 0 ? (float)(t[i + k] / len) : 0.0f;
    t[i + 3] = t[i + 3] < 0 ? -1.0f : 1.0f;
  }
}

// A strip's or fan's indices as a triangle list, winding kept (glTF 2.0
// section 3.7.2.1: strip triangle i is (i, i + 1 + i % 2, i + 2 - i % 2),
// fan triangle i is (i + 1, i + 2, 0)).
std::vector<uint32_t> triangle_list(int mode, const std::vector<uint32_t> &in) {
  std::vector<uint32_t> out;
  out.reserve((in.size() - 2) * 3);
  for (size_t i = 0; i + 2 < in.size(); i++) {
    if (mode == TINYGLTF_MODE_TRIANGLE_STRIP)
      out.insert(out.end(), {in[i], in[i + 1 + i % 2], in[i + 2 - i % 2]});
    else
      out.insert(out.end(), {in[i + 1], in[i + 2], in[0]});
  }
  return out;
}

// ---- deformation: morph targets and skin influences ------------------------

// A component type view_get reads as [0, 1] or [-1, 1]: glTF's normalized integers.
bool normalized_int(const View &v) { return v.normalized && v.type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT; }

// Morph target t's `name` deltas (POSITION or NORMAL) into out[count * 3].
bool read_target(Loader &L, const char *where, size_t t, const std::string &name, int index, size_t count,
                 float *out) {
  char what[192];
  snprintf(what, sizeof what, "%s: target %zu: %s", where, t, name.c_str());
  View v;
  if (!accessor_view(L, what, index, 3, &v)) return false;
  if (v.count != count)
    return fail(L, "%s: accessor %d has %zu elements, but POSITION has %zu", what, index, v.count, count);
  for (size_t i = 0; i < count; i++)
    for (int c = 0; c < 3; c++)
      if (!read_coord(L, v, what, index, "element", i, c, &out[i * 3 + c])) return false;
  return true;
}

// JOINTS_k and WEIGHTS_k of a primitive into influences [k * 4, k * 4 + 4) of
// each vertex's 4 * sets (the weights not yet normalized).
bool read_influences(Loader &L, const char *where, const tinygltf::Primitive &p, int k, int sets, size_t count,
                     uint16_t *joints, float *weights) {
  std::string jname = "JOINTS_" + std::to_string(k), wname = "WEIGHTS_" + std::to_string(k);
  char what[192];
  snprintf(what, sizeof what, "%s: %s", where, jname.c_str());
  View jv, wv;
  int ji = p.attributes.at(jname), wi = p.attributes.at(wname);
  if (!accessor_view(L, what, ji, 4, &jv)) return false;
  if ((jv.type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && jv.type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) ||
      jv.normalized)
    return fail(L, "%s: accessor %d has component type %d%s; joints are unsigned bytes or shorts (5121, 5123)", what,
                ji, jv.type, jv.normalized ? ", normalized" : "");
  if (jv.count != count)
    return fail(L, "%s: accessor %d has %zu elements, but POSITION has %zu", what, ji, jv.count, count);
  snprintf(what, sizeof what, "%s: %s", where, wname.c_str());
  if (!accessor_view(L, what, wi, 4, &wv)) return false;
  if (wv.type != TINYGLTF_COMPONENT_TYPE_FLOAT &&
      !(normalized_int(wv) && (wv.type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                wv.type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)))
    return fail(L, "%s: accessor %d has component type %d; weights are floats or normalized unsigned bytes or "
                "shorts", what, wi, wv.type);
  if (wv.count != count)
    return fail(L, "%s: accessor %d has %zu elements, but POSITION has %zu", what, wi, wv.count, count);
  for (size_t v = 0; v < count; v++)
    for (int c = 0; c < 4; c++) {
      size_t at = (v * (size_t)sets + (size_t)k) * 4 + (size_t)c;
      double w = view_get(wv, v, c);
      if (!std::isfinite(w) || std::fabs(w) > 1e6)
        return fail(L, "%s: accessor %d: element %zu has a non-finite or huge weight (%g)", what, wi, v, w);
      joints[at] = (uint16_t)view_get(jv, v, c);
      weights[at] = (float)w;
    }
  return true;
}

// Each vertex's weights scaled to sum 1; negative ones count as 0. A vertex
// whose weights did not sum to 1 is mended with one warning a file; one
// whose weights are all 0 stays unskinned (anim.c keeps it in place).
void normalize_weights(Loader &L, const char *where, float *weights, size_t count, int sets) {
  size_t n = 4 * (size_t)sets;
  for (size_t v = 0; v < count; v++) {
    float *w = weights + v * n;
    double sum = 0;
    bool negative = false;
    for (size_t i = 0; i < n; i++) {
      negative |= w[i] < 0;
      w[i] = std::fmax(w[i], 0.0f);
      sum += w[i];
    }
    if ((negative || std::fabs(sum - 1) > 0.01) && !L.mended_weights++)
      L.first_weights = std::string(where) + " vertex " + std::to_string(v) + " (sum " + std::to_string(sum) + ")";
    for (size_t i = 0; i < n && sum > 0; i++) w[i] = (float)(w[i] / sum);
  }
}

// A primitive's morph targets (POSITION and NORMAL deltas; TANGENT and
// others are ignored, with one warning a file) and its JOINTS_n / WEIGHTS_n
// sets into lm mesh `id`, which keeps its undeformed vertices as `rest`.
bool read_deform(Loader &L, const char *where, const tinygltf::Mesh &mesh, const tinygltf::Primitive &p, size_t count,
                 int id) {
  int sets = 0;
  for (;; sets++) {
    bool j = p.attributes.count("JOINTS_" + std::to_string(sets)) > 0;
    bool w = p.attributes.count("WEIGHTS_" + std::to_string(sets)) > 0;
    if (j != w)
      return fail(L, "%s: %s_%d comes without %s_%d", where, j ? "JOINTS" : "WEIGHTS", sets, j ? "WEIGHTS" : "JOINTS",
                  sets);
    if (!j) break;
  }
  size_t nt = p.targets.size();
  if (!nt && !sets) return true;
  if (nt > (size_t)LM_GLTF_MAX_ELEMENTS / count || (size_t)sets * 4 > (size_t)LM_GLTF_MAX_ELEMENTS / count)
    return fail(L, "%s: %zu morph targets and %d joint sets of %zu vertices: more than %d values", where, nt, sets,
                count, LM_GLTF_MAX_ELEMENTS);
  lm_scene_mesh *m = &L.s->meshes[id];
  size_t floats = count * 8;
  m->rest = (float *)memcpy(lm_alloc(sizeof(float) * floats), m->vertices, sizeof(float) * floats);
  if (nt) {
    m->target_count = (int)nt;
    m->target_positions = (float *)lm_alloc(sizeof(float) * nt * count * 3);
    m->default_weights = (float *)lm_alloc(sizeof(float) * nt);
    for (size_t t = 0; t < mesh.weights.size() && t < nt; t++) m->default_weights[t] = (float)mesh.weights[t];
    for (size_t t = 0; t < nt; t++)
      for (const auto &[name, index] : p.targets[t]) {
        float *out = nullptr;
        if (name == "POSITION") {
          out = m->target_positions;
        } else if (name == "NORMAL") {
          if (!m->target_normals) m->target_normals = (float *)lm_alloc(sizeof(float) * nt * count * 3);
          out = m->target_normals;
        } else {
          if (!L.ignored_targets++) L.first_target = std::string(where) + " target " + std::to_string(t) + " " + name;
          continue;
        }
        if (!read_target(L, where, t, name, index, count, out + t * count * 3)) return false;
      }
  }
  if (sets) {
    m->influence_sets = sets;
    m->joints = (uint16_t *)lm_alloc(sizeof(uint16_t) * count * 4 * (size_t)sets);
    m->joint_weights = (float *)lm_alloc(sizeof(float) * count * 4 * (size_t)sets);
    for (int k = 0; k < sets; k++)
      if (!read_influences(L, where, p, k, sets, count, m->joints, m->joint_weights)) return false;
    normalize_weights(L, where, m->joint_weights, count, sets);
  }
  return true;
}

// True when a primitive of the mesh morphs or is skinned: its lm meshes are
// then one node's pose, and each node that uses it gets its own copies.
bool deformable(const tinygltf::Mesh &mesh) {
  for (const tinygltf::Primitive &p : mesh.primitives)
    if (!p.targets.empty() || p.attributes.count("JOINTS_0")) return true;
  return false;
}

// A KHR_draco_mesh_compression primitive's indices and the attributes the
// extension names, decoded into L.draco for accessor_view to read as the
// accessors' own; the other attributes stay where their accessors point.
bool decode_draco(Loader &L, const char *where, const tinygltf::Primitive &p, int indices_accessor,
                  const tinygltf::Value &o) {
  char what[128];
  snprintf(what, sizeof what, "%s: KHR_draco_mesh_compression", where);
  if (!o.IsObject() || !o.Get("bufferView").IsInt() || !o.Get("attributes").IsObject())
    return fail(L, "%s wants {\"bufferView\": index, \"attributes\": {name: id}}", what);
  if (indices_accessor < 0) return fail(L, "%s: the primitive has no indices accessor for the decoded triangles", what);
  std::vector<lm_draco_attribute> wanted;
  std::vector<int> accessors;
  std::vector<std::string> names = o.Get("attributes").Keys(); // wanted[i].name points into it
  for (const std::string &name : names) {
    const tinygltf::Value &id = o.Get("attributes").Get(name);
    auto it = p.attributes.find(name);
    if (!id.IsInt() || it == p.attributes.end())
      return fail(L, "%s: attribute %s wants an integer id and the primitive's own %s accessor", what, name.c_str(),
                  name.c_str());
    if (it->second < 0 || (size_t)it->second >= L.m.accessors.size())
      return fail(L, "%s: %s: accessor %d does not exist (the file has %zu)", what, name.c_str(), it->second,
                  L.m.accessors.size());
    const tinygltf::Accessor &a = L.m.accessors[it->second];
    wanted.push_back({name.c_str(), id.Get<int>(), a.componentType, component_count(a.type), {}});
    accessors.push_back(it->second);
  }
  const unsigned char *bytes;
  size_t size, points;
  std::vector<uint32_t> indices;
  if (!view_bytes(L, what, o.Get("bufferView").Get<int>(), &bytes, &size)) return false;
  std::string why = lm_draco_decode(bytes, size, indices, &points, wanted);
  if (!why.empty()) return fail(L, "%s: %s", what, why.c_str());
  Decoded &ix = L.draco[indices_accessor];
  ix.type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  ix.bytes.resize(indices.size() * sizeof(uint32_t));
  memcpy(ix.bytes.data(), indices.data(), ix.bytes.size());
  for (size_t i = 0; i < wanted.size(); i++) {
    Decoded &d = L.draco[accessors[i]];
    d.type = wanted[i].component_type;
    d.bytes = std::move(wanted[i].bytes);
  }
  return true;
}

// The indices accessor of primitive pi of mesh mi (-1: none), a Draco one's too.
int indices_of(const Loader &L, int mi, int pi) {
  auto d = L.src->draco_indices.find({(size_t)mi, (size_t)pi});
  return d != L.src->draco_indices.end() ? d->second : L.m.meshes[mi].primitives[pi].indices;
}

// A primitive's decoded geometry, as its lm mesh will hold it.
struct Geometry {
  std::vector<float> verts;    // position(3) normal(3) uv(2)
  std::vector<float> tangents; // empty: none
  std::vector<uint32_t> idx;   // a triangle list
  bool operator==(const Geometry &o) const { return verts == o.verts && tangents == o.tangents && idx == o.idx; }
};

// Decodes primitive pi of mesh mi into g: 1, 0 when skipped (points and
// lines), -1 on error.
int decode_primitive(Loader &L, int mi, int pi, Geometry &g) {
  const tinygltf::Mesh &mesh = L.m.meshes[mi];
  const tinygltf::Primitive &p = mesh.primitives[pi];
  char where[64];
  snprintf(where, sizeof where, "mesh %d primitive %d", mi, pi);
  int mode = p.mode == -1 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) return 0;
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      mode != TINYGLTF_MODE_TRIANGLE_FAN)
    return fail(L, "%s: mode %d is not a glTF primitive mode (0 to 6)", where, mode), -1;
  auto pos = p.attributes.find("POSITION");
  if (pos == p.attributes.end()) return fail(L, "%s: no POSITION attribute", where), -1;
  L.draco.clear(); // the previous primitive's
  int indices = indices_of(L, mi, pi);
  auto draco = p.extensions.find("KHR_draco_mesh_compression");
  if (draco != p.extensions.end() && !decode_draco(L, where, p, indices, draco->second)) return -1;
  char what[160];
  snprintf(what, sizeof what, "%s: POSITION", where);
  View v; // POSITION's count first: every other attribute must match it
  if (!accessor_view(L, what, pos->second, 3, &v)) return -1;
  size_t count = v.count;
  bool present, has_normals, has_tangents;
  if (!read_attribute(L, where, p, "POSITION", 3, 0, 8, g.verts, count, &present) ||
      !read_attribute(L, where, p, "NORMAL", 3, 3, 8, g.verts, count, &has_normals) ||
      !read_attribute(L, where, p, "TEXCOORD_0", 2, 6, 8, g.verts, count, &present) ||
      !read_attribute(L, where, p, "TANGENT", 4, 0, 4, g.tangents, count, &has_tangents))
    return -1;
  if (!has_tangents || count == 0) g.tangents.clear();
  else normalize_tangents(g.tangents);

  std::vector<uint32_t> &idx = g.idx;
  if (indices >= 0) {
    if (!read_indices(L, where, indices, count, idx)) return -1;
  } else {
    idx.resize(count);
    for (size_t i = 0; i < count; i++) idx[i] = (uint32_t)i;
  }
  if (mode == TINYGLTF_MODE_TRIANGLES && idx.size() % 3)
    return fail(L, "%s: %zu %s, not a multiple of 3 (triangles)", where, idx.size(),
                indices >= 0 ? "indices" : "vertices"), -1;
  if (mode != TINYGLTF_MODE_TRIANGLES) {
    if (idx.size() < 3)
      return fail(L, "%s: a triangle %s of %zu %s, fewer than 3", where,
                  mode == TINYGLTF_MODE_TRIANGLE_STRIP ? "strip" : "fan", idx.size(),
                  indices >= 0 ? "indices" : "vertices"), -1;
    idx = triangle_list(mode, idx);
  }
  if (has_normals) normalize_normals(g.verts);
  else compute_normals(g.verts, idx);
  return 1;
}

// A hash of everything that decides a primitive's lm mesh (what its GPU
// buffers hold), with the standard library's hash of bytes.
size_t geometry_hash(const Geometry &g) {
  auto bytes = [](const void *p, size_t n) { return std::hash<std::string_view>{}({(const char *)p, n}); };
  size_t h = bytes(g.verts.data(), g.verts.size() * sizeof(float));
  h = h * 31 + bytes(g.tangents.data(), g.tangents.size() * sizeof(float));
  return h * 31 + bytes(g.idx.data(), g.idx.size() * sizeof(uint32_t));
}

// True when lm mesh `m`, loaded from primitive `from` ([mesh, primitive]),
// holds geometry g byte for byte: compared with the mesh's arrays while it
// has them, else with the primitive decoded again (a GPU-only scene frees
// them once uploaded), so that a hash collision never merges two meshes.
bool same_geometry(Loader &L, int m, std::pair<int, int> from, const Geometry &g) {
  const lm_scene_mesh &mesh = L.s->meshes[m];
  if (mesh.vertices) {
    size_t n = (size_t)mesh.vertex_count;
    return n * 8 == g.verts.size() && (size_t)mesh.index_count == g.idx.size() &&
           !memcmp(mesh.vertices, g.verts.data(), n * 8 * sizeof(float)) &&
           !memcmp(mesh.indices, g.idx.data(), g.idx.size() * sizeof(uint32_t)) &&
           (mesh.tangents ? g.tangents.size() == n * 4 && !memcmp(mesh.tangents, g.tangents.data(), n * 4 * sizeof(float))
                          : g.tangents.empty());
  }
  Geometry again;
  return decode_primitive(L, from.first, from.second, again) == 1 && again == g;
}

// lm mesh of primitive pi of mesh mi; -2 when skipped, -1 on error. A
// primitive of a mesh that does not deform whose geometry is byte-identical
// to one already loaded (as exporters write duplicated objects: a mesh each)
// gets that one's lm mesh, name included, so that its nodes are drawn as
// instances of it, with one set of simplified copies and GPU buffers.
int load_primitive(Loader &L, int mi, int pi) {
  const tinygltf::Mesh &mesh = L.m.meshes[mi];
  Geometry g;
  int decoded = decode_primitive(L, mi, pi, g);
  if (decoded == 0) {
    int mode = mesh.primitives[pi].mode;
    if (!L.skipped++)
      L.first_skipped = "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi) + " (mode " +
                        std::to_string(mode) + ")";
    return -2;
  }
  if (decoded < 0) return -1;
  bool deforms = deformable(mesh);
  size_t hash = deforms ? 0 : geometry_hash(g);
  if (!deforms) {
    auto [first, last] = L.loaded.equal_range(hash);
    for (auto it = first; it != last; ++it)
      if (same_geometry(L, it->second.first, it->second.second, g)) {
        L.shared++;
        return it->second.first;
      }
  }

  char base[LM_NAME_MAX], name[LM_NAME_MAX];
  if (mesh.name.empty()) snprintf(base, sizeof base, "mesh%d", mi);
  else snprintf(base, sizeof base, "%s", mesh.name.c_str());
  if (mesh.primitives.size() == 1) snprintf(name, sizeof name, "%s", base);
  else snprintf(name, sizeof name, "%s.%d", base, pi);
  size_t count = g.verts.size() / 8;
  int m = lm_scene_add_mesh(L.s, name, g.verts.data(), (int)count, g.idx.data(), (int)g.idx.size());
  if (!g.tangents.empty()) lm_scene_mesh_set_tangents(L.s, m, g.tangents.data());
  char where[64];
  snprintf(where, sizeof where, "mesh %d primitive %d", mi, pi);
  if (!read_deform(L, where, mesh, mesh.primitives[pi], count, m)) return -1;
  if (!deforms) L.loaded.insert({hash, {m, {mi, pi}}});
  if (L.s->gpu_only && !L.s->meshes[m].rest) lm_scene_upload_mesh(L.s, m); // lm_scene_load_gpu
  return m;
}

// ---- materials -------------------------------------------------------------

// Image `src`'s encoded bytes into *bytes, *size: a view of its buffer, a
// data URI decoded into `storage` or the file beside the glTF read into it.
// 1 when read, 0 when there are none (a missing file), -1 with the error set
// when its bufferView is bad (messages start with `at`).
int image_bytes(Loader &L, const char *at, int src, const unsigned char **bytes, size_t *size,
                 std::vector<unsigned char> &storage) {
  const ImageRef &img = L.src->images[src];
  *bytes = nullptr, *size = 0;
  if (img.buffer_view >= 0) return view_bytes(L, at, img.buffer_view, bytes, size) ? 1 : -1;
  if (tinygltf::IsDataURI(img.uri)) {
    std::string mime;
    if (!tinygltf::DecodeDataURI(&storage, mime, img.uri, 0, false)) return 0;
  } else {
    std::string full = L.src->dir + "/" + tinygltf::dlib::urldecode(img.uri);
    lm_error ignored;
    char *file = lm_read_file(full.c_str(), size, &ignored);
    if (!file) return 0;
    storage.assign(file, file + *size);
    free(file);
  }
  *bytes = storage.data(), *size = storage.size();
  return *size > 0;
}

// "image N ('name or uri')" for messages and labels.
std::string image_label(const Loader &L, int src) {
  const ImageRef &img = L.src->images[src];
  std::string named = img.name.empty() ? img.uri.substr(0, 40) : img.name;
  return "image " + std::to_string(src) + (named.empty() ? "" : " ('" + named + "')");
}

// Every image a material names, decoded on all cores before the materials
// are read (texture_for takes them from L.decoded). An image whose bytes
// cannot be had is left to texture_for, which names the material.
void decode_images(Loader &L) {
  const tinygltf::Model &m = L.m;
  L.decoded.resize(L.src->images.size());
  std::vector<int> todo;
  std::vector<std::vector<unsigned char>> storage(L.src->images.size());
  std::vector<const unsigned char *> bytes(L.src->images.size());
  std::vector<size_t> sizes(L.src->images.size());
  for (const tinygltf::Material &gm : m.materials)
    for (int t : {gm.pbrMetallicRoughness.baseColorTexture.index, gm.pbrMetallicRoughness.metallicRoughnessTexture.index,
                  gm.normalTexture.index, gm.occlusionTexture.index, gm.emissiveTexture.index}) {
      int src = t >= 0 && (size_t)t < m.textures.size() ? m.textures[t].source : -1;
      if (src < 0 || (size_t)src >= L.src->images.size() || L.decoded[src].wanted) continue;
      L.decoded[src].wanted = true;
      lm_error quiet = {""};
      lm_error *err = L.err;
      L.err = &quiet; // a bad bufferView is named by texture_for, with its material
      if (image_bytes(L, "", src, &bytes[src], &sizes[src], storage[src]) == 1) todo.push_back(src);
      L.err = err;
    }
  std::atomic<size_t> next{0};
  auto work = [&]() {
    for (size_t i; (i = next++) < todo.size();) {
      int src = todo[i];
      Pending &d = L.decoded[src];
      lm_error why = {""};
      d.ok = lm_image_decode_rgba8(bytes[src], sizes[src], image_label(L, src).c_str(), &d.width, &d.height, &d.rgba,
                                   &why);
      d.error = why.msg;
      d.done = true;
    }
  };
  unsigned cores = std::max(1u, std::min(std::thread::hardware_concurrency(), (unsigned)todo.size()));
  std::vector<std::thread> threads;
  for (unsigned i = 1; i < cores; i++) threads.emplace_back(work);
  work();
  for (std::thread &t : threads) t.join();
}

// lm texture of texture `index` (for material `material`'s `what`): its
// image as decode_images left it (decoded here when it did not, as for a
// second use of one image, as colour and as data); colour images are
// sampled as sRGB, data images (`linear`) as they are. -1 on error.
int texture_for(Loader &L, int material, const char *what, int index, bool linear) {
  const tinygltf::Model &m = L.m;
  if (index < 0 || (size_t)index >= m.textures.size())
    return fail(L, "material %d: %s: texture %d does not exist (the file has %zu)", material, what, index,
                m.textures.size()), -1;
  int src = m.textures[index].source;
  const std::vector<ImageRef> &images = L.src->images;
  if (src < 0 || (size_t)src >= images.size())
    return fail(L, "material %d: %s: texture %d: image %d does not exist (the file has %zu)", material, what,
                index, src, images.size()), -1;
  int &cached = L.textures[(size_t)src * 2 + linear];
  if (cached >= 0) return cached;
  const ImageRef &img = images[src];
  std::string name = image_label(L, src);
  char at[LM_NAME_MAX + 160];
  snprintf(at, sizeof at, "material %d: %s: texture %d: %s", material, what, index, name.c_str());
  bool ahead = (size_t)src < L.decoded.size() && L.decoded[src].done && (L.decoded[src].rgba || !L.decoded[src].ok);
  Pending none, &d = ahead ? L.decoded[src] : none;
  if (!d.done) {
    const unsigned char *bytes;
    size_t size;
    std::vector<unsigned char> storage;
    int read = image_bytes(L, at, src, &bytes, &size, storage);
    if (read < 0) return -1;
    if (!read) return fail(L, "%s: no image data (a missing file?)", at), -1;
    lm_error why = {""};
    d.ok = lm_image_decode_rgba8(bytes, size, name.c_str(), &d.width, &d.height, &d.rgba, &why);
    d.error = why.msg;
  }
  if (!d.ok) return fail(L, "material %d: %s: texture %d: %s", material, what, index, d.error.c_str()), -1;
  int w = d.width, h = d.height;
  unsigned char *rgba = d.rgba;
  d.rgba = nullptr; // the scene's now
  char label[LM_NAME_MAX];
  snprintf(label, sizeof label, "%s", img.name.empty() ? name.c_str() : img.name.c_str());
  cached = lm_scene_add_texture(L.s, label, w, h, rgba);
  L.s->textures[cached].linear = linear;
  lm_error why = {""};
  if (L.s->gpu_only && !lm_scene_upload_texture(L.s, cached, &why)) // lm_scene_load_gpu
    return fail(L, "%s: %s", at, why.msg), -1;
  return cached;
}

// A number array of `n` finite values from extension object `o`'s `key`, if there.
bool ext_numbers(const tinygltf::Value &o, const char *key, double *out, int n) {
  if (!o.Has(key)) return true;
  const tinygltf::Value &v = o.Get(key);
  if (n == 1) {
    if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble())) return false;
    out[0] = v.GetNumberAsDouble();
    return true;
  }
  if (!v.IsArray() || v.ArrayLen() != (size_t)n) return false;
  for (int i = 0; i < n; i++) {
    if (!v.Get(i).IsNumber() || !std::isfinite(v.Get(i).GetNumberAsDouble())) return false;
    out[i] = v.Get(i).GetNumberAsDouble();
  }
  return true;
}

// Material texture `what` into slot `slot` of m, with its KHR_texture_transform.
bool material_texture(Loader &L, int material, const char *what, lm_texture_slot slot, int index, int tex_coord,
                      const tinygltf::ExtensionMap &ext, lm_material *m, lm_material_pbr *p) {
  if (index < 0) return true;
  auto it = ext.find("KHR_texture_transform");
  if (it != ext.end()) {
    const tinygltf::Value &o = it->second;
    double offset[2] = {0, 0}, rotation = 0, scale[2] = {1, 1}, coord = tex_coord;
    if (!o.IsObject() || !ext_numbers(o, "offset", offset, 2) || !ext_numbers(o, "rotation", &rotation, 1) ||
        !ext_numbers(o, "scale", scale, 2) || !ext_numbers(o, "texCoord", &coord, 1))
      return fail(L, "material %d: %s: KHR_texture_transform wants offset [2], rotation, scale [2] and "
                  "texCoord, finite numbers", material, what);
    tex_coord = (int)coord;
    // uv' = T(offset) R(rotation) S(scale) uv; rotation turns the UVs counter-clockwise (v points down).
    double c = std::cos(rotation), sn = std::sin(rotation);
    const double t[6] = {scale[0] * c, scale[1] * sn, offset[0], -scale[0] * sn, scale[1] * c, offset[1]};
    for (int k = 0; k < 6; k++) p->uv_transform[slot][k] = (float)t[k];
  }
  if (tex_coord != 0)
    lm_warn("%s: material %d: %s uses TEXCOORD_%d; only TEXCOORD_0 is read", L.path, material, what, tex_coord);
  bool linear = slot == LM_TEX_METALLIC_ROUGHNESS || slot == LM_TEX_NORMAL || slot == LM_TEX_OCCLUSION;
  int t = texture_for(L, material, what, index, linear);
  if (t < 0) return false;
  (slot == LM_TEX_BASE_COLOR ? m->base_color_texture : p->textures[slot]) = t + 1;
  return true;
}

// Number `field` of material extension object `o` (`extension`) into *v when
// there: finite and within lo..hi, else false naming the material and field.
bool glass_number(Loader &L, int index, const char *name, const tinygltf::Value &o, const char *extension,
                  const char *field, double lo, double hi, double *v) {
  double x = *v;
  if (!ext_numbers(o, field, &x, 1) || !(x >= lo && x <= hi))
    return fail(L, "material %d ('%s'): %s.%s must be a number in [%g, %g]", index, name, extension, field, lo, hi);
  *v = x;
  return true;
}

// KHR_materials_transmission, _ior and _volume, which Blender writes for
// glass, into p (lm_material_pbr's glass fields). Their textures are not
// read: one warning a file for each field.
bool glass_extensions(Loader &L, int index, const char *name, const tinygltf::ExtensionMap &ext,
                      lm_material_pbr *p) {
  double transmission = 0, ior = 1.5, thickness = 0, distance = 0, colour[3] = {1, 1, 1};
  for (const char *e : {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"}) {
    auto it = ext.find(e);
    if (it == ext.end()) continue;
    const tinygltf::Value &o = it->second;
    if (!o.IsObject()) return fail(L, "material %d ('%s'): %s must be an object", index, name, e);
    bool ok = !strcmp(e, "KHR_materials_transmission")
                  ? glass_number(L, index, name, o, e, "transmissionFactor", 0, 1, &transmission)
              : !strcmp(e, "KHR_materials_ior") ? glass_number(L, index, name, o, e, "ior", 1, 10, &ior)
              : glass_number(L, index, name, o, e, "thicknessFactor", 0, LM_GLTF_MAX_COORD, &thickness) &&
                    glass_number(L, index, name, o, e, "attenuationDistance", 0, INFINITY, &distance);
    if (!ok) return false;
    if (!strcmp(e, "KHR_materials_volume") && !ext_numbers(o, "attenuationColor", colour, 3))
      return fail(L, "material %d ('%s'): KHR_materials_volume.attenuationColor must be 3 numbers in [0, 1]",
                  index, name);
    for (const char *t : {"transmissionTexture", "thicknessTexture"}) {
      std::string field = std::string(e) + "." + t;
      if (!o.Has(t) || std::find(L.warned_glass.begin(), L.warned_glass.end(), field) != L.warned_glass.end())
        continue;
      lm_warn("%s: material %d ('%s'): %s is not read (the factor alone applies)", L.path, index, name,
              field.c_str());
      L.warned_glass.push_back(field);
    }
  }
  for (double c : colour)
    if (!(c >= 0 && c <= 1))
      return fail(L, "material %d ('%s'): KHR_materials_volume.attenuationColor must be 3 numbers in [0, 1]",
                  index, name);
  p->transmission = (float)transmission, p->ior = (float)ior, p->thickness = (float)thickness;
  p->attenuation_distance = std::isfinite(distance) ? (float)distance : 0.0f; /* infinite: no absorption */
  for (int c = 0; c < 3; c++) p->attenuation_color[c] = (float)colour[c];
  return true;
}

// lm material of glTF material `index`, converted on first use; -1 on error.
int material_for(Loader &L, const char *where, int index) {
  if (index < 0) return -1;
  if ((size_t)index >= L.m.materials.size())
    return fail(L, "%s: material %d does not exist (the file has %zu)", where, index,
                L.m.materials.size()), -1;
  if (L.materials[index] >= 0) return L.materials[index];
  const tinygltf::Material &gm = L.m.materials[index];
  const tinygltf::PbrMetallicRoughness &pbr = gm.pbrMetallicRoughness;
  if (pbr.baseColorFactor.size() != 4 || !finite_all(pbr.baseColorFactor) ||
      !std::isfinite(pbr.metallicFactor) || !std::isfinite(pbr.roughnessFactor))
    return fail(L, "material %d: baseColorFactor needs 4 finite numbers, metallicFactor and "
                "roughnessFactor finite ones", index), -1;
  if ((!gm.emissiveFactor.empty() && gm.emissiveFactor.size() != 3) || !finite_all(gm.emissiveFactor) ||
      !std::isfinite(gm.alphaCutoff) || !std::isfinite(gm.normalTexture.scale) ||
      !std::isfinite(gm.occlusionTexture.strength))
    return fail(L, "material %d: emissiveFactor needs 3 finite numbers; alphaCutoff, normalTexture.scale and "
                "occlusionTexture.strength finite ones", index), -1;
  lm_material m = {};
  snprintf(m.name, sizeof m.name, "%s", gm.name.empty() ? "material" : gm.name.c_str());
  float color[3];
  for (int c = 0; c < 3; c++) color[c] = clamp01(pbr.baseColorFactor[c]);
  float metal = clamp01(pbr.metallicFactor), rough = clamp01(pbr.roughnessFactor);
  lm_material phong = lm_gltf_phong(color, metal, rough);
  memcpy(phong.name, m.name, sizeof m.name);
  m = phong;

  // The metallic-roughness model as glTF gives it, for the pbr technique.
  lm_material_pbr p = {};
  p.set = true;
  p.metallic = metal, p.roughness = rough;
  p.normal_scale = (float)gm.normalTexture.scale;
  p.occlusion_strength = clamp01(gm.occlusionTexture.strength);
  if (!(pbr.baseColorFactor[3] >= 0 && pbr.baseColorFactor[3] <= 1))
    return fail(L, "material %d ('%s'): baseColorFactor's alpha must be in [0, 1] (got %g)", index, m.name,
                pbr.baseColorFactor[3]), -1;
  p.alpha = (float)pbr.baseColorFactor[3];
  p.alpha_mode = gm.alphaMode == "MASK" ? LM_ALPHA_MASK : gm.alphaMode == "BLEND" ? LM_ALPHA_BLEND : LM_ALPHA_OPAQUE;
  if (gm.alphaMode != "MASK" && gm.alphaMode != "BLEND" && gm.alphaMode != "OPAQUE" && !gm.alphaMode.empty())
    return fail(L, "material %d: alphaMode '%s' is none of OPAQUE, MASK, BLEND", index, gm.alphaMode.c_str()), -1;
  p.alpha_cutoff = (float)std::fmax(gm.alphaCutoff, 0.0);
  double strength = 1;
  auto es = gm.extensions.find("KHR_materials_emissive_strength");
  if (es != gm.extensions.end() && (!es->second.IsObject() ||
                                    !ext_numbers(es->second, "emissiveStrength", &strength, 1) || strength < 0))
    return fail(L, "material %d: KHR_materials_emissive_strength wants emissiveStrength, a finite number >= 0",
                index), -1;
  for (int c = 0; c < 3 && !gm.emissiveFactor.empty(); c++)
    p.emissive[c] = (float)(std::fmax(gm.emissiveFactor[c], 0.0) * strength);
  if (!glass_extensions(L, index, m.name, gm.extensions, &p)) return -1;
  // Blender writes glass as OPAQUE with transmission: seen through, so drawn blended (its alpha ignored).
  if (p.transmission > 0 && p.alpha_mode == LM_ALPHA_OPAQUE) p.alpha_mode = LM_ALPHA_BLEND, p.alpha = 1;
  if (p.transmission > 0 && p.alpha_mode == LM_ALPHA_MASK &&
      std::find(L.warned_glass.begin(), L.warned_glass.end(), "MASK") == L.warned_glass.end()) {
    lm_warn("%s: material %d ('%s'): transmission on an alphaMode MASK material is not drawn (opaque where "
            "not masked)", L.path, index, m.name);
    L.warned_glass.push_back("MASK");
  }
  if (!material_texture(L, index, "baseColorTexture", LM_TEX_BASE_COLOR, pbr.baseColorTexture.index,
                        pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions, &m, &p) ||
      !material_texture(L, index, "metallicRoughnessTexture", LM_TEX_METALLIC_ROUGHNESS,
                        pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                        pbr.metallicRoughnessTexture.extensions, &m, &p) ||
      !material_texture(L, index, "normalTexture", LM_TEX_NORMAL, gm.normalTexture.index,
                        gm.normalTexture.texCoord, gm.normalTexture.extensions, &m, &p) ||
      !material_texture(L, index, "occlusionTexture", LM_TEX_OCCLUSION, gm.occlusionTexture.index,
                        gm.occlusionTexture.texCoord, gm.occlusionTexture.extensions, &m, &p) ||
      !material_texture(L, index, "emissiveTexture", LM_TEX_EMISSIVE, gm.emissiveTexture.index,
                        gm.emissiveTexture.texCoord, gm.emissiveTexture.extensions, &m, &p))
    return -1;
  if (gm.extras.IsObject() && gm.extras.Has("reflectivity")) {
    const tinygltf::Value &r = gm.extras.Get("reflectivity");
    double v = r.IsNumber() ? r.GetNumberAsDouble() : -1;
    if (!(v >= 0 && v <= 1))
      return fail(L, "material %d ('%s'): extras.reflectivity must be a number in [0, 1]", index, m.name), -1;
    m.reflectivity = (float)v;
  }
  L.materials[index] = lm_scene_add_material(L.s, &m);
  L.s->material_pbr[L.materials[index]] = p;
  return L.materials[index];
}

// ---- nodes -----------------------------------------------------------------

// The node's matrix, or T * R * S kept beside its matrix (what channels replace).
bool local_transform(Loader &L, int ni, const tinygltf::Node &n, lm_node *out) {
  if (!n.matrix.empty()) {
    if (n.matrix.size() != 16 || !finite_all(n.matrix))
      return fail(L, "node %d: matrix needs 16 finite numbers", ni);
    for (int i = 0; i < 16; i++) out->local[i] = (float)n.matrix[i];
    return true;
  }
  double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
  if ((!n.translation.empty() && n.translation.size() != 3) ||
      (!n.rotation.empty() && n.rotation.size() != 4) || (!n.scale.empty() && n.scale.size() != 3) ||
      !finite_all(n.translation) || !finite_all(n.rotation) || !finite_all(n.scale))
    return fail(L, "node %d: translation, rotation and scale need 3, 4 and 3 finite numbers", ni);
  for (size_t i = 0; i < n.translation.size(); i++) t[i] = n.translation[i];
  for (size_t i = 0; i < n.scale.size(); i++) s[i] = n.scale[i];
  if (!n.rotation.empty()) {
    double len = std::sqrt(n.rotation[0] * n.rotation[0] + n.rotation[1] * n.rotation[1] +
                           n.rotation[2] * n.rotation[2] + n.rotation[3] * n.rotation[3]);
    if (!(len > 1e-12) || !std::isfinite(len))
      return fail(L, "node %d: rotation is not a usable quaternion", ni);
    for (int i = 0; i < 4; i++) q[i] = n.rotation[i] / len;
  }
  out->trs = true;
  for (int k = 0; k < 3; k++) out->translation[k] = (float)t[k], out->scale[k] = (float)s[k];
  for (int k = 0; k < 4; k++) out->rotation[k] = (float)q[k];
  lm_scene_trs_matrix(out->translation, out->rotation, out->scale, out->local);
  return true;
}

bool add_camera(Loader &L, int ni, int ci, int node) {
  if (ci < 0 || (size_t)ci >= L.m.cameras.size())
    return fail(L, "node %d: camera %d does not exist (the file has %zu)", ni, ci, L.m.cameras.size());
  const tinygltf::Camera &c = L.m.cameras[ci];
  if (c.type == "orthographic") {
    const tinygltf::OrthographicCamera &o = c.orthographic;
    if (!(o.xmag > 0 && o.xmag < 1e30) || !(o.ymag > 0 && o.ymag < 1e30) || !(o.znear >= 0) ||
        !(o.zfar > o.znear && o.zfar < 1e30))
      return fail(L, "camera %d: orthographic wants xmag, ymag > 0 and zfar > znear >= 0; got %g, %g, %g, %g",
                  ci, o.xmag, o.ymag, o.znear, o.zfar);
    lm_camera cam = {};
    snprintf(cam.name, sizeof cam.name, "%s", c.name.empty() ? "camera" : c.name.c_str());
    cam.fov_y = (float)(M_PI / 4);
    cam.znear = (float)std::fmax(o.znear, 1e-6), cam.zfar = (float)o.zfar;
    cam.ortho[0] = (float)o.xmag, cam.ortho[1] = (float)o.ymag;
    cam.node = node;
    lm_scene_add_camera(L.s, &cam);
    return true;
  }
  if (c.type != "perspective")
    return fail(L, "camera %d: type '%s' is neither perspective nor orthographic", ci, c.type.c_str());
  const tinygltf::PerspectiveCamera &p = c.perspective;
  if (!(p.yfov > 0 && p.yfov < M_PI) || !(p.znear > 0 && p.znear < 1e30) ||
      !(p.zfar == 0 || (p.zfar > p.znear && p.zfar < 1e30)))
    return fail(L, "camera %d: want 0 < yfov < pi, znear > 0 and zfar > znear (or absent); "
                "got %g, %g, %g", ci, p.yfov, p.znear, p.zfar);
  lm_camera cam = {};
  snprintf(cam.name, sizeof cam.name, "%s", c.name.empty() ? "camera" : c.name.c_str());
  cam.fov_y = (float)p.yfov;
  cam.znear = (float)p.znear;
  cam.zfar = p.zfar > 0 ? (float)p.zfar : LM_GLTF_INFINITE_ZFAR_RATIO * cam.znear;
  cam.node = node;
  if (p.aspectRatio > 0 && p.aspectRatio < 1e6) cam.aspect = (float)p.aspectRatio;
  lm_scene_add_camera(L.s, &cam);
  return true;
}

// The node's KHR_lights_punctual light index, -1 when none; -2 when malformed.
int node_light(const tinygltf::Node &n) {
  auto it = n.extensions.find("KHR_lights_punctual");
  if (it == n.extensions.end()) return -1;
  const tinygltf::Value &ext = it->second;
  if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber()) return -2;
  double d = ext.Get("light").GetNumberAsDouble();
  return d >= 0 && d < 1e9 && d == std::floor(d) ? (int)d : -2;
}

bool add_light(Loader &L, int ni, int li, int node) {
  if (li < 0 || (size_t)li >= L.m.lights.size())
    return fail(L, "node %d: KHR_lights_punctual light %d does not exist (the file has %zu)", ni,
                li, L.m.lights.size());
  const tinygltf::Light &gl = L.m.lights[li];
  lm_light l = {};
  snprintf(l.name, sizeof l.name, "%s", gl.name.empty() ? "light" : gl.name.c_str());
  if (gl.type == "point") l.type = LM_LIGHT_POINT;
  else if (gl.type == "spot") l.type = LM_LIGHT_SPOT;
  else if (gl.type == "directional") l.type = LM_LIGHT_DIRECTIONAL;
  else return fail(L, "light %d: type '%s' is none of point, spot, directional", li, gl.type.c_str());
  char what[LM_NAME_MAX + 32]; // "light 2" or "light 2 ('lamp')"
  snprintf(what, sizeof what, gl.name.empty() ? "light %d" : "light %d ('%s')", li, gl.name.c_str());
  if ((!gl.color.empty() && gl.color.size() != 3) || !finite_all(gl.color))
    return fail(L, "%s: color needs 3 finite numbers", what);
  double peak = gl.color.empty() ? 1.0 : std::max({gl.color[0], gl.color[1], gl.color[2]});
  if (!gl.color.empty() && std::min({gl.color[0], gl.color[1], gl.color[2]}) < 0)
    return fail(L, "%s: color (%g, %g, %g) has a negative component (light is never negative)", what,
                gl.color[0], gl.color[1], gl.color[2]);
  if (!(gl.intensity >= 0 && gl.intensity < 1e30))
    return fail(L, "%s: intensity %g is not a number in [0, 1e30)", what, gl.intensity);
  if (!(gl.range >= 0 && gl.range < 1e30))
    return fail(L, "%s: range %g is not a number in [0, 1e30)", what, gl.range);
  // The light a pass computes is intensity times colour, in floats: bounded as the intensity is.
  if (!(gl.intensity * peak < 1e30))
    return fail(L, "%s: intensity %g times color %g is past 1e30 (a pass's light would overflow)", what,
                gl.intensity, peak);
  double inner = gl.spot.innerConeAngle, outer = gl.spot.outerConeAngle;
  if (l.type == LM_LIGHT_SPOT && !(inner >= 0 && inner < outer && outer <= M_PI / 2))
    return fail(L, "light %d: spot cone angles need 0 <= inner < outer <= pi/2; got %g, %g", li,
                inner, outer);
  for (int c = 0; c < 3; c++) l.color[c] = gl.color.empty() ? 1.0f : (float)gl.color[c];
  l.power = (float)(gl.intensity * LM_GLTF_EXPOSURE);
  l.radius = (float)gl.range; // 0 (absent): no range, the light reaches everywhere
  l.falloff = LM_FALLOFF_RANGE;
  l.inner_cone = l.type == LM_LIGHT_SPOT ? (float)inner : 0.0f;
  l.outer_cone = l.type == LM_LIGHT_SPOT ? (float)outer : (float)(M_PI / 2);
  if (gl.extras.IsObject() && gl.extras.Has("size")) { // soft shadows: see lm_light.size
    const tinygltf::Value &v = gl.extras.Get("size");
    double size = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
    if (!(size >= 0 && size < 1e30))
      return fail(L, "light %d: extras.size must be a finite number >= 0 (the light's diameter, radians "
                     "for a directional light)", li);
    l.size = (float)size;
  }
  l.casts_shadows = true;
  l.node = node;
  lm_scene_add_light(L.s, &l);
  return true;
}

// The node's mesh: on the node itself when it has one primitive, else one
// child per primitive. Nodes share a mesh's lm meshes unless it deforms. A
// morphing mesh's nodes get their weights: the node's, else the mesh's.
bool add_mesh(Loader &L, int ni, int mi, int lm_node) {
  if (mi < 0 || (size_t)mi >= L.m.meshes.size())
    return fail(L, "node %d: mesh %d does not exist (the file has %zu)", ni, mi, L.m.meshes.size());
  const tinygltf::Mesh &mesh = L.m.meshes[mi];
  const tinygltf::Node &node = L.m.nodes[ni];
  size_t targets = mesh.primitives.empty() ? 0 : mesh.primitives[0].targets.size();
  for (size_t pi = 1; pi < mesh.primitives.size(); pi++)
    if (mesh.primitives[pi].targets.size() != targets)
      return fail(L, "mesh %d: primitive %zu has %zu morph targets, primitive 0 has %zu (glTF wants the same)", mi,
                  pi, mesh.primitives[pi].targets.size(), targets);
  if ((!mesh.weights.empty() && mesh.weights.size() != targets) || !finite_all(mesh.weights))
    return fail(L, "mesh %d: weights has %zu numbers for %zu morph targets (or one is not finite)", mi,
                mesh.weights.size(), targets);
  if ((!node.weights.empty() && node.weights.size() != targets) || !finite_all(node.weights))
    return fail(L, "node %d: weights has %zu numbers for the %zu morph targets of mesh %d (or one is not finite)", ni,
                node.weights.size(), targets, mi);
  std::vector<int> &cache = L.meshes[mi];
  std::vector<int> ids = cache;
  if (cache.empty() || deformable(mesh)) {
    ids.clear();
    for (size_t pi = 0; pi < mesh.primitives.size(); pi++) {
      int id = load_primitive(L, mi, (int)pi);
      if (id == -1) return false;
      ids.push_back(id);
    }
    L.src->file.release();
    for (const auto &bin : L.src->bins) bin->release();
    if (cache.empty()) cache = ids;
  }
  static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  for (size_t pi = 0; pi < mesh.primitives.size(); pi++) {
    if (ids[pi] < 0) continue;
    char where[64];
    snprintf(where, sizeof where, "mesh %d primitive %zu", mi, pi);
    int mat = material_for(L, where, mesh.primitives[pi].material);
    if (mat == -1 && mesh.primitives[pi].material >= 0) return false;
    int holder = lm_node;
    if (mesh.primitives.size() == 1) {
      L.s->nodes[lm_node].mesh = ids[pi];
      L.s->nodes[lm_node].material = mat;
    } else {
      char name[LM_NAME_MAX];
      snprintf(name, sizeof name, "%s.%zu", L.s->nodes[lm_node].name, pi);
      holder = lm_scene_add_node(L.s, name, lm_node, identity, ids[pi], mat);
    }
    L.holders[ni].push_back(holder);
    if (targets) {
      const std::vector<double> &w = node.weights.empty() ? mesh.weights : node.weights;
      float *weights = (float *)lm_alloc(sizeof(float) * targets);
      for (size_t t = 0; t < w.size(); t++) weights[t] = (float)w[t];
      L.s->nodes[holder].weights = weights;
    }
  }
  return true;
}

// EXT_mesh_gpu_instancing: the node's mesh drawn once per instance, each
// placed by the node's transform times its own TRS. Each instance becomes a
// child node ("<node>[i]") holding the mesh, so that the instanced draw of
// nodes sharing a mesh (lm_scene_draw) draws them, channels on the node move
// them all, and the bounds and the tracer see each copy. false (and nothing
// added) when the node has none; bad data fails naming the node and field.
bool add_instances(Loader &L, int ni, int lm_node, bool *instanced) {
  const tinygltf::Node &n = L.m.nodes[ni];
  auto it = n.extensions.find("EXT_mesh_gpu_instancing");
  *instanced = it != n.extensions.end();
  if (!*instanced) return true;
  char where[LM_NAME_MAX + 64];
  snprintf(where, sizeof where, "node %d ('%s'): EXT_mesh_gpu_instancing", ni, L.s->nodes[lm_node].name);
  const tinygltf::Value &ext = it->second;
  if (n.mesh < 0) return fail(L, "%s: the node has no mesh to instance", where);
  if (!ext.IsObject() || !ext.Has("attributes") || !ext.Get("attributes").IsObject())
    return fail(L, "%s: attributes: want an object of TRANSLATION, ROTATION, SCALE accessors", where);
  const tinygltf::Value &attrs = ext.Get("attributes");
  static const char *const names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
  View views[3];
  bool present[3] = {false, false, false};
  size_t count = 0;
  for (int k = 0; k < 3; k++) {
    if (!attrs.Has(names[k])) continue;
    char what[LM_NAME_MAX + 96];
    snprintf(what, sizeof what, "%s: attributes.%s", where, names[k]);
    const tinygltf::Value &a = attrs.Get(names[k]);
    double index = a.IsNumber() ? a.GetNumberAsDouble() : -1;
    if (!(index >= 0 && index < 1e9 && index == std::floor(index)))
      return fail(L, "%s: want an accessor index", what);
    if (!accessor_view(L, what, (int)index, k == 1 ? 4 : 3, &views[k])) return false;
    if (count && views[k].count != count)
      return fail(L, "%s: accessor %d has %zu elements, the other attributes %zu", what, (int)index,
                  views[k].count, count);
    count = views[k].count;
    present[k] = true;
  }
  if (!count) return fail(L, "%s: attributes names none of TRANSLATION, ROTATION, SCALE", where);
  for (size_t i = 0; i < count; i++) {
    float v[3][4] = {{0, 0, 0, 0}, {0, 0, 0, 1}, {1, 1, 1, 0}};
    for (int k = 0; k < 3; k++)
      for (int c = 0; present[k] && c < (k == 1 ? 4 : 3); c++) {
        double x = view_get(views[k], i, c);
        if (!std::isfinite(x) || std::fabs(x) > LM_GLTF_MAX_COORD)
          return fail(L, "%s: attributes.%s: element %zu has a non-finite or huge value (%g)", where, names[k], i, x);
        v[k][c] = (float)x;
      }
    double len = std::sqrt((double)v[1][0] * v[1][0] + (double)v[1][1] * v[1][1] + (double)v[1][2] * v[1][2] +
                           (double)v[1][3] * v[1][3]);
    if (!(len > 1e-6)) return fail(L, "%s: attributes.ROTATION: element %zu is not a usable quaternion", where, i);
    for (int c = 0; c < 4; c++) v[1][c] = (float)(v[1][c] / len);
    float local[16];
    lm_scene_trs_matrix(v[0], v[1], v[2], local);
    char name[LM_NAME_MAX];
    snprintf(name, sizeof name, "%.40s[%zu]", L.s->nodes[lm_node].name, i);
    int child = lm_scene_add_node(L.s, name, lm_node, local, -1, -1);
    if (!add_mesh(L, ni, n.mesh, child)) return false;
  }
  return true;
}

bool add_node(Loader &L, int ni, int parent, int *out) {
  const tinygltf::Node &n = L.m.nodes[ni];
  lm_node pose = {};
  pose.rotation[3] = pose.scale[0] = pose.scale[1] = pose.scale[2] = 1;
  if (!local_transform(L, ni, n, &pose)) return false;
  char name[LM_NAME_MAX];
  if (n.name.empty()) snprintf(name, sizeof name, "node%d", ni);
  else snprintf(name, sizeof name, "%s", n.name.c_str());
  int id = *out = lm_scene_add_node(L.s, name, parent, pose.local, -1, -1);
  lm_node *node = &L.s->nodes[id];
  node->trs = pose.trs;
  memcpy(node->translation, pose.translation, sizeof pose.translation);
  memcpy(node->rotation, pose.rotation, sizeof pose.rotation);
  memcpy(node->scale, pose.scale, sizeof pose.scale);
  L.nodes[ni] = id;
  bool instanced;
  if (!add_instances(L, ni, id, &instanced)) return false;
  if (n.mesh >= 0 && !instanced && !add_mesh(L, ni, n.mesh, id)) return false;
  if (n.camera >= 0 && !add_camera(L, ni, n.camera, id)) return false;
  int li = node_light(n);
  if (li == -2) return fail(L, "node %d: KHR_lights_punctual wants {\"light\": index}", ni);
  if (li >= 0 && !add_light(L, ni, li, id)) return false;
  return true;
}

// The scene's root nodes: the default scene's, scene 0's, or every node no
// other node names as a child.
bool root_nodes(Loader &L, std::vector<int> &roots) {
  const tinygltf::Model &m = L.m;
  if (m.scenes.empty()) {
    std::vector<char> child(m.nodes.size(), 0);
    for (const tinygltf::Node &n : m.nodes)
      for (int c : n.children)
        if (c >= 0 && (size_t)c < child.size()) child[c] = 1;
    for (size_t i = 0; i < m.nodes.size(); i++)
      if (!child[i]) roots.push_back((int)i);
    return true;
  }
  int si = m.defaultScene < 0 ? 0 : m.defaultScene;
  if ((size_t)si >= m.scenes.size())
    return fail(L, "scene %d does not exist (the file has %zu)", si, m.scenes.size());
  for (int r : m.scenes[si].nodes) {
    if (r < 0 || (size_t)r >= m.nodes.size())
      return fail(L, "scene %d: node %d does not exist (the file has %zu)", si, r, m.nodes.size());
    roots.push_back(r);
  }
  return true;
}

// Depth first with an explicit stack (a deep file cannot overflow ours),
// parents before children as lm_scene_update wants. A node met twice is a
// cycle or a child of two parents: glTF allows neither.
bool load_nodes(Loader &L) {
  std::vector<int> roots;
  if (!root_nodes(L, roots)) return false;
  std::vector<std::pair<int, int>> stack; // (glTF node, lm parent)
  for (size_t i = roots.size(); i-- > 0;) stack.push_back({roots[i], -1});
  while (!stack.empty()) {
    auto [ni, parent] = stack.back();
    stack.pop_back();
    if (L.nodes[ni] >= 0)
      return fail(L, "node %d is reached twice (a cycle, or a child of two parents)", ni);
    int id;
    if (!add_node(L, ni, parent, &id)) return false;
    const std::vector<int> &children = L.m.nodes[ni].children;
    for (size_t i = children.size(); i-- > 0;) {
      int c = children[i];
      if (c < 0 || (size_t)c >= L.m.nodes.size())
        return fail(L, "node %d: child %d does not exist (the file has %zu)", ni, c,
                    L.m.nodes.size());
      stack.push_back({c, id});
    }
  }
  return true;
}

// Finite transforms can still multiply past float range down a hierarchy; and
// a camera's world transform must invert, since its view matrix is the inverse.
bool check_world(Loader &L) {
  for (size_t ni = 0; ni < L.nodes.size(); ni++) {
    if (L.nodes[ni] < 0) continue;
    const float *w = L.s->nodes[L.nodes[ni]].world;
    for (int k = 0; k < 16; k++)
      if (!std::isfinite(w[k]) || std::fabs(w[k]) > LM_GLTF_MAX_COORD)
        return fail(L, "node %zu: world transform reaches %g (more than %g): scales or "
                    "translations too large", ni, (double)w[k], (double)LM_GLTF_MAX_COORD);
  }
  for (int ci = 0; ci < L.s->camera_count; ci++) {
    if (!lm_scene_camera_invertible(L.s, ci))
      return fail(L, "camera '%s' on node '%s': its world transform has (near) zero scale and "
                  "cannot be inverted into a view", L.s->cameras[ci].name,
                  L.s->nodes[L.s->cameras[ci].node].name);
  }
  return true;
}

// ---- skins -----------------------------------------------------------------

// lm skin of glTF skin si: joints as lm nodes, inverse bind matrices
// (identity when the file has none). Its index in *out; false on bad data.
bool add_skin(Loader &L, int si, int *out) {
  const tinygltf::Skin &sk = L.m.skins[si];
  char where[LM_NAME_MAX + 32];
  if (sk.name.empty()) snprintf(where, sizeof where, "skin %d", si);
  else snprintf(where, sizeof where, "skin %d ('%.*s')", si, LM_NAME_MAX - 1, sk.name.c_str());
  size_t n = sk.joints.size();
  if (n == 0) return fail(L, "%s: joints is empty", where);
  if (n > LM_SKIN_MAX_JOINTS)
    return fail(L, "%s: joints: %zu joints, more than the %d the engine takes", where, n, LM_SKIN_MAX_JOINTS);
  std::vector<int> joints(n);
  for (size_t j = 0; j < n; j++) {
    int jn = sk.joints[j];
    if (jn < 0 || (size_t)jn >= L.m.nodes.size())
      return fail(L, "%s: joints[%zu]: node %d does not exist (the file has %zu)", where, j, jn, L.m.nodes.size());
    if (L.nodes[jn] < 0) return fail(L, "%s: joints[%zu]: node %d is not in the scene", where, j, jn);
    joints[j] = L.nodes[jn];
  }
  std::vector<float> bind(n * 16, 0.0f);
  for (size_t j = 0; j < n; j++)
    for (int k = 0; k < 4; k++) bind[j * 16 + k * 5] = 1;
  if (sk.inverseBindMatrices >= 0) {
    char what[LM_NAME_MAX + 64];
    snprintf(what, sizeof what, "%s: inverseBindMatrices", where);
    View v;
    int ai = sk.inverseBindMatrices;
    if (!accessor_view(L, what, ai, 16, &v)) return false;
    if (v.type != TINYGLTF_COMPONENT_TYPE_FLOAT)
      return fail(L, "%s: accessor %d has component type %d, not floats (5126)", what, ai, v.type);
    if (v.count < n) return fail(L, "%s: accessor %d has %zu matrices for %zu joints", what, ai, v.count, n);
    for (size_t j = 0; j < n; j++)
      for (int k = 0; k < 16; k++)
        if (!read_coord(L, v, what, ai, "matrix", j, k, &bind[j * 16 + k])) return false;
  }
  lm_skin *k = push(L.s->skins, L.s->skin_count, L.s->skin_cap);
  snprintf(k->name, sizeof k->name, "%s", sk.name.empty() ? where : sk.name.c_str());
  k->joints = (int *)memcpy(lm_alloc(sizeof(int) * n), joints.data(), sizeof(int) * n);
  k->inverse_bind = (float *)memcpy(lm_alloc(sizeof(float) * 16 * n), bind.data(), sizeof(float) * 16 * n);
  k->joint_count = (int)n;
  *out = L.s->skin_count - 1;
  return true;
}

// The skins of the scene's nodes, given to the lm nodes that hold their
// meshes; every influence with a weight must name one of the skin's joints.
bool load_skins(Loader &L) {
  std::vector<int> skins(L.m.skins.size(), -1); // [glTF skin] -> lm skin
  for (size_t ni = 0; ni < L.m.nodes.size(); ni++) {
    int si = L.m.nodes[ni].skin;
    if (si < 0 || L.nodes[ni] < 0) continue;
    if ((size_t)si >= L.m.skins.size())
      return fail(L, "node %zu: skin %d does not exist (the file has %zu)", ni, si, L.m.skins.size());
    if (skins[si] < 0 && !add_skin(L, si, &skins[si])) return false;
    for (int h : L.holders[ni]) {
      L.s->nodes[h].skin = skins[si];
      lm_scene_mesh *m = &L.s->meshes[L.s->nodes[h].mesh];
      int joints = L.s->skins[skins[si]].joint_count, per_vertex = 4 * m->influence_sets;
      for (size_t i = 0; i < (size_t)m->vertex_count * per_vertex; i++) {
        if (m->joints[i] < joints) continue;
        if (m->joint_weights[i] > 0)
          return fail(L, "node %zu: mesh '%s': JOINTS_%zu of vertex %zu names joint %d, past the %d joints of skin %d",
                      ni, m->name, i % per_vertex / 4, i / per_vertex, m->joints[i], joints, si);
        m->joints[i] = 0; // no weight: no matter which
      }
    }
  }
  return true;
}

// ---- animations ------------------------------------------------------------

// Channel ci of animation ai into lm channels (a weights channel: one for
// each lm node that holds a primitive of the target's mesh). Bad data fails
// the file naming the animation, the channel and the field; a channel the
// engine cannot use (another path, a node outside the scene) is skipped.
bool add_channel(Loader &L, int ai, int ci) {
  const tinygltf::Animation &ga = L.m.animations[ai];
  const tinygltf::AnimationChannel &gc = ga.channels[ci];
  char where[LM_NAME_MAX + 96], what[LM_NAME_MAX + 160];
  snprintf(where, sizeof where, "animation %d ('%s') channel %d", ai, L.s->animations[ai].name, ci);
  auto skip = [&](const std::string &why) {
    if (!L.skipped_channels++) L.first_channel = std::string(where) + ": " + why;
    return true;
  };
  static const char *const kPaths[] = {"translation", "rotation", "scale", "weights"};
  int path = -1;
  for (int k = 0; k < 4; k++)
    if (gc.target_path == kPaths[k]) path = k;
  if (path < 0) return skip("target.path '" + gc.target_path + "'");
  if (gc.target_node < 0) return skip("no target.node");
  if ((size_t)gc.target_node >= L.m.nodes.size())
    return fail(L, "%s: target.node %d does not exist (the file has %zu)", where, gc.target_node, L.m.nodes.size());
  int node = L.nodes[gc.target_node];
  if (node < 0) return skip("target.node " + std::to_string(gc.target_node) + " is not in the scene");
  const char *node_name = L.s->nodes[node].name;
  if (path != LM_ANIM_WEIGHTS && !L.s->nodes[node].trs)
    return fail(L, "%s: target.node %d ('%s') has a matrix, and glTF lets no animation move such a node", where,
                gc.target_node, node_name);
  if (gc.sampler < 0 || (size_t)gc.sampler >= ga.samplers.size())
    return fail(L, "%s: sampler %d does not exist (the animation has %zu)", where, gc.sampler, ga.samplers.size());
  const tinygltf::AnimationSampler &gs = ga.samplers[gc.sampler];
  lm_anim_interp interp = gs.interpolation == "STEP" ? LM_ANIM_STEP
                          : gs.interpolation == "CUBICSPLINE" ? LM_ANIM_CUBICSPLINE : LM_ANIM_LINEAR;
  if (gs.interpolation != "STEP" && gs.interpolation != "CUBICSPLINE" && gs.interpolation != "LINEAR")
    return fail(L, "%s: sampler %d: interpolation '%s' is none of LINEAR, STEP, CUBICSPLINE", where, gc.sampler,
                gs.interpolation.c_str());
  bool cubic = interp == LM_ANIM_CUBICSPLINE;

  std::vector<int> holders; // a weights channel's lm nodes, and their target count
  int targets = 0;
  if (path == LM_ANIM_WEIGHTS) {
    for (int h : L.holders[gc.target_node])
      if (L.s->meshes[L.s->nodes[h].mesh].target_count > 0) {
        holders.push_back(h);
        targets = L.s->meshes[L.s->nodes[h].mesh].target_count;
      }
    if (!targets)
      return fail(L, "%s: target.node %d ('%s') has no mesh with morph targets for its weights", where,
                  gc.target_node, node_name);
  }
  int width = path == LM_ANIM_ROTATION ? 4 : path == LM_ANIM_WEIGHTS ? targets : 3;

  snprintf(what, sizeof what, "%s: sampler %d: input", where, gc.sampler);
  View in;
  if (!accessor_view(L, what, gs.input, 1, &in)) return false;
  if (in.type != TINYGLTF_COMPONENT_TYPE_FLOAT)
    return fail(L, "%s: accessor %d has component type %d; times are floats (5126)", what, gs.input, in.type);
  size_t n = in.count;
  std::vector<float> times(n);
  for (size_t i = 0; i < n; i++) {
    double t = view_get(in, i, 0);
    if (!std::isfinite(t)) return fail(L, "%s: accessor %d: time %zu is not finite", what, gs.input, i);
    times[i] = (float)t;
    if (i > 0 && !(times[i] > times[i - 1]))
      return fail(L, "%s: accessor %d: time %zu (%g) is not after time %zu (%g): times must increase", what,
                  gs.input, i, t, i - 1, (double)times[i - 1]);
  }
  if (cubic && n < 2)
    return fail(L, "%s: a CUBICSPLINE sampler needs 2 keys or more; it has %zu", what, n);

  snprintf(what, sizeof what, "%s: sampler %d: output", where, gc.sampler);
  View out;
  int ncomp = path == LM_ANIM_WEIGHTS ? 1 : width;
  if (!accessor_view(L, what, gs.output, ncomp, &out)) return false;
  bool may_normalize = path == LM_ANIM_ROTATION || path == LM_ANIM_WEIGHTS;
  if (out.type != TINYGLTF_COMPONENT_TYPE_FLOAT && !(may_normalize && normalized_int(out)))
    return fail(L, "%s: accessor %d has component type %d%s; %s wants floats%s", what, gs.output, out.type,
                out.normalized ? ", normalized" : "", kPaths[path], may_normalize ? " or normalized integers" : "");
  size_t per_key = (cubic ? 3 : 1) * (path == LM_ANIM_WEIGHTS ? (size_t)targets : 1);
  if (out.count != n * per_key) {
    if (path == LM_ANIM_WEIGHTS && out.count % (n * (cubic ? 3 : 1)) == 0)
      return fail(L, "%s: accessor %d holds %zu weights a key, but the mesh of target.node %d ('%s') has %d morph "
                  "targets", what, gs.output, out.count / (n * (cubic ? 3 : 1)), gc.target_node, node_name, targets);
    return fail(L, "%s: accessor %d has %zu elements for the input's %zu keys (want %zu%s)", what, gs.output,
                out.count, n, n * per_key, cubic ? ": CUBICSPLINE keys are in-tangent, value, out-tangent" : "");
  }
  std::vector<float> values(out.count * (size_t)ncomp);
  for (size_t e = 0; e < out.count; e++)
    for (int c = 0; c < ncomp; c++) {
      double x = view_get(out, e, c);
      if (!std::isfinite(x) || std::fabs(x) > LM_GLTF_MAX_COORD)
        return fail(L, "%s: accessor %d: element %zu has a non-finite or huge value (%g)", what, gs.output, e, x);
      values[e * (size_t)ncomp + (size_t)c] = (float)x;
    }
  if (path == LM_ANIM_ROTATION) // unit quaternions, so that slerp stays on the sphere (tangents as they are)
    for (size_t k = 0; k < n; k++) {
      float *q = &values[(cubic ? 3 * k + 1 : k) * 4];
      double len = std::sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
      if (!(len > 1e-12))
        return fail(L, "%s: accessor %d: key %zu is no rotation (a zero quaternion)", what, gs.output, k);
      for (int c = 0; c < 4; c++) q[c] = (float)(q[c] / len);
    }

  if (path != LM_ANIM_WEIGHTS) holders.assign(1, node);
  lm_animation *a = &L.s->animations[ai];
  for (int h : holders) {
    a->channels = (lm_anim_channel *)lm_realloc(a->channels, sizeof *a->channels * (size_t)(a->channel_count + 1));
    lm_anim_channel *c = &a->channels[a->channel_count++];
    c->node = h;
    c->path = (lm_anim_path)path;
    c->interp = interp;
    c->count = (int)n;
    c->width = width;
    c->times = (float *)memcpy(lm_alloc(sizeof(float) * n), times.data(), sizeof(float) * n);
    c->values = (float *)memcpy(lm_alloc(sizeof(float) * values.size()), values.data(), sizeof(float) * values.size());
    if (a->channel_count == 1 || times[0] < a->start) a->start = times[0];
    if (a->channel_count == 1 || times[n - 1] > a->end) a->end = times[n - 1];
  }
  return true;
}

// Every animation of the file, in its order (an unnamed one: "animation N"),
// even one left without channels, so that indices stay the file's.
bool load_animations(Loader &L) {
  for (size_t ai = 0; ai < L.m.animations.size(); ai++) {
    const tinygltf::Animation &ga = L.m.animations[ai];
    lm_animation *a = push(L.s->animations, L.s->animation_count, L.s->animation_cap);
    if (ga.name.empty()) snprintf(a->name, sizeof a->name, "animation %zu", ai);
    else snprintf(a->name, sizeof a->name, "%s", ga.name.c_str());
    for (size_t ci = 0; ci < ga.channels.size(); ci++)
      if (!add_channel(L, (int)ai, (int)ci)) return false;
  }
  return true;
}

// ---- defaults --------------------------------------------------------------

// World-space bounds of every mesh node's vertices; a unit box when none.
void scene_bounds(const lm_scene *s, double lo[3], double hi[3]) {
  bool any = false;
  for (int k = 0; k < 3; k++) lo[k] = INFINITY, hi[k] = -INFINITY;
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->mesh < 0) continue;
    const lm_scene_mesh *m = &s->meshes[n->mesh];
    const float *w = n->world;
    std::vector<float> back; // a mesh already on the GPU (lm_scene_load_gpu): as it is drawn
    if (!m->vertices) {
      back.resize((size_t)m->vertex_count * 8);
      std::vector<uint32_t> indices((size_t)m->index_count);
      lm_mesh_read(&m->gpu, back.data(), m->vertex_count, indices.data(), m->index_count);
    }
    const float *vertices = m->vertices ? m->vertices : back.data();
    for (int v = 0; v < m->vertex_count; v++) {
      const float *p = vertices + v * 8;
      for (int k = 0; k < 3; k++) {
        double x = (double)w[k] * p[0] + (double)w[4 + k] * p[1] + (double)w[8 + k] * p[2] + w[12 + k];
        if (!std::isfinite(x)) continue; // a degenerate transform: leave this one out
        lo[k] = std::fmin(lo[k], x), hi[k] = std::fmax(hi[k], x);
        any = true;
      }
    }
  }
  for (int k = 0; k < 3 && any; k++)
    if (!(lo[k] <= hi[k])) any = false;
  if (!any)
    for (int k = 0; k < 3; k++) lo[k] = -0.5, hi[k] = 0.5;
}

// A node at `eye` whose -Z points along `dir` (+Y up, unless dir is vertical).
void look_along(const double eye[3], const double dir[3], float out[16]) {
  double len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  double z[3] = {-dir[0] / len, -dir[1] / len, -dir[2] / len};
  double up[3] = {0, 1, 0};
  if (std::fabs(z[1]) > 0.999) up[1] = 0, up[2] = 1;
  double x[3] = {up[1] * z[2] - up[2] * z[1], up[2] * z[0] - up[0] * z[2], up[0] * z[1] - up[1] * z[0]};
  double xl = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  for (int k = 0; k < 3; k++) x[k] /= xl;
  double y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
  for (int k = 0; k < 3; k++) {
    out[k] = (float)x[k], out[4 + k] = (float)y[k], out[8 + k] = (float)z[k];
    out[12 + k] = (float)eye[k];
  }
  out[3] = out[7] = out[11] = 0, out[15] = 1;
}

void add_defaults(lm_scene *s) {
  if (s->light_count && s->camera_count) return;
  double lo[3], hi[3], c[3], diag = 0;
  scene_bounds(s, lo, hi);
  for (int k = 0; k < 3; k++) c[k] = 0.5 * (lo[k] + hi[k]), diag += (hi[k] - lo[k]) * (hi[k] - lo[k]);
  diag = std::fmax(std::sqrt(diag), 1e-3);

  float m[16];
  if (s->light_count == 0) {
    double dir[3] = {-0.3, -1.0, -0.5}, eye[3];
    for (int k = 0; k < 3; k++) eye[k] = c[k] - dir[k] * diag;
    look_along(eye, dir, m);
    lm_light l = {};
    snprintf(l.name, sizeof l.name, "default_light");
    l.type = LM_LIGHT_DIRECTIONAL;
    l.color[0] = l.color[1] = l.color[2] = 1;
    l.power = 1;
    l.radius = (float)std::fmax(2 * diag, 1.0);
    l.outer_cone = (float)(M_PI / 2);
    l.casts_shadows = true;
    l.node = lm_scene_add_node(s, "default_light", -1, m, -1, -1);
    lm_scene_add_light(s, &l);
  }
  lm_scene_update(s);
  if (s->camera_count == 0) lm_scene_add_framing_camera(s, "default_camera", 0);
}

// ---- parsing ---------------------------------------------------------------

// tinygltf's message, first line only, with any data URI it quotes (a whole
// buffer in base64) cut to its head.
std::string first_line(const std::string &s) {
  std::string t = s.substr(0, s.find('\n'));
  for (size_t at = t.find("data:"); at != std::string::npos; at = t.find("data:", at + 1)) {
    size_t end = t.find_first_of(" '\"", at);
    if (end == std::string::npos) end = t.size();
    if (end - at > 48) t.replace(at + 40, end - at - 40, "...");
  }
  return t.empty() ? "not a glTF file" : t;
}

// tinygltf refuses a primitive whose indices accessor does not exist before
// we see the model, with a message that names no mesh: find the primitive in
// the JSON ourselves.
std::string locate_bad_indices(const nlohmann::json &doc) {
  using nlohmann::json;
  if (!doc.is_object() || !doc.contains("meshes") || !doc["meshes"].is_array()) return "";
  size_t accessors = doc.contains("accessors") && doc["accessors"].is_array() ? doc["accessors"].size() : 0;
  const json &meshes = doc["meshes"];
  for (size_t mi = 0; mi < meshes.size(); mi++) {
    if (!meshes[mi].is_object() || !meshes[mi].contains("primitives")) continue;
    const json &prims = meshes[mi]["primitives"];
    for (size_t pi = 0; prims.is_array() && pi < prims.size(); pi++) {
      if (!prims[pi].is_object() || !prims[pi].contains("indices")) continue;
      const json &ix = prims[pi]["indices"];
      if (ix.is_number_integer() && ix.get<long long>() >= (long long)accessors)
        return "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi) +
               ": indices: accessor " + std::to_string(ix.get<long long>()) +
               " does not exist (the file has " + std::to_string(accessors) + ")";
    }
  }
  return "";
}

// The extensions this loader reads: a file that requires any other is refused
// before tinygltf sees it (which would fail later, on data it cannot decode).
const char *const kSupportedExtensions[] = {"KHR_lights_punctual", "KHR_texture_transform",
                                            "KHR_materials_emissive_strength", "EXT_mesh_gpu_instancing",
                                            "KHR_draco_mesh_compression", "EXT_meshopt_compression",
                                            "KHR_mesh_quantization", "KHR_materials_transmission",
                                            "KHR_materials_ior", "KHR_materials_volume"};

// The first name in the file's extensionsRequired that is not supported, or "".
std::string unsupported_required(const nlohmann::json &doc) {
  using nlohmann::json;
  if (!doc.contains("extensionsRequired") || !doc["extensionsRequired"].is_array()) return "";
  for (const json &e : doc["extensionsRequired"]) {
    std::string name = e.is_string() ? e.get<std::string>() : e.dump();
    bool known = false;
    for (const char *k : kSupportedExtensions) known |= name == k;
    if (!known) return name;
  }
  return "";
}

// Buffer i of the file (its JSON `b`) into src.buffers: the GLB's BIN chunk
// (`bin`, NULL without one) for a first buffer without a uri, a data URI
// decoded, or a file beside the glTF mapped.
bool load_buffer(const char *path, Source &src, size_t i, const nlohmann::json &b, const unsigned char *bin,
                 size_t bin_len, lm_error *err) {
  Buffer out;
  if (!b.is_object() || !b.contains("byteLength") || !b["byteLength"].is_number_unsigned())
    return lm_error_set(err, "%s: buffer %zu: byteLength is missing or not an unsigned integer", path, i), false;
  out.size = b["byteLength"].get<size_t>();
  bool has_uri = b.contains("uri") && b["uri"].is_string();
  const nlohmann::json *ext = b.contains("extensions") && b["extensions"].is_object() &&
                                      b["extensions"].contains("EXT_meshopt_compression")
                                  ? &b["extensions"]["EXT_meshopt_compression"]
                                  : nullptr;
  out.fallback = !has_uri && ext && ext->is_object() && ext->value("fallback", false) == true;
  if (out.fallback) {
  } else if (!has_uri) {
    if (i != 0 || !bin)
      return lm_error_set(err, "%s: buffer %zu has no uri (only a GLB's first buffer may go without)", path, i), false;
    if (out.size > bin_len)
      return lm_error_set(err, "%s: buffer 0: byteLength %zu is more than the GLB's BIN chunk (%zu bytes)", path,
                          out.size, bin_len), false;
    out.data = bin;
  } else {
    std::string uri = b["uri"].get<std::string>();
    if (tinygltf::IsDataURI(uri)) {
      auto bytes = std::make_unique<std::vector<unsigned char>>();
      std::string mime;
      if (!tinygltf::DecodeDataURI(bytes.get(), mime, uri, out.size, true))
        return lm_error_set(err, "%s: buffer %zu: its data URI does not decode to byteLength %zu bytes", path, i,
                            out.size), false;
      out.data = bytes->data();
      src.owned.push_back(std::move(bytes));
    } else {
      std::string full = src.dir + "/" + tinygltf::dlib::urldecode(uri);
      auto bin_file = std::make_unique<Mapping>();
      lm_error why;
      if (!map_file(full.c_str(), *bin_file, &why))
        return lm_error_set(err, "%s: buffer %zu: %s", path, i, why.msg), false;
      if (bin_file->len < out.size)
        return lm_error_set(err, "%s: buffer %zu: %s has %zu bytes, byteLength says %zu", path, i, full.c_str(),
                            bin_file->len, out.size), false;
      out.data = bin_file->bytes();
      src.bins.push_back(std::move(bin_file));
    }
  }
  src.buffers.push_back(out);
  return true;
}

// Image i of the file (its JSON `o`) into src.images.
bool load_image_ref(const char *path, Source &src, size_t i, const nlohmann::json &o, lm_error *err) {
  ImageRef img;
  bool has_uri = o.is_object() && o.contains("uri") && o["uri"].is_string();
  bool has_view = o.is_object() && o.contains("bufferView") && o["bufferView"].is_number_integer();
  if (has_uri == has_view)
    return lm_error_set(err, "%s: image %zu wants a uri or a bufferView (one of them)", path, i), false;
  if (has_uri) img.uri = o["uri"].get<std::string>();
  if (has_view) img.buffer_view = (int)std::clamp(o["bufferView"].get<long long>(), -1LL, (long long)INT32_MAX);
  if (o.contains("name") && o["name"].is_string()) img.name = o["name"].get<std::string>();
  src.images.push_back(img);
  return true;
}

// Reads `path`: its buffers and images into src (mapped where they lie),
// the rest of its JSON into *model through tinygltf.
bool parse(const char *path, Source &src, tinygltf::Model *model, lm_error *err) {
  using nlohmann::json;
  if (!map_file(path, src.file, err)) return false;
  char dir[4096];
  lm_dirname(path, dir, sizeof dir);
  src.dir = dir;
  const unsigned char *bytes = src.file.bytes();
  size_t len = src.file.len;
  // A GLB: header (magic, version, length), a JSON chunk, an optional BIN chunk.
  const unsigned char *text = bytes, *bin = nullptr;
  size_t text_len = len, bin_len = 0;
  if (len >= 4 && !memcmp(bytes, "glTF", 4)) {
    uint32_t head[5] = {0};
    if (len >= 20) memcpy(head, bytes, 20);
    if (len < 20 || head[1] != 2 || head[2] > len || head[2] < 20 || memcmp(&head[4], "JSON", 4) ||
        head[3] > head[2] - 20)
      return lm_error_set(err, "%s: not a glTF 2.0 binary (its header or JSON chunk does not fit its %zu bytes)",
                          path, len), false;
    text = bytes + 20, text_len = head[3];
    size_t at = 20 + (size_t)head[3];
    uint32_t chunk[2];
    if (at + 8 <= head[2]) {
      memcpy(chunk, bytes + at, 8);
      if (memcmp(&chunk[1], "BIN", 4) || chunk[0] > head[2] - at - 8)
        return lm_error_set(err, "%s: the GLB's second chunk is not a BIN chunk that fits the file", path), false;
      bin = bytes + at + 8, bin_len = chunk[0];
    }
  }
  json doc;
  try {
    doc = text ? json::parse(text, text + text_len) : json();
  } catch (const json::exception &e) {
    return lm_error_set(err, "%s: not JSON (%s)", path, e.what()), false;
  }
  if (!doc.is_object()) return lm_error_set(err, "%s: not a glTF file (its JSON is not an object)", path), false;
  std::string missing = unsupported_required(doc);
  if (!missing.empty()) {
    std::string known;
    for (const char *k : kSupportedExtensions) known += std::string(known.empty() ? "" : ", ") + k;
    lm_error_set(err, "%s: extensionsRequired names '%s', which this engine does not support (it reads %s)",
                 path, missing.c_str(), known.c_str());
    return false;
  }
  if (doc.contains("buffers")) {
    if (!doc["buffers"].is_array()) return lm_error_set(err, "%s: buffers is not an array", path), false;
    for (size_t i = 0; i < doc["buffers"].size(); i++)
      if (!load_buffer(path, src, i, doc["buffers"][i], bin, bin_len, err)) return false;
    doc.erase("buffers");
  }
  if (doc.contains("images")) {
    if (!doc["images"].is_array()) return lm_error_set(err, "%s: images is not an array", path), false;
    for (size_t i = 0; i < doc["images"].size(); i++)
      if (!load_image_ref(path, src, i, doc["images"][i], err)) return false;
    doc.erase("images");
  }
  if (doc.contains("meshes") && doc["meshes"].is_array())
    for (size_t mi = 0; mi < doc["meshes"].size(); mi++) {
      json &mesh = doc["meshes"][mi];
      if (!mesh.is_object() || !mesh.contains("primitives")) continue;
      json &prims = mesh["primitives"];
      for (size_t pi = 0; prims.is_array() && pi < prims.size(); pi++) {
        json &p = prims[pi];
        if (!p.is_object() || !p.contains("indices") || !p["indices"].is_number_integer() ||
            !p.contains("extensions") || !p["extensions"].is_object() ||
            !p["extensions"].contains("KHR_draco_mesh_compression"))
          continue;
        src.draco_indices[{mi, pi}] = (int)std::clamp(p["indices"].get<long long>(), -1LL, (long long)INT32_MAX);
        p.erase("indices");
      }
    }
  std::string rest = doc.dump();
  tinygltf::TinyGLTF gltf;
  std::string why, warn;
  bool ok = gltf.LoadASCIIFromString(model, &why, &warn, rest.data(), (unsigned)rest.size(), src.dir);
  if (!warn.empty()) lm_debug("%s: tinygltf: %s", path, first_line(warn).c_str());
  // Some of tinygltf's checks (a baseColorFactor of 2 numbers) report into
  // `why` and carry on with a default: a wrong file all the same.
  if (ok && why.empty()) return true;
  std::string what = first_line(why);
  if (what.find("primitive indices accessor out of bounds") != std::string::npos) {
    std::string where = locate_bad_indices(doc);
    if (!where.empty()) what = where;
  }
  lm_error_set(err, "%s: %s", path, what.c_str());
  return false;
}

// The memory budget in bytes (gltf.h): LIMN_MEMORY_BUDGET MiB, else 3/4 of
// physical memory; *from says which.
double memory_budget(const char **from) {
  const char *env = getenv("LIMN_MEMORY_BUDGET");
  char *end;
  double mib = env ? strtod(env, &end) : 0;
  if (env && end != env && !*end && mib > 0 && std::isfinite(mib)) return *from = "LIMN_MEMORY_BUDGET", mib * 1048576;
  *from = "the default, 3/4 of physical memory; LIMN_MEMORY_BUDGET=MiB sets another";
  return 0.75 * (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
}

// Do the uvs of primitive p lie in [0, 1], so that the GPU keeps them in
// 16 bits (lm_mesh_create)? A normalized unsigned accessor's do; a float
// one's bounds say so where given (glTF asks them only of POSITION). None:
// zeros.
bool uvs_in_unit_square(const Loader &L, const tinygltf::Primitive &p) {
  auto uv = p.attributes.find("TEXCOORD_0");
  if (uv == p.attributes.end()) return true;
  if (uv->second < 0 || (size_t)uv->second >= L.m.accessors.size()) return false;
  const tinygltf::Accessor &a = L.m.accessors[uv->second];
  if (a.normalized && (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                       a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT))
    return true;
  if (a.minValues.size() < 2 || a.maxValues.size() < 2) return false;
  for (int c = 0; c < 2; c++)
    if (!(a.minValues[c] >= 0 && a.maxValues[c] <= 1)) return false;
  return true;
}

// What the scene will hold, in bytes, against the budget. On the GPU what
// lm_mesh_create uploads: a vertex 16 bytes (positions and uvs in 16 bits,
// octahedral normals), floats where a primitive deforms (positions, 4 more)
// or its uvs leave [0, 1] (4 more), tangents 16 more; indices of 2 bytes
// below 65536 vertices, else 4, and for a mesh of LM_LOD_MIN_TRIANGLES or
// more that does not deform its simplified copies (lm_scene_upload_mesh:
// two chains, each level aiming at a quarter of the last's triangles, about
// 1/3 of the mesh's indices a chain); the decoded images with their mip
// levels (4/3). In memory the scene's own copies: tangents, 16 bytes a
// vertex, always (lm_scene_upload_mesh frees vertices and indices alone);
// the rest where it keeps them (all but lm_scene_load_gpu's, which frees
// each mesh that does not deform and each image as it uploads them): 32
// bytes a vertex (its undeformed copy 32 more where it deforms), 4 an
// index, 4 a texel. Checked before the images are decoded and again after
// (their size is known then), before a mesh is made.
bool within_budget(Loader &L) {
  double geometry = 0, images = 0;
  bool gpu_only = L.s->gpu_only;
  for (size_t mi = 0; mi < L.m.meshes.size(); mi++) {
    bool deforms = deformable(L.m.meshes[mi]);
    for (size_t pi = 0; pi < L.m.meshes[mi].primitives.size(); pi++) {
      const tinygltf::Primitive &p = L.m.meshes[mi].primitives[pi];
      int index_accessor = indices_of(L, (int)mi, (int)pi);
      auto pos = p.attributes.find("POSITION");
      auto count = [&](int a) { return a >= 0 && (size_t)a < L.m.accessors.size() ? (double)L.m.accessors[a].count : 0; };
      double vertices = pos == p.attributes.end() ? 0 : count(pos->second);
      double indices = index_accessor >= 0 ? count(index_accessor) : vertices;
      double tangents = p.attributes.count("TANGENT") ? 16 : 0;
      double gpu_vertex = 16 + (deforms ? 4 : 0) + (uvs_in_unit_square(L, p) ? 0 : 4) + tangents;
      double copies = !deforms && indices / 3 >= LM_LOD_MIN_TRIANGLES ? 2.0 / 3 : 0;
      geometry += vertices * (gpu_vertex + tangents /* the scene's */) +
                  indices * (1 + copies) * (vertices <= 65536 ? 2 : 4);
      if (!gpu_only || deforms) geometry += vertices * (32 + (deforms ? 32 : 0)) + indices * 4;
    }
  }
  for (const Pending &d : L.decoded)
    if (d.rgba) images += (gpu_only ? 4.0 / 3 : 1 + 4.0 / 3) * 4 * (double)d.width * (double)d.height;
  const char *from;
  double budget = memory_budget(&from);
  if (geometry + images <= budget) return true;
  return fail(L, "the scene needs about %.4g MiB (vertices and indices %.4g MiB, textures %.4g MiB, in memory and on "
              "the GPU), more than the memory budget of %.4g MiB (%s)", (geometry + images) / 1048576,
              geometry / 1048576, images / 1048576, budget / 1048576, from);
}

// Fills `s` from the parsed model; false (message in L.err) on bad input.
bool convert(const char *path, const Source &src, const tinygltf::Model &model, lm_scene *s, lm_error *err) {
  Loader L{path, model, s, err, {}, {}, {}, {}, 0, {}, {}, 0, 0, 0, {}, {}, {}, &src, {}, {}, {}, {}, {}, 0};
  L.views.resize(model.bufferViews.size());
  if (!within_budget(L)) return false; // the geometry, before an image is decoded
  decode_images(L);
  if (!within_budget(L)) return false;
  L.meshes.resize(model.meshes.size());
  L.materials.assign(model.materials.size(), -1);
  L.textures.assign(src.images.size() * 2, -1);
  L.nodes.assign(model.nodes.size(), -1);
  L.holders.resize(model.nodes.size());
  if (!load_nodes(L) || !load_skins(L) || !load_animations(L)) return false;
  if (L.skipped)
    lm_warn("%s: %d point or line primitive%s skipped (the first: %s): only triangles are drawn", path,
            L.skipped, L.skipped > 1 ? "s" : "", L.first_skipped.c_str());
  if (L.skipped_channels)
    lm_warn("%s: %d animation channel%s skipped (the first: %s): only translation, rotation, scale and weights of "
            "the scene's nodes move", path, L.skipped_channels, L.skipped_channels > 1 ? "s" : "",
            L.first_channel.c_str());
  if (L.ignored_targets)
    lm_warn("%s: %d morph target attribute%s ignored (the first: %s): only POSITION and NORMAL morph", path,
            L.ignored_targets, L.ignored_targets > 1 ? "s" : "", L.first_target.c_str());
  if (L.mended_weights)
    lm_warn("%s: the skin weights of %d vert%s did not sum to 1 and were normalized (the first: %s)", path,
            L.mended_weights, L.mended_weights > 1 ? "ices" : "ex", L.first_weights.c_str());
  if (L.shared)
    lm_debug("%s: %d meshes identical to another, shared (each keeps the first one's name)", path, L.shared);
  lm_scene_update(s);
  if (!check_world(L)) return false;
  lm_scene_pose(s, LM_ANIM_NONE, 0); // morph weights and skins at rest
  add_defaults(s);
  return true;
}

} // namespace

// lm_scene_load_gltf; gpu_only: lm_scene_load_gpu's.
static lm_scene *load_gltf(const char *path, bool gpu_only, lm_error *err) {
  lm_scene *s = nullptr;
  try {
    tinygltf::Model model;
    Source src;
    if (!parse(path, src, &model, err)) return nullptr;
    const char *base = strrchr(path, '/');
    s = lm_scene_create(base ? base + 1 : path);
    s->gpu_only = gpu_only;
    if (convert(path, src, model, s, err)) return s;
  } catch (const std::exception &e) { // tinygltf throws on some malformed input
    lm_error_set(err, "%s: malformed glTF (%s)", path, e.what());
  } catch (...) {
    lm_error_set(err, "%s: malformed glTF", path);
  }
  lm_scene_destroy(s);
  return nullptr;
}

extern "C" lm_scene *lm_scene_load_gltf(const char *path, lm_error *err) { return load_gltf(path, false, err); }

extern "C" lm_material lm_gltf_phong(const float color[3], float metallic, float roughness) {
  lm_material m = {};
  float maxc = 0;
  for (int c = 0; c < 3; c++) m.color[c] = color[c], maxc = std::fmax(maxc, color[c]);
  m.kd = 1.0f - metallic;
  // Light from everywhere (the ambient term, the sky) is reflected as light from one direction is: by the
  // diffuse part (the Phong lobe's share of it, 2 ks / (n + 2), is left out as for dielectrics).
  m.ka = m.kd;
  m.ks = 0.04f + (maxc - 0.04f) * metallic;
  double r4 = (double)roughness * roughness * roughness * roughness;
  double shin = r4 > 0 ? 2.0 / r4 - 2.0 : 1024.0;
  m.shininess = (float)(shin < 1 ? 1 : shin > 1024 ? 1024 : shin);
  m.rho = maxc * m.kd;
  return m;
}

extern "C" lm_scene *lm_scene_load_gpu(const char *name, lm_error *err) {
  if (lm_scene_is_gltf_name(name)) return load_gltf(name, true, err);
  lm_scene *s = lm_scene_builtin(name, err);
  if (s) s->gpu_only = true;
  return s;
}

extern "C" bool lm_scene_is_gltf_name(const char *name) {
  const char *dot = strrchr(name, '.');
  return dot && !strchr(dot, '/') && (!strcasecmp(dot, ".gltf") || !strcasecmp(dot, ".glb"));
}

extern "C" lm_scene *lm_scene_load(const char *name, lm_error *err) {
  return lm_scene_is_gltf_name(name) ? lm_scene_load_gltf(name, err) : lm_scene_builtin(name, err);
}
