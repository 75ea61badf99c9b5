// Glossy indirect light for the pbr technique's surfaces (scripts/glossy.lua):
// screen-space reflections of the lit frame, roughness-aware, with the sky
// for what the screen cannot show. Each pbr pixel takes `samples` GGX
// half-vectors of its roughness (alpha = roughness^2, as pbr_reflect in
// lighting.glsl), sampled by D(h) n.h (R3 points shifted per 4 x 4 tile),
// reflects the view direction about each, and marches the ray through the
// depth buffer in `steps` geometric steps from a pixel's footprint to the
// scene's diagonal; where a step passes behind the buffer's surface within
// `thickness` of its depth, the ray met that surface and brings the lit
// frame's radiance there; a ray that leaves the screen or passes behind
// everything brings what the screen cannot show (unseen): with LPV (the
// frame's technique has light propagation volumes, scripts/lpv.lua) the
// volumes' light arriving along the ray (lpv_light_from, band 1 whole: the
// GGX directions sampled are what makes it roughness-aware), plus the sky's
// radiance (sky.glsl's sky_radiance, plus the background) times the share
// the geometry volume lets through along the ray (SKY_OCCLUSION,
// lpv_sky_through); without, the sky as the camera would see it. The estimate of
// int L(l) f_spec(v, l) n.l dl is the mean of L(l) F(v.h) 4 Vis n.l v.h / n.h
// (Smith height-correlated Vis, Schlick F): a mirror (alpha -> 0) reflects F
// L(r). Phong pixels and background keep the lit frame bit for bit.
#include "gbuffer.glsl"
#include "halton.glsl"
#ifdef LPV
#include "lpv_light.glsl"
#endif

uniform sampler2D clr, nrm, dpt, mat, lit;
uniform vec3 background = vec3(0.0);
uniform int samples = 4, steps = 24;
uniform float thickness = 0.05; // a hit lies within this share of the buffer's depth behind it
uniform float reach = 1.0;      // the march's length, world units (the scene's diagonal)

out vec4 result;

// The light arriving at p facing n along unit direction l from what the
// screen does not show, pre-exposed as the lit frame it stands in for.
vec3 unseen(vec3 p, vec3 n, vec3 l) {
  vec3 sky = exposed(background) + sky_radiance(l);
#ifdef LPV
  vec3 bounce = lpv_light_from(p, n, l, 1.0); // sets lpv_origins, which lpv_sky_through reads
#ifdef SKY_OCCLUSION
  sky *= lpv_sky_through(p, n, l);
#endif
  return bounce + sky;
#else
  return sky;
#endif
}

// The lit frame's radiance along the ray from p (facing n) in unit direction
// l, or unseen's where the screen does not show what it meets.
vec3 trace(vec3 p, vec3 n, vec3 l, float foot) {
  float t0 = max(foot, 1e-6 * reach), t1 = max(reach, 2.0 * t0);
  float grow = pow(t1 / t0, 1.0 / float(max(steps - 1, 1)));
  float t = t0;
  for (int i = 0; i < steps; i++, t *= grow) {
    vec4 c = frame.view_proj * vec4(p + t * l, 1.0);
    if (c.w <= 0.0) break; // behind the camera
    vec2 uv = c.xy / c.w * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) break;
    float ray = c.w, seen = dpt_view_depth(textureLod(dpt, uv, 0.0).r); // view depths
    bool covered = textureLod(mat, uv, 0.0).a >= 0.5;
    if (covered && ray > seen && ray < seen * (1.0 + thickness) + t * (grow - 1.0))
      return textureLod(lit, uv, 0.0).rgb;
  }
  return unseen(p, n, l);
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec3 base = texelFetch(lit, px, 0).rgb;
  result = vec4(base, 1.0);
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, px);
  if (!s.covered || !s.pbr) return;
  vec3 v = safe_normalize(frame.camera_pos.xyz - s.p, s.n);
  float ndv = max(dot(s.n, v), 1e-4), a = max(s.roughness * s.roughness, 1e-3), a2 = a * a;
  float foot = 2.0 * dpt_view_depth(s.depth01) * frame.clip.w * frame.output_size.w; // a pixel's world size
  mat3 around = tangent_frame(s.n);
  vec3 offset = halton_offset(px, 4), sum = vec3(0.0);
  for (int i = 0; i < samples; i++) {
    vec2 u = r3_sample(i, offset).xy;
    // GGX's D(h) n.h: cos^2 theta = (1 - u) / (1 + (a^2 - 1) u)
    float c2 = (1.0 - u.y) / max(1.0 + (a2 - 1.0) * u.y, 1e-8), ct = sqrt(saturate(c2)), st = sqrt(saturate(1.0 - c2));
    float phi = 2.0 * PI * u.x;
    vec3 h = around * vec3(cos(phi) * st, sin(phi) * st, ct);
    vec3 l = reflect(-v, h);
    float ndl = dot(s.n, l), vdh = saturate(dot(v, h)), ndh = max(dot(s.n, h), 1e-4);
    if (ndl <= 0.0) continue;
    vec3 weight = ggx_fresnel(s.f0, vdh) * (4.0 * ggx_visibility(ndl, ndv, a2) * ndl * vdh / ndh);
    sum += weight * trace(s.p + s.n * foot, s.n, l, foot);
  }
  result.rgb = base + finite_or_zero(sum / float(max(samples, 1)));
}
