// Compressed glTF geometry, decoded by the libraries made for it: Draco for
// KHR_draco_mesh_compression, meshoptimizer for EXT_meshopt_compression.
// C++ only: the glTF loader (gltf_tinygltf.cpp) is its one caller. Each
// function trusts no size it is given and returns "" or what went wrong.
#ifndef LIMN_GLTF_DECODE_H
#define LIMN_GLTF_DECODE_H

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

// One attribute wanted from a Draco mesh: its unique id in the compressed
// data, the glTF component type (5120..5126) and components per element of
// the accessor it fills; `bytes` receives num_points tightly packed elements.
struct lm_draco_attribute {
  const char *name; // POSITION, NORMAL, ... (for messages)
  int unique_id, component_type, components;
  std::vector<unsigned char> bytes;
};

// Decodes a Draco mesh: its triangles' corner indices into `indices` and
// every one of `attributes`; *points is the vertex count.
std::string lm_draco_decode(const unsigned char *data, size_t size, std::vector<uint32_t> &indices, size_t *points,
                            std::vector<lm_draco_attribute> &attributes);

// Decodes an EXT_meshopt_compression bufferView: `count` elements of
// `stride` bytes in `mode` (ATTRIBUTES, TRIANGLES, INDICES) with `filter`
// (NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL) into `out`.
std::string lm_meshopt_decode(const unsigned char *data, size_t size, size_t count, size_t stride,
                              const std::string &mode, const std::string &filter, std::vector<unsigned char> &out);

#endif
