/* sky: the light of an outdoor sky as 3-band spherical harmonics (seed 003,
 * section 5.3: sky irradiance in 3 bands). A sky is a radiance over
 * directions, either a gradient from the horizon to the zenith or an
 * equirectangular HDR map; what the lighting shaders get is its irradiance
 * over pi, the radiance a white Lambertian surface of normal n sends back:
 * a uniform sky of radiance L gives L (shared/design/gi-scale.md). */
#ifndef LIMN_SKY_H
#define LIMN_SKY_H

#include "core/core.h"

typedef struct lm_sky {
  float zenith[3];  /* radiance straight up */
  float horizon[3]; /* radiance at the horizon and below it */
  float intensity;  /* multiplies either */
} lm_sky;

/* The gradient: intensity * (horizon + (zenith - horizon) * max(d.y, 0)) for
 * a unit direction d (+Y up, as in glTF). export-pov writes the same. */
void lm_sky_radiance(const lm_sky *sky, const float d[3], float out[3]);

/* LM_SKY_SH numbers: for r, g and b in turn the 9 coefficients c_lm of
 * E(n) / pi = sum c_lm Y_lm(n), in the order (0,0), (1,-1), (1,0), (1,1),
 * (2,-2), (2,-1), (2,0), (2,1), (2,2) of the real basis (x, y, z the normal);
 * c_lm = A_l / pi * L_lm with A = pi, 2 pi / 3, pi / 4 (Ramamoorthi and
 * Hanrahan's irradiance convolution). */
#define LM_SKY_SH 27
void lm_sky_sh_gradient(const lm_sky *sky, float out[LM_SKY_SH]);
/* The same for an equirectangular (latitude-longitude) map read through
 * OpenImageIO: top row the zenith, the middle column looking along -Z, u
 * growing toward +X; its values are radiance as stored (times intensity). A
 * map that cannot be read, or holds a value that is not finite and not
 * negative, is an error naming the file. */
bool lm_sky_sh_map(const char *path, float intensity, float out[LM_SKY_SH], lm_error *err);

#endif
