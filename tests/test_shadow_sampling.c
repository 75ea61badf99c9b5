/* shaders/shadow.glsl's sampling: shadow_texels, the one gather and its
 * bilinear weights that ESM and PCSS read a position's 2 x 2 neighbours with,
 * against four fetches each clamped into the tile (shadow_texel, as they read
 * before) weighted by the position's fraction: the same bilinear value,
 * inside a tile, on its edges and past them on every side, at fractions 0,
 * 0.25, 0.5 and 0.75 (0: a texel's centre). A test shader (in the scratch
 * root) fills an r32f atlas with a value per texel and a second one writes,
 * per pixel, the two values' difference and both values. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gl_test.h"

enum { W = 64, H = 48 };

static const char atlas_frag[] =
    "out vec4 o;\n"
    "void main() {\n"
    "  ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "  o = vec4(0.001 + fract(float(p.x * 37 + p.y * 101) / 997.0), 0.0, 0.0, 1.0);\n"
    "}\n";

/* The tile [lo, hi] lies inside the atlas; the pixels' positions run from 8
 * texels before it to 23 after it in x, 6 before and 17 after in y. */
static const char texels_frag[] =
    "#include \"shadow.glsl\"\n"
    "out vec4 o;\n"
    "float bilinear(vec4 v, vec2 f) { return mix(mix(v.x, v.y, f.x), mix(v.z, v.w, f.x), f.y); }\n"
    "void main() {\n"
    "  ivec2 t = ivec2(gl_FragCoord.xy), lo = ivec2(8, 6), hi = ivec2(40, 30);\n"
    "  vec2 f = vec2((t.x * 7) % 4, (t.y * 5) % 4) * 0.25, w;\n"
    "  vec4 fetched = vec4(shadow_texel(t, lo, hi), shadow_texel(t + ivec2(1, 0), lo, hi),\n"
    "                      shadow_texel(t + ivec2(0, 1), lo, hi), shadow_texel(t + ivec2(1, 1), lo, hi));\n"
    "  vec4 gathered = shadow_texels(vec2(t) + f, lo, hi, w);\n"
    "  float a = bilinear(fetched, f), b = bilinear(gathered, w);\n"
    "  o = vec4(abs(a - b), a, b, 1.0);\n"
    "}\n";

static const char texels_lua[] =
    "Techniques = { 'texels' }\n"
    "Options = {}\n"
    "function OnRender()\n"
    "  local atlas = pass{ 'atlas', shader = 'test_atlas.frag', out = target{ 'atlas', format = 'r32f' } }\n"
    "  present(pass{ 'texels', shader = 'test_texels.frag', inputs = { shadow_atlas = atlas },\n"
    "                out = target{ 'texels', format = 'rgba32f' } }, 'display')\n"
    "end\n";

static int setup(void **state) {
  if (gl_test_setup(state) != 0) return -1;
  return gl_write_file("shaders/test_atlas.frag", atlas_frag) &&
                 gl_write_file("shaders/test_texels.frag", texels_frag) && gl_write_file("texels.lua", texels_lua)
             ? 0
             : -1;
}

static void one_gather_weighs_as_the_four_clamped_texels(void **state) {
  (void)state;
  gl_result r = gl_render_ok(&(gl_run){.script = "texels.lua", .width = W, .height = H});
  double worst = 0, lo = 1, hi = 0;
  int differ = 0;
  for (int i = 0; i < W * H; i++) {
    const float *p = r.rgb + 3 * i;
    worst = fmax(worst, p[0]);
    differ += p[1] != p[2]; /* past the tile's far edge: weight 1 on the far texel, a lerp's rounding */
    lo = fmin(lo, p[1]), hi = fmax(hi, p[1]);
  }
  printf("gather against four clamped fetches over %d pixels: largest difference %g, values that differ %d; "
         "the fetched values span %.4f .. %.4f\n",
         W * H, worst, differ, lo, hi);
  assert_true(worst <= 1e-6); /* values of 0.001 .. 1.001 */
  assert_true(lo > 0 && hi - lo > 0.5); /* the atlas was read: its values vary */
  gl_result_free(&r);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(one_gather_weighs_as_the_four_clamped_texels),
  };
  return cmocka_run_group_tests(tests, setup, gl_test_teardown);
}
