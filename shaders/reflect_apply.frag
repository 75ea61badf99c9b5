// Adds the reflected view to the surface's own light, weighted by its
// reflectivity: POV-Ray's finish { reflection r } without energy
// conservation (engine/scene/pov.h), so the two agree. The upsampled
// reflection's alpha is the share of traced texels in its average: dividing
// by it keeps a mirror's edge beside a plain surface from darkening.
#include "common.glsl"

in vec2 uv;
uniform sampler2D lit, refl, mat;

out vec4 dst;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float r = mat_alpha_reflectivity(texelFetch(mat, p, 0).a);
  vec4 s = texture(refl, uv);
  vec3 reflected = s.a > 1e-3 ? s.rgb / s.a : vec3(0.0);
  dst = vec4(texelFetch(lit, p, 0).rgb + r * reflected, 1.0);
}
