// The sky's light on a surface: the uniform ambient radiance plus, with
// `#define SKY`, the sky's irradiance over pi for normal n from 3-band
// spherical harmonics (scene/sky.h; seed 003, section 5.3), one mat3 of 9
// coefficients per colour (scripts/sky.lua binds them). Times k_a and the
// albedo it is the ambient term, which occlusion alone may take away.
#ifndef LIMN_SKY_GLSL
#define LIMN_SKY_GLSL
#include "common.glsl"
#ifdef SKY
uniform mat3 sky_r, sky_g, sky_b;

float sky_sh(mat3 c, vec3 n) {
  return c[0][0] * 0.282094792 + 0.488602512 * (c[0][1] * n.y + c[0][2] * n.z + c[1][0] * n.x) +
         1.092548431 * (c[1][1] * n.x * n.y + c[1][2] * n.y * n.z + c[2][1] * n.x * n.z) +
         0.315391565 * c[2][0] * (3.0 * n.z * n.z - 1.0) + 0.546274215 * c[2][2] * (n.x * n.x - n.y * n.y);
}
#endif

// The sky's radiance along unit direction d (black without SKY), pre-exposed
// (common.glsl's exposed()): the 3 bands of radiance, each band's irradiance
// coefficients over A_l / pi (1, 2/3, 1/4), clamped as above. What
// background pixels and rays that miss see, as POV-Ray's camera sees its
// sky_sphere (a smooth 3-band sky).
vec3 sky_radiance(vec3 d) {
#ifdef SKY
  const mat3 band = mat3(1.0, 1.5, 1.5, 1.5, 4.0, 4.0, 4.0, 4.0, 4.0); // sky_sh's layout
  return exposed(max(vec3(sky_sh(matrixCompMult(sky_r, band), d), sky_sh(matrixCompMult(sky_g, band), d),
                          sky_sh(matrixCompMult(sky_b, band), d)), 0.0));
#else
  return vec3(0.0);
#endif
}

// The sky seen through the output's uv (0..1), on the camera's ray there.
vec3 sky_seen(vec2 uv) {
#ifdef SKY
  return sky_radiance(safe_normalize(position_from_depth(uv, 1.0) - frame.camera_pos.xyz, vec3(0.0, 0.0, -1.0)));
#else
  return vec3(0.0);
#endif
}

// The background's radiance (a uniform colour) and the sky's through uv, pre-exposed.
vec3 background_seen(vec3 background, vec2 uv) { return exposed(background) + sky_seen(uv); }

// The ambient light on a surface facing n, pre-exposed (exposed()).
vec3 sky_ambient(vec3 ambient, vec3 n) {
#ifdef SKY
  // Three bands ring slightly below zero opposite a bright region: clamp.
  return exposed(ambient + max(vec3(sky_sh(sky_r, n), sky_sh(sky_g, n), sky_sh(sky_b, n)), 0.0));
#else
  return exposed(ambient);
#endif
}
#endif
