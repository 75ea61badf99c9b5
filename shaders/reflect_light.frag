// Lights the ray-traced hits (seed 003 section 6.3): the hit record the CPU
// wrote is a G-buffer (std.frag's layout, with the position given rather than
// rebuilt from depth), lit by the same Phong and shadows as the camera's view
// (lighting.glsl), seen from the reflecting surface. A miss sees the background
// and the sky.
// Alpha is 1 where a ray was traced, 0 where the surface does not reflect, so
// that the upsampling's average can be renormalized to the traced texels.
#include "gbuffer.glsl"

uniform sampler2D hit_clr, hit_nrm, hit_pos, hit_mat, rays_o, rays_d;
uniform vec3 ambient = vec3(0.0);
uniform vec3 background = vec3(0.0);

out vec4 lit;

void main() {
  ivec2 q = ivec2(gl_FragCoord.xy);
  if (texelFetch(rays_o, q, 0).w < 0.5) { // not reflective: nothing traced
    lit = vec4(0.0);
    return;
  }
  vec4 m = texelFetch(hit_mat, q, 0);
  if (m.a < 0.5) { // a miss: the background and the sky along the ray
    lit = vec4(exposed(background) + sky_radiance(safe_normalize(texelFetch(rays_d, q, 0).xyz, vec3(0.0, 1.0, 0.0))), 1.0);
    return;
  }
  vec4 c = texelFetch(hit_clr, q, 0), nn = texelFetch(hit_nrm, q, 0);
  vec3 n = safe_normalize(nn.xyz, vec3(0.0, 1.0, 0.0));
  vec3 v = safe_normalize(-texelFetch(rays_d, q, 0).xyz, n);
  lit = vec4(phong(saturate(c.rgb), saturate(m.xyz), nn.w, n, v, texelFetch(hit_pos, q, 0).xyz,
                 sky_ambient(ambient, n)), 1.0);
}
