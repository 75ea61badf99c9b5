// A mask of the metallic surfaces (scripts/examples/mask.lua): 1 where the
// pbr technique drew a surface of metallic at least `metallic`, else 0.
#include "gbuffer.glsl"

uniform sampler2D clr, nrm, dpt, mat;
uniform float metallic = 0.5;

out vec4 dst;

void main() {
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, ivec2(gl_FragCoord.xy));
  float m = s.covered && s.pbr && 1.0 - s.k.y >= metallic ? 1.0 : 0.0; // k.y = 1 - metallic
  dst = vec4(m, m, m, 1.0);
}
