// Deferred direct light over the G-buffer: position rebuilt from linear depth.
#include "gbuffer.glsl"

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat;
uniform vec3 ambient = vec3(0.0);
uniform vec3 background = vec3(0.0);

out vec4 lit;

void main() {
  Surface s = gbuffer_read(clr, nrm, dpt, mat, uv);
  lit = vec4(s.covered ? direct_light(s, ambient) : background + sky_seen(uv), 1.0);
}
