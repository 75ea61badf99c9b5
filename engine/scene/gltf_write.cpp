// The glTF writer (scene/gltf.h: lm_scene_write_gltf): the scene as Limn
// holds it, through tinygltf's serializer (its implementation is compiled in
// gltf_tinygltf.cpp). Every choice here is the inverse of what the loader
// does, so that reading the file back gives the scene written; where glTF
// cannot say what Limn has, Limn's values go into `extras` with a warning.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#include <tiny_gltf.h>

#include "image/image.h"
#include "scene/gltf.h"

#include <strings.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Writer {
  const lm_scene *s;
  tinygltf::Model m;
  std::vector<unsigned char> &bin; // buffer 0
  lm_buf *warnings;
  std::vector<int> mesh_accessors; // [lm mesh] -> first of its accessors (position, normal, uv, indices[, tangent])
};

// A line of the writer's warnings (the loader's fail() is alike, into its error).
__attribute__((format(printf, 2, 3))) void warn(Writer &W, const char *fmt, ...) {
  char line[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(line, sizeof line, fmt, ap);
  va_end(ap);
  lm_buf_printf(W.warnings, "%s\n", line);
}

// Appends `bytes` to the binary buffer (4-byte aligned) as a buffer view, and an accessor over it.
int add_accessor(Writer &W, const void *bytes, size_t size, int component, int type, size_t count, int target,
                 const float *lo = nullptr, const float *hi = nullptr) {
  while (W.bin.size() % 4) W.bin.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = W.bin.size();
  view.byteLength = size;
  view.target = target;
  W.bin.insert(W.bin.end(), (const unsigned char *)bytes, (const unsigned char *)bytes + size);
  W.m.bufferViews.push_back(view);
  tinygltf::Accessor a;
  a.bufferView = (int)W.m.bufferViews.size() - 1;
  a.componentType = component;
  a.type = type;
  a.count = count;
  if (lo && hi) a.minValues.assign(lo, lo + 3), a.maxValues.assign(hi, hi + 3);
  W.m.accessors.push_back(a);
  return (int)W.m.accessors.size() - 1;
}

// A mesh's vertices as they are now (a deformed mesh: its pose), split into glTF's attributes.
void add_mesh_data(Writer &W, int mi) {
  const lm_scene_mesh &sm = W.s->meshes[mi];
  size_t n = (size_t)sm.vertex_count;
  std::vector<float> pos(n * 3), nrm(n * 3), uv(n * 2);
  float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (size_t v = 0; v < n; v++) {
    const float *x = sm.vertices + v * 8;
    for (int k = 0; k < 3; k++) {
      pos[v * 3 + k] = x[k], nrm[v * 3 + k] = x[3 + k];
      lo[k] = v ? std::fmin(lo[k], x[k]) : x[k];
      hi[k] = v ? std::fmax(hi[k], x[k]) : x[k];
    }
    uv[v * 2] = x[6], uv[v * 2 + 1] = x[7];
  }
  W.mesh_accessors[mi] = add_accessor(W, pos.data(), pos.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                                      n, TINYGLTF_TARGET_ARRAY_BUFFER, lo, hi);
  add_accessor(W, nrm.data(), nrm.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n,
               TINYGLTF_TARGET_ARRAY_BUFFER);
  add_accessor(W, uv.data(), uv.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, n,
               TINYGLTF_TARGET_ARRAY_BUFFER);
  add_accessor(W, sm.indices, (size_t)sm.index_count * 4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
               (size_t)sm.index_count, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  if (sm.tangents)
    add_accessor(W, sm.tangents, n * 16, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, n,
                 TINYGLTF_TARGET_ARRAY_BUFFER);
}

tinygltf::Value number_array(const float *v, int n) {
  tinygltf::Value::Array a;
  for (int i = 0; i < n; i++) a.push_back(tinygltf::Value((double)v[i]));
  return tinygltf::Value(a);
}

// Texture t as a PNG beside the file, named by its content so that a scene
// written twice (or two scenes) share it; its glTF texture index.
int add_texture(Writer &W, int t, const std::string &dir, std::vector<int> &done, lm_error *err) {
  if (done[t] >= 0) return done[t];
  const lm_scene_texture &st = W.s->textures[t];
  uint64_t h = lm_hash(st.rgba, (size_t)st.width * (size_t)st.height * 4, LM_HASH_SEED);
  char name[64];
  snprintf(name, sizeof name, "texture-%016llx.png", (unsigned long long)h);
  std::string path = dir + name;
  if (access(path.c_str(), F_OK) != 0 && !lm_image_write(path.c_str(), st.width, st.height, 4, false, st.rgba, err))
    return -1;
  tinygltf::Image image;
  image.name = st.name;
  image.uri = name;
  W.m.images.push_back(image);
  tinygltf::Texture tex;
  tex.source = (int)W.m.images.size() - 1;
  W.m.textures.push_back(tex);
  return done[t] = (int)W.m.textures.size() - 1;
}

bool near(float a, float b) { return std::fabs(a - b) <= 1e-3f * std::fmax(1.0f, std::fabs(b)); }

// Extension `name` on the material, and in the file's extensionsUsed (once).
void use_extension(Writer &W, tinygltf::Material &g, const char *name, tinygltf::Value::Object o) {
  g.extensions[name] = tinygltf::Value(o);
  auto &used = W.m.extensionsUsed;
  if (std::find(used.begin(), used.end(), name) == used.end()) used.push_back(name);
}

// Glass as the loader reads it: KHR_materials_transmission, _ior, and _volume
// (which glTF allows only beside transmission).
void add_glass(Writer &W, const lm_material_pbr &p, tinygltf::Material &g) {
  if (p.transmission > 0)
    use_extension(W, g, "KHR_materials_transmission",
                  {{"transmissionFactor", tinygltf::Value((double)p.transmission)}});
  if (p.ior > 0 && p.ior != 1.5f) use_extension(W, g, "KHR_materials_ior", {{"ior", tinygltf::Value((double)p.ior)}});
  if (p.transmission > 0 && p.thickness > 0 && p.attenuation_distance > 0)
    use_extension(W, g, "KHR_materials_volume",
                  {{"thicknessFactor", tinygltf::Value((double)p.thickness)},
                   {"attenuationDistance", tinygltf::Value((double)p.attenuation_distance)},
                   {"attenuationColor", number_array(p.attenuation_color, 3)}});
}

bool add_material(Writer &W, int i, const std::string &dir, std::vector<int> &textures, lm_error *err) {
  const lm_material &lm = W.s->materials[i];
  lm_material_pbr p = lm_scene_material_pbr(W.s, i, &lm);
  tinygltf::Material g;
  g.name = lm.name;
  auto &pbr = g.pbrMetallicRoughness;
  pbr.baseColorFactor = {lm.color[0], lm.color[1], lm.color[2], p.alpha};
  pbr.metallicFactor = p.metallic;
  pbr.roughnessFactor = p.roughness;
  g.emissiveFactor = {p.emissive[0], p.emissive[1], p.emissive[2]};
  g.alphaMode = p.alpha_mode == LM_ALPHA_MASK ? "MASK" : p.alpha_mode == LM_ALPHA_BLEND ? "BLEND" : "OPAQUE";
  g.alphaCutoff = p.alpha_cutoff;
  int t[LM_TEX_SLOTS];
  for (int slot = 0; slot < LM_TEX_SLOTS; slot++) {
    int ti = (slot == LM_TEX_BASE_COLOR ? lm.base_color_texture : p.textures[slot]) - 1;
    t[slot] = ti >= 0 && ti < W.s->texture_count ? add_texture(W, ti, dir, textures, err) : -2;
    if (t[slot] == -1) return false;
    const float *x = p.uv_transform[slot];
    if (t[slot] >= 0 && (x[0] || x[1] || x[2] || x[3] || x[4] || x[5]))
      warn(W, "material '%s': a texture's KHR_texture_transform is not written (the texture is, untransformed)",
           lm.name);
  }
  pbr.baseColorTexture.index = t[LM_TEX_BASE_COLOR] >= 0 ? t[LM_TEX_BASE_COLOR] : -1;
  pbr.metallicRoughnessTexture.index = t[LM_TEX_METALLIC_ROUGHNESS] >= 0 ? t[LM_TEX_METALLIC_ROUGHNESS] : -1;
  g.normalTexture.index = t[LM_TEX_NORMAL] >= 0 ? t[LM_TEX_NORMAL] : -1;
  g.normalTexture.scale = p.normal_scale;
  g.occlusionTexture.index = t[LM_TEX_OCCLUSION] >= 0 ? t[LM_TEX_OCCLUSION] : -1;
  g.occlusionTexture.strength = p.occlusion_strength;
  g.emissiveTexture.index = t[LM_TEX_EMISSIVE] >= 0 ? t[LM_TEX_EMISSIVE] : -1;
  add_glass(W, p, g);
  // Limn's Phong values always go into extras.limn; the loader reads extras.reflectivity.
  tinygltf::Value::Object limn, extras;
  limn["color"] = number_array(lm.color, 3);
  limn["ka"] = tinygltf::Value((double)lm.ka);
  limn["kd"] = tinygltf::Value((double)lm.kd);
  limn["ks"] = tinygltf::Value((double)lm.ks);
  limn["shininess"] = tinygltf::Value((double)lm.shininess);
  limn["rho"] = tinygltf::Value((double)lm.rho);
  extras["limn"] = tinygltf::Value(limn);
  if (lm.reflectivity > 0) extras["reflectivity"] = tinygltf::Value((double)lm.reflectivity);
  g.extras = tinygltf::Value(extras);
  lm_material back = lm_gltf_phong(lm.color, p.metallic, p.roughness);
  if (!near(back.ka, lm.ka) || !near(back.kd, lm.kd) || !near(back.ks, lm.ks) || !near(back.rho, lm.rho) ||
      !near(back.shininess, lm.shininess))
    warn(W, "material '%s': Phong ka %g kd %g ks %g shininess %g rho %g is no glTF metallic-roughness material "
            "(it reads back as ka %g kd %g ks %g shininess %g rho %g); Limn's values are in its extras.limn",
         lm.name, lm.ka, lm.kd, lm.ks, lm.shininess, lm.rho, back.ka, back.kd, back.ks, back.shininess, back.rho);
  W.m.materials.push_back(g);
  return true;
}

// Light l as KHR_lights_punctual, in glTF's units (candela, lux: the loader's LM_GLTF_EXPOSURE undone).
tinygltf::Light light_of(Writer &W, const lm_light &l) {
  tinygltf::Light g;
  g.name = l.name;
  g.type = l.type == LM_LIGHT_POINT ? "point" : l.type == LM_LIGHT_SPOT ? "spot" : "directional";
  g.color = {l.color[0], l.color[1], l.color[2]};
  g.intensity = l.power / LM_GLTF_EXPOSURE;
  if (l.type == LM_LIGHT_SPOT) g.spot.innerConeAngle = l.inner_cone, g.spot.outerConeAngle = l.outer_cone;
  tinygltf::Value::Object extras;
  if (l.size > 0) extras["size"] = tinygltf::Value((double)l.size);
  if (l.type != LM_LIGHT_DIRECTIONAL) {
    if (l.falloff == LM_FALLOFF_RANGE) {
      g.range = l.radius;
    } else if (l.falloff != LM_FALLOFF_INVERSE_SQUARE) { /* glTF's falloff is 1 / d^2 within its range */
      static const char *const names[] = {"window", "none"};
      warn(W, "light '%s': its %s falloff (radius %g) is not glTF's 1 / d^2; written as 1 / d^2, Limn's in "
              "extras.limn_falloff", l.name, names[l.falloff == LM_FALLOFF_NONE], l.radius);
      tinygltf::Value::Object f;
      f["falloff"] = tinygltf::Value(std::string(names[l.falloff == LM_FALLOFF_NONE]));
      f["radius"] = tinygltf::Value((double)l.radius);
      extras["limn_falloff"] = tinygltf::Value(f);
    }
  }
  if (!l.casts_shadows) {
    warn(W, "light '%s': casts no shadow in Limn; glTF lights always do (extras.casts_shadows false)", l.name);
    extras["casts_shadows"] = tinygltf::Value(false);
  }
  if (!extras.empty()) g.extras = tinygltf::Value(extras);
  return g;
}

// An extension object { key: index } on node n (KHR_lights_punctual's light).
void set_light(tinygltf::Node &n, int index) {
  tinygltf::Value::Object o;
  o["light"] = tinygltf::Value(index);
  n.extensions["KHR_lights_punctual"] = tinygltf::Value(o);
}

bool build(Writer &W, const std::string &dir, lm_error *err) {
  const lm_scene *s = W.s;
  W.m.asset.version = "2.0";
  W.m.asset.generator = "Limn (limn export-gltf)";
  W.m.buffers.resize(1);
  W.mesh_accessors.assign((size_t)s->mesh_count, -1);
  std::vector<int> textures((size_t)s->texture_count, -1);
  for (int i = 0; i < s->material_count; i++)
    if (!add_material(W, i, dir, textures, err)) return false;
  W.m.scenes.resize(1);
  W.m.defaultScene = 0;
  // Nodes keep their indices.
  for (int i = 0; i < s->node_count; i++) {
    const lm_node &ln = s->nodes[i];
    tinygltf::Node n;
    n.name = ln.name;
    n.matrix.assign(ln.local, ln.local + 16);
    if (ln.mesh >= 0 && ln.mesh < s->mesh_count) {
      if (W.mesh_accessors[ln.mesh] < 0) add_mesh_data(W, ln.mesh);
      int a = W.mesh_accessors[ln.mesh];
      tinygltf::Primitive p;
      p.attributes["POSITION"] = a;
      p.attributes["NORMAL"] = a + 1;
      p.attributes["TEXCOORD_0"] = a + 2;
      p.indices = a + 3;
      if (s->meshes[ln.mesh].tangents) p.attributes["TANGENT"] = a + 4;
      p.mode = TINYGLTF_MODE_TRIANGLES;
      p.material = ln.material >= 0 && ln.material < s->material_count ? ln.material : -1;
      tinygltf::Mesh mesh;
      mesh.name = s->meshes[ln.mesh].name;
      mesh.primitives.push_back(p);
      W.m.meshes.push_back(mesh);
      n.mesh = (int)W.m.meshes.size() - 1;
    }
    W.m.nodes.push_back(n);
  }
  for (int i = 0; i < s->node_count; i++) {
    int parent = s->nodes[i].parent;
    if (parent >= 0 && parent < s->node_count) W.m.nodes[parent].children.push_back(i);
    else W.m.scenes[0].nodes.push_back(i);
  }
  // The node that carries a light or camera: its own, or a new child when
  // that has one already (a new root for one without a node).
  auto holder = [&](int node, bool light, const char *name) {
    bool valid = node >= 0 && node < s->node_count;
    if (valid && !(light ? W.m.nodes[node].extensions.count("KHR_lights_punctual") : W.m.nodes[node].camera >= 0))
      return node;
    tinygltf::Node child;
    child.name = name;
    W.m.nodes.push_back(child);
    int added = (int)W.m.nodes.size() - 1;
    if (valid) W.m.nodes[node].children.push_back(added);
    else W.m.scenes[0].nodes.push_back(added);
    return added;
  };
  for (int i = 0; i < s->light_count; i++) {
    const lm_light &l = s->lights[i];
    W.m.lights.push_back(light_of(W, l));
    set_light(W.m.nodes[holder(l.node, true, l.name)], i);
  }
  if (s->light_count) W.m.extensionsUsed.push_back("KHR_lights_punctual");
  for (int i = 0; i < s->camera_count; i++) {
    const lm_camera &c = s->cameras[i];
    tinygltf::Camera g;
    g.name = c.name;
    if (c.ortho[0] > 0 || c.ortho[1] > 0) {
      g.type = "orthographic";
      g.orthographic.xmag = c.ortho[0], g.orthographic.ymag = c.ortho[1];
      g.orthographic.znear = c.znear, g.orthographic.zfar = c.zfar;
    } else {
      g.type = "perspective";
      g.perspective.yfov = c.fov_y;
      g.perspective.znear = c.znear;
      g.perspective.zfar = c.zfar;
      g.perspective.aspectRatio = c.aspect;
    }
    W.m.cameras.push_back(g);
    W.m.nodes[holder(c.node, false, c.name)].camera = i;
  }
  W.m.buffers[0].data = W.bin;
  if (W.bin.empty()) W.m.buffers.clear();
  if (s->animation_count || s->skin_count)
    warn(W, "%d animation%s and %d skin%s not written: the scene as posed (at %g s)", s->animation_count,
         s->animation_count == 1 ? "" : "s", s->skin_count, s->skin_count == 1 ? "" : "s", s->time);
  return true;
}

} // namespace

extern "C" bool lm_scene_write_gltf(const lm_scene *s, const char *path, lm_buf *warnings, lm_error *err) {
  std::string p = path, dir;
  size_t slash = p.rfind('/');
  if (slash != std::string::npos) dir = p.substr(0, slash + 1);
  bool binary = p.size() >= 4 && strcasecmp(p.c_str() + p.size() - 4, ".glb") == 0;
  std::vector<unsigned char> bin;
  Writer W{s, {}, bin, warnings, {}};
  if (!build(W, dir, err)) {
    lm_error_prefix(err, "%s", path);
    return false;
  }
  std::ostringstream out;
  tinygltf::TinyGLTF gltf;
  if (!gltf.WriteGltfSceneToStream(&W.m, out, !binary, binary)) {
    lm_error_set(err, "%s: the glTF writer failed", path);
    return false;
  }
  // Whole or not at all: a temporary name beside it, renamed.
  std::string text = out.str(), tmp = p + ".tmp-" + std::to_string((long)getpid());
  FILE *f = fopen(tmp.c_str(), "wb");
  bool ok = f && fwrite(text.data(), 1, text.size(), f) == text.size();
  ok = f && fclose(f) == 0 && ok;
  if (!ok || rename(tmp.c_str(), path) != 0) {
    lm_error_set(err, "%s: cannot write (%s)", path, strerror(errno));
    remove(tmp.c_str());
    return false;
  }
  return true;
}
