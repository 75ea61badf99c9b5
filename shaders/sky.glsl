// The sky's light on a surface: the uniform ambient radiance plus, with
// `#define SKY`, the sky's irradiance over pi for normal n from 3-band
// spherical harmonics (scene/sky.h; seed 003, section 5.3), one mat3 of 9
// coefficients per colour (scripts/sky.lua binds them). Times k_a and the
// albedo it is the ambient term, which occlusion alone may take away.
#ifndef LIMN_SKY_GLSL
#define LIMN_SKY_GLSL
#ifdef SKY
uniform mat3 sky_r, sky_g, sky_b;

float sky_sh(mat3 c, vec3 n) {
  return c[0][0] * 0.282094792 + 0.488602512 * (c[0][1] * n.y + c[0][2] * n.z + c[1][0] * n.x) +
         1.092548431 * (c[1][1] * n.x * n.y + c[1][2] * n.y * n.z + c[2][1] * n.x * n.z) +
         0.315391565 * c[2][0] * (3.0 * n.z * n.z - 1.0) + 0.546274215 * c[2][2] * (n.x * n.x - n.y * n.y);
}
#endif

vec3 sky_ambient(vec3 ambient, vec3 n) {
#ifdef SKY
  // Three bands ring slightly below zero opposite a bright region: clamp.
  return ambient + max(vec3(sky_sh(sky_r, n), sky_sh(sky_g, n), sky_sh(sky_b, n)), 0.0);
#else
  return ambient;
#endif
}
#endif
