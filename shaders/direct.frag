// Deferred direct light over the G-buffer: position rebuilt from linear depth.
#include "lighting.glsl"

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat;
uniform vec3 ambient = vec3(0.0);
uniform vec3 background = vec3(0.0);

out vec4 lit;

void main() {
  vec4 m = texture(mat, uv);
  if (m.a < 0.5) { // no geometry here
    lit = vec4(background, 1.0);
    return;
  }
  vec4 c = texture(clr, uv);
  vec4 nn = texture(nrm, uv);
  vec3 p = position_from_depth(uv, texture(dpt, uv).r);
  vec3 n = safe_normalize(nn.xyz, vec3(0.0, 1.0, 0.0));
  vec3 v = safe_normalize(frame.camera_pos.xyz - p, n);
  lit = vec4(phong(c.rgb, m.xyz, nn.w, n, v, p, ambient), 1.0);
}
