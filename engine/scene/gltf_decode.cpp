// Compressed glTF geometry through Draco and meshoptimizer (gltf_decode.h).
#include "scene/gltf_decode.h"

#include <draco/compression/decode.h>
#include <meshoptimizer.h>

namespace {

// The accessor's component type as T, every point of `a` into out.
template <typename T> bool convert_all(const draco::PointCloud &pc, const draco::PointAttribute &a, int n,
                                       std::vector<unsigned char> &out) {
  out.resize(pc.num_points() * (size_t)n * sizeof(T));
  T value[4];
  for (draco::PointIndex i(0); i < pc.num_points(); ++i) {
    if (!a.ConvertValue<T>(a.mapped_index(i), (int8_t)n, value)) return false;
    memcpy(out.data() + (size_t)i.value() * n * sizeof(T), value, n * sizeof(T));
  }
  return true;
}

bool convert_attribute(const draco::PointCloud &pc, const draco::PointAttribute &a, int type, int n,
                       std::vector<unsigned char> &out) {
  switch (type) {
  case 5120: return convert_all<int8_t>(pc, a, n, out);
  case 5121: return convert_all<uint8_t>(pc, a, n, out);
  case 5122: return convert_all<int16_t>(pc, a, n, out);
  case 5123: return convert_all<uint16_t>(pc, a, n, out);
  case 5125: return convert_all<uint32_t>(pc, a, n, out);
  case 5126: return convert_all<float>(pc, a, n, out);
  default: return false;
  }
}

} // namespace

std::string lm_draco_decode(const unsigned char *data, size_t size, std::vector<uint32_t> &indices, size_t *points,
                            std::vector<lm_draco_attribute> &attributes) {
  draco::DecoderBuffer buffer;
  buffer.Init((const char *)data, size);
  auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok()) return "not Draco data (" + type.status().error_msg_string() + ")";
  if (type.value() != draco::TRIANGULAR_MESH) return "Draco data of a point cloud, not a triangle mesh";
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) return "Draco cannot decode it (" + decoded.status().error_msg_string() + ")";
  const draco::Mesh &mesh = *decoded.value();
  *points = mesh.num_points();
  indices.resize((size_t)mesh.num_faces() * 3);
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; k++) indices[(size_t)f.value() * 3 + k] = mesh.face(f)[k].value();
  for (lm_draco_attribute &want : attributes) {
    const draco::PointAttribute *a = want.unique_id >= 0 ? mesh.GetAttributeByUniqueId(want.unique_id) : nullptr;
    if (!a) return std::string(want.name) + ": Draco attribute " + std::to_string(want.unique_id) + " does not exist";
    if (want.components < 1 || want.components > 4)
      return std::string(want.name) + ": an accessor of " + std::to_string(want.components) +
             " components (Draco attributes have 1 to 4)";
    if (a->num_components() != want.components)
      return std::string(want.name) + ": Draco attribute " + std::to_string(want.unique_id) + " has " +
             std::to_string(a->num_components()) + " components, the accessor " + std::to_string(want.components);
    if (!convert_attribute(mesh, *a, want.component_type, want.components, want.bytes))
      return std::string(want.name) + ": Draco attribute " + std::to_string(want.unique_id) +
             " does not convert to component type " + std::to_string(want.component_type);
  }
  return "";
}

std::string lm_meshopt_decode(const unsigned char *data, size_t size, size_t count, size_t stride,
                              const std::string &mode, const std::string &filter, std::vector<unsigned char> &out) {
  // meshoptimizer asserts on sizes it does not take: check them here first.
  bool attributes = mode == "ATTRIBUTES", triangles = mode == "TRIANGLES", indices = mode == "INDICES";
  if (!attributes && !triangles && !indices) return "mode '" + mode + "' is not ATTRIBUTES, TRIANGLES or INDICES";
  if (attributes ? stride == 0 || stride > 256 || stride % 4 : stride != 2 && stride != 4)
    return "byteStride " + std::to_string(stride) + " does not fit mode " + mode;
  if (triangles && count % 3) return "mode TRIANGLES with count " + std::to_string(count) + ", not a multiple of 3";
  if (count > ((size_t)1 << 31) / stride) return "count " + std::to_string(count) + " is too large";
  bool oct = filter == "OCTAHEDRAL", quat = filter == "QUATERNION", exp = filter == "EXPONENTIAL";
  if (filter != "NONE" && !oct && !quat && !exp)
    return "filter '" + filter + "' is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL";
  if ((oct || quat || exp) && !attributes) return "filter " + filter + " on mode " + mode;
  if ((oct && stride != 4 && stride != 8) || (quat && stride != 8))
    return "filter " + filter + " with byteStride " + std::to_string(stride);
  out.assign(count * stride, 0);
  int rc = attributes ? meshopt_decodeVertexBuffer(out.data(), count, stride, data, size)
           : triangles ? meshopt_decodeIndexBuffer(out.data(), count, stride, data, size)
                       : meshopt_decodeIndexSequence(out.data(), count, stride, data, size);
  if (rc != 0) return "meshoptimizer cannot decode it (error " + std::to_string(rc) + ")";
  if (oct) meshopt_decodeFilterOct(out.data(), count, stride);
  if (quat) meshopt_decodeFilterQuat(out.data(), count, stride);
  if (exp) meshopt_decodeFilterExp(out.data(), count, stride);
  return "";
}
