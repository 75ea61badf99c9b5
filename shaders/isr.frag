// Image-space radiosity (seed 000, eq 25-26, Listing 6, lines 1449-1562):
// indirect light gathered from N neighbours in screen space, and their
// ambient occlusion, in one loop over the coarse G-buffer.
//
// Output: rgb = E = (2 pi / N) sum_X F_PX L_X, eq 25 without rho_P (the
//               consumer multiplies by rho at its own resolution, so colour
//               edges stay sharp after upsampling);
//         a   = accessibility A = 1 - occlusion, 1 = open, 0 = fully
//               occluded (the value eq 29 reads as L_SSAO).
//
// Sample pattern: a Vogel (golden-angle) spiral of N points that fills a
// screen disc evenly, sample i at radius R sqrt((i + 0.5) / N) and angle
// i * 137.5 deg, turned per pixel by interleaved gradient noise (the blur
// then averages the rotations). R is `radius` world units projected at P's
// depth (so the disc shrinks as 1/depth), kept between one texel and the
// frame's height.
//
// Patch sizes: each sample stands for 1/N of the disc, whose radius at X's
// depth is R_X (world units). Eq 25 weighs each sample by 2 pi / N, so the
// patch area in its form factor (eq 6) is A_X = R_X^2 / 2: then
// (2 pi / N) A_X = pi R_X^2 / N, X's share of the disc, and the sum is the
// discrete radiosity gather. The seed derives A_X from depth alone; here it
// is also divided by the cosine between X's normal and the ray to the eye
// (at least 0.1), the area a pixel covers on a tilted surface: without it a
// wall seen edge-on, which few samples reach, gives almost nothing.
// Eq 26's occluder radius is r = R_X: with the 2 pi / N weight each sample
// then occludes X's share of solid angle, at most 2 pi / N.
#include "gbuffer.glsl"

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat; // coarse G-buffer
uniform sampler2D sender;             // L_X: albedo (the seed) or lit colour
#ifdef BOUNCE
uniform sampler2D previous;           // the last bounce: L_X += rho_X * its rgb
#endif
uniform int samples = 48;
uniform float radius = 0.5; // world units

out vec4 isr;

const float GOLDEN_ANGLE = 2.39996322972865332;

// Jimenez 2014: a per-pixel value in [0, 1) that a small blur averages well.
float interleaved_gradient_noise(vec2 px) {
  return fract(52.9829189 * fract(dot(px, vec2(0.06711056, 0.00583715))));
}

void main() {
  ivec2 size = textureSize(dpt, 0), px = ivec2(gl_FragCoord.xy);
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, px);
  if (!s.covered) {
    isr = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  int n = clamp(samples, 1, 256);
  // World length of one uv unit along y at view depth z: 2 z tan(fov / 2).
  float world_per_uv = 2.0 * frame.clip.y * frame.clip.w;
  float r_uv = clamp(max(radius, 0.0) / max(world_per_uv * s.depth01, 1e-12), 1.0 / float(size.y), 1.0);
  float aspect = float(size.x) / float(size.y);
  float turn = 2.0 * PI * interleaved_gradient_noise(vec2(px));
  vec3 gathered = vec3(0.0);
  float occlusion = 0.0;
  for (int i = 0; i < n; i++) {
    float angle = float(i) * GOLDEN_ANGLE + turn;
    vec2 q_uv = uv + r_uv * sqrt((float(i) + 0.5) / float(n)) * vec2(cos(angle) / aspect, sin(angle));
    if (any(lessThan(q_uv, vec2(0.0))) || any(greaterThanEqual(q_uv, vec2(1.0)))) continue;
    ivec2 q = min(ivec2(q_uv * vec2(size)), size - 1);
    if (q == px) continue; // a patch does not light itself
    Surface x = gbuffer_fetch(clr, nrm, dpt, mat, q);
    if (!x.covered) continue;
    vec3 to_x = x.p - s.p;
    float d2 = dot(to_x, to_x);
    if (d2 < 1e-12) continue; // coincident points: no direction
    vec3 w = to_x * inversesqrt(d2);
    float cos_p = max(dot(s.n, w), 0.0), cos_x = max(dot(x.n, -w), 0.0);
    float r_x = r_uv * world_per_uv * x.depth01, r_x2 = r_x * r_x;
    // Eq 25 with eq 6, F = cos cos A / (pi d^2). Adding A_X to d^2 keeps F
    // finite as d -> 0 and caps a sample's solid angle at 2 pi / N.
    float tilt = max(abs(dot(x.n, safe_normalize(frame.camera_pos.xyz - x.p, x.n))), 0.1);
    float area = 0.5 * r_x2 / tilt;
    float form_factor = cos_p * cos_x * area / (PI * (d2 + area));
    vec3 radiance = texelFetch(sender, q, 0).rgb;
#ifdef BOUNCE
    radiance += x.rho * texelFetch(previous, q, 0).rgb;
#endif
    gathered += form_factor * radiance;
    // Eq 26: the spherical cap 1 - sqrt(1 - (r / d)^2), the square root's
    // argument clamped where the sphere holds P (r > d: fully covered).
    occlusion += (1.0 - sqrt(max(1.0 - min(r_x2 / d2, 1.0), 0.0))) * cos_p;
  }
  float weight = 2.0 * PI / float(n);
  // Occlusion is normalized by pi, the cosine-weighted hemisphere.
  isr = vec4(weight * gathered, 1.0 - saturate(weight * occlusion / PI));
}
