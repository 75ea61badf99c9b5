/* gltf: glTF 2.0 scenes (.gltf with external or data-URI buffers, and .glb)
 * read into an lm_scene. The reading itself is tinygltf's, behind the C++
 * bridge gltf_tinygltf.cpp; every index, offset, length and count it hands
 * over is checked again here before a byte is read.
 *
 * What comes over, and how:
 * - extensionsRequired first: a file that requires an extension other than
 *   those the loader reads (KHR_lights_punctual, KHR_texture_transform,
 *   KHR_materials_emissive_strength, EXT_mesh_gpu_instancing,
 *   KHR_draco_mesh_compression, EXT_meshopt_compression,
 *   KHR_mesh_quantization, KHR_materials_transmission, KHR_materials_ior,
 *   KHR_materials_volume) is refused, naming it.
 * - Buffers are read where they lie, not copied: the file is mapped, a
 *   GLB's BIN chunk and each .bin beside a .gltf are read in place (data
 *   URIs are decoded); tinygltf parses the JSON only. The images materials
 *   use are decoded on all cores before the materials are read; mip levels
 *   are built once, at upload.
 * - Compressed meshes: KHR_draco_mesh_compression primitives through Draco
 *   (the attributes it names, and the indices; the others as stored),
 *   EXT_meshopt_compression bufferViews through meshoptimizer's decoders
 *   and filters (each view once; a fallback buffer holds no data), and
 *   KHR_mesh_quantization's integer attributes (normalized or not; the
 *   node transform dequantizes). Data that does not decode fails the file
 *   naming the mesh, primitive, accessor and bufferView.
 * - A memory budget: the loader adds up what the scene will hold (vertices
 *   and indices, decoded images with their mip levels, as the GPU holds
 *   them and in memory where the scene keeps them) before building it and
 *   refuses a file over the budget,
 *   naming it: LIMN_MEMORY_BUDGET (MiB) in the environment, else 3/4 of the
 *   machine's physical memory.
 * - Nodes of the file's default scene (scene 0 when it names none; every
 *   root node when it has no scenes), parents before children. A node's
 *   local transform is its matrix, or T * R * S. Every world transform must
 *   stay within LM_GLTF_MAX_COORD, and a camera's must be invertible (no
 *   zero scale), or the file is refused (a pose an animation gives it,
 *   lm_scene_camera_check refuses when a frame renders it).
 * - Each mesh primitive becomes its own lm mesh: a node whose mesh has one
 *   primitive holds it itself; a node whose mesh has several gets one child
 *   node per primitive ("<node>.<i>", identity transform), so that each node
 *   keeps one material. Nodes sharing a mesh share its lm meshes.
 *   A primitive that does not deform whose decoded geometry (vertices,
 *   tangents, indices) is byte-identical to one already read shares that
 *   one's lm mesh and name, as if the nodes named one mesh (exporters write
 *   each duplicated object as a mesh of its own).
 * - EXT_mesh_gpu_instancing: a node's TRANSLATION, ROTATION, SCALE accessors
 *   (the same count; floats, or normalized integers) place one child node
 *   "<node>[i]" a copy, holding the mesh as above, under the node's own
 *   transform; the renderer draws the copies of a mesh in one instanced
 *   draw as it does any nodes sharing a mesh. A node without a mesh, an
 *   attribute of the wrong width or count, a non-finite value or a zero
 *   rotation fails the file naming the node and the attribute.
 * - Triangles, triangle strips and fans (modes 4, 5, 6, indexed by
 *   u8/u16/u32 or not indexed); strips and fans become triangle lists with
 *   their winding kept. Points and lines (modes 0 to 3) are skipped, with one
 *   warning per file. Normals absent from
 *   the file are computed, area-weighted; a vertex that only touches
 *   zero-area triangles gets +Z. UVs (TEXCOORD_0) are optional (0 when
 *   absent). Coordinates must be finite and within LM_GLTF_MAX_COORD.
 *   Sparse accessors are not supported.
 * - Morph targets: POSITION and NORMAL deltas (TANGENT and other attributes
 *   are ignored with one warning a file; tangents are not deformed). Every
 *   primitive of a mesh must have as many targets; the mesh's `weights` are
 *   the defaults, a node's `weights` override them (each of the target
 *   count). Skins: JOINTS_n / WEIGHTS_n sets (joints unsigned byte or short;
 *   weights float or normalized unsigned byte or short), all of them, 4
 *   influences a set; weights that do not sum to 1 (or are negative) are
 *   normalized with one warning a file, and a vertex whose weights are all
 *   0 is not skinned. A skin's joints must be nodes of the scene, at most
 *   LM_SKIN_MAX_JOINTS; inverseBindMatrices are float MAT4s (identity when
 *   absent); an influence with a weight must name one of its joints. A node
 *   with a skin, or whose mesh has morph targets, gets its own copies of the
 *   mesh's lm meshes: their vertices are that node's pose, posed on the CPU
 *   (engine/scene/anim.c), at rest when loaded; `rest` keeps the undeformed
 *   vertices. Node `translation`, `rotation`, `scale` are kept (lm_node.trs)
 *   for the channels that replace them.
 * - Animations, all of them in the file's order (unnamed: "animation N"),
 *   every channel on translation, rotation, scale and weights with its
 *   sampler's STEP, LINEAR or CUBICSPLINE keys: times are floats, finite and
 *   strictly increasing; values are floats (rotation and weights also
 *   normalized integers), finite and within LM_GLTF_MAX_COORD, rotations
 *   normalized; the output holds a value a key (CUBICSPLINE: in-tangent,
 *   value, out-tangent; weights: the target count each). A weights channel
 *   drives every primitive of its node's mesh. Bad data fails the file
 *   naming the animation, channel and field ("animation 0 ('walk') channel
 *   2: sampler 1: input: accessor 4: time 3 (0.5) is not after time 2
 *   (0.5)"), as do a channel on a node the file lacks or one with a matrix,
 *   and a weights channel of the wrong width; channels on other paths or on
 *   nodes outside the scene are skipped with one warning a file.
 * - Materials, metallic-roughness to Phong (emissive ignored):
 *     color     = baseColorFactor.rgb, clamped to [0, 1]
 *     kd        = 1 - metallic               (metals have no diffuse part)
 *     ks        = mix(0.04, max(color), metallic)   (F0 of glass-like
 *                 dielectrics, the base color's for metals)
 *     shininess = 2 / roughness^4 - 2, clamped to [1, 1024] (the Blinn-Phong
 *                 exponent whose lobe matches GGX of alpha = roughness^2)
 *     ka        = kd; rho = max(color) * kd  (ka: the ambient term and the
 *                 sky reflect as the diffuse part does, so a metal takes
 *                 none of them, as in the pbr technique and both references)
 *     reflectivity = extras.reflectivity, a number in [0, 1] (absent: 0).
 *                 Mirror reflection is the artist's choice, not derived
 *                 from metallic/roughness: a rough metal is no mirror, and
 *                 existing files keep their look. A script overrides it per
 *                 material (scene{ materials = ... }).
 *   A primitive without a material gets material -1, the engine's default.
 *   Beside it (lm_scene.material_pbr) the metallic-roughness model whole,
 *   for the pbr technique: factors, alphaMode and alphaCutoff, normal scale,
 *   occlusion strength, emissiveFactor times KHR_materials_emissive_strength,
 *   and the textures (metallic-roughness, normal, occlusion, emissive), each
 *   with its KHR_texture_transform (TEXCOORD_0 only; another set warns).
 *   Colour images (base colour, emissive) are sampled as sRGB, data images
 *   as they are (one image used both ways is uploaded twice).
 *   baseColorFactor's alpha outside [0, 1] fails the file naming the
 *   material. Glass, as Blender writes it: KHR_materials_transmission's
 *   transmissionFactor (0..1), KHR_materials_ior's ior (1..10; default 1.5)
 *   and KHR_materials_volume's thicknessFactor, attenuationDistance (absent:
 *   no absorption) and attenuationColor (each in 0..1) go to
 *   lm_material_pbr's glass fields; a value out of range or not finite fails
 *   the file naming the material, extension and field. Their textures
 *   (transmissionTexture, thicknessTexture) are not read: one warning a
 *   file for each. A material with transmission is drawn blended: an
 *   OPAQUE one becomes BLEND with alpha 1 (Blender writes glass OPAQUE); on
 *   a MASK one transmission is not drawn (one warning a file). alphaMode
 *   BLEND materials are drawn by the forward pass over the lit image
 *   (scripts/transparent.lua), never into the G-buffer, and into shadow
 *   maps' transmittance (scripts/shadow.lua).
 * - Perspective cameras: yfov, znear, zfar; the aspect ratio is the output's:
 *   aspectRatio is kept (lm_camera.aspect, written back by export-gltf) but an
 *   output of another shape keeps yfov and widens or narrows x, as Blender
 *   does, never stretching the image.
 *   An infinite far plane (zfar absent) becomes LM_GLTF_INFINITE_ZFAR_RATIO
 *   times znear: relative, so any unit works (reversed float depth holds it).
 *   Orthographic cameras are kept (so camera indices stay the file's) and
 *   refused by name when a view uses one (lm_scene_camera_check).
 * - KHR_lights_punctual point, spot and directional lights, one lm light per
 *   node that names one, as the extension says: point and spot lights fall
 *   off as 1 / d^2 times its range window clamp(1 - (d / range)^4, 0, 1)
 *   (LM_FALLOFF_RANGE, radius = range; no range: no window). Intensity is
 *   photometric (candela for point and spot, lux for directional) and the
 *   engine's light is radiometric, folded with Lambert's 1 / pi (its Phong
 *   has none): power = intensity * LM_GLTF_EXPOSURE. Spot cone angles carry
 *   over as the inner and outer half-angles.
 * - With no light in the scene: "default_light", directional, white, power
 *   1, shining down along normalize(-0.3, -1, -0.5) from above the bounds.
 * - With no camera: "default_camera" from lm_scene_add_framing_camera, every
 *   corner of the bounds in view on any output at least as wide as high
 *   (`--camera auto` fits the output's own aspect).
 * - A material's baseColorTexture (TEXCOORD_0) becomes a scene texture:
 *   tinygltf never sees the images (no stb_image); the images a material
 *   uses are decoded through OpenImageIO
 *   (engine/image) to RGBA8 as stored, and uploaded as sRGB so that shaders
 *   sample linear colour, multiplied by baseColorFactor. An image that does
 *   not decode, or an external one that is missing, fails the scene with a
 *   message naming the material, texture and image index; an image no
 *   material uses is never decoded. Samplers are ignored (trilinear, repeat). */
#ifndef LIMN_GLTF_H
#define LIMN_GLTF_H

/* The bridge is C++: it needs the scene API with C linkage too. */
#ifdef __cplusplus
extern "C" {
#endif

#include "scene/scene.h"

#define LM_GLTF_MAX_COORD 1e9f      /* largest |coordinate| a vertex may have */
#define LM_GLTF_INFINITE_ZFAR_RATIO 1e6f /* zfar / znear of a camera with an infinite far plane */
#define LM_GLTF_MAX_ELEMENTS (1 << 26) /* most vertices or indices per primitive */
/* Engine light per glTF candela or lux: 1 / (683 lm/W * pi). Blender's
 * exporter writes W / (4 pi) * 683 cd for a point light of W watts and
 * 683 lux per W/m^2 of sun, so a Lambert surface shows here the radiance
 * Blender (Cycles, exposure 0, Standard view) shows. */
#define LM_GLTF_EXPOSURE (1.0 / (683.0 * 3.14159265358979))

/* Reads a .gltf or .glb file (told apart by the GLB magic, not the name).
 * NULL on any error, with a message naming the file and the element
 * ("scene.glb: mesh 0 primitive 1: index 7 is 12, past the 8 vertices").
 * The scene's world transforms are up to date; nothing is uploaded. */
lm_scene *lm_scene_load_gltf(const char *path, lm_error *err);

/* The Phong material the loader derives from glTF's metallic-roughness
 * values (above; color clamped, metallic and roughness in [0, 1]). */
lm_material lm_gltf_phong(const float color[3], float metallic, float roughness);

/* lm_scene_load for an owner that reads no vertex on the CPU (a renderer's:
 * the scene comes gpu_only): a glTF file's textures and meshes, but those
 * that deform, go to the GPU as they are read and their CPU copies are
 * freed at once, so that the file's meshes are never whole in memory and on
 * the GPU together. Needs a current GL context. */
lm_scene *lm_scene_load_gpu(const char *name, lm_error *err);
/* True when `name` ends in .gltf or .glb (any case): a file, not a built-in. */
bool lm_scene_is_gltf_name(const char *name);
/* A glTF file when lm_scene_is_gltf_name(name), else a built-in scene. */
lm_scene *lm_scene_load(const char *name, lm_error *err);

/* Writes the scene as it stands to a .glb (binary, told by the name) or
 * .gltf file (buffers embedded), whole or not at all (a temporary name
 * renamed), so that another program (Blender) sees what Limn renders and
 * lm_scene_load_gltf reads the same scene back:
 * - every node with its local matrix (the current pose), parents before
 *   children; a mesh node one primitive of its mesh as it is now (a
 *   deformed one: posed), POSITION, NORMAL, TEXCOORD_0 (and TANGENT), u32
 *   indices. Animations and skins are not written (one warning).
 * - materials as glTF metallic-roughness: the material's own when it came
 *   from glTF, else lm_scene_material_pbr's inverse of the loader's Phong
 *   mapping (metallic 1 - kd, roughness from the exponent); Limn's Phong
 *   values always in extras.limn {color, ka, kd, ks, shininess, rho} and
 *   reflectivity in extras.reflectivity. A Phong material the loader would
 *   not read back (ks other than mix(0.04, max(color), metallic), ka not kd)
 *   warns, naming it. Textures as PNG files beside the file, named
 *   texture-<hash of the texels>.png; KHR_texture_transform is not written.
 * - lights as KHR_lights_punctual in glTF's units: intensity = power /
 *   LM_GLTF_EXPOSURE (candela, lux), range the radius of a range falloff,
 *   the cone half-angles; a falloff glTF has not (window, none) warns and is
 *   kept in extras.limn_falloff, a light without shadows in
 *   extras.casts_shadows. extras.size as the loader reads it.
 * - cameras, perspective or orthographic, on their nodes (a node with two
 *   gets a child).
 * `warnings` gets a line per thing glTF cannot hold as Limn has it. */
bool lm_scene_write_gltf(const lm_scene *s, const char *path, lm_buf *warnings, lm_error *err);

#ifdef __cplusplus
}
#endif
#endif
