/* shaders/shadow.glsl's sampling: shadow_texels, the one gather that ESM and
 * PCSS read a texel's 2 x 2 neighbours with, against four fetches each
 * clamped into the tile (shadow_texel, as they read before): the same values
 * exactly, inside a tile, on its edges and past them on every side. A test
 * shader (in the scratch root) fills an r32f atlas with a value per texel and
 * a second one writes, per pixel t, the largest difference of the four pairs
 * (0 wanted), the fetches' mean and the gather's mean. */
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

/* The tile [lo, hi] lies inside the atlas; the pixels' t run from 8 texels
 * before it to 23 after it in x, 6 before and 17 after in y. */
static const char texels_frag[] =
    "#include \"shadow.glsl\"\n"
    "out vec4 o;\n"
    "void main() {\n"
    "  ivec2 t = ivec2(gl_FragCoord.xy), lo = ivec2(8, 6), hi = ivec2(40, 30);\n"
    "  vec4 fetched = vec4(shadow_texel(t, lo, hi), shadow_texel(t + ivec2(1, 0), lo, hi),\n"
    "                      shadow_texel(t + ivec2(0, 1), lo, hi), shadow_texel(t + ivec2(1, 1), lo, hi));\n"
    "  vec4 gathered = shadow_texels(t, lo, hi), d = abs(gathered - fetched);\n"
    "  o = vec4(max(max(d.x, d.y), max(d.z, d.w)), dot(fetched, vec4(0.25)), dot(gathered, vec4(0.25)), 1.0);\n"
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

static void one_gather_reads_the_four_clamped_texels(void **state) {
  (void)state;
  gl_result r = gl_render_ok(&(gl_run){.script = "texels.lua", .width = W, .height = H});
  double worst = 0, lo = 1, hi = 0;
  int differ = 0;
  for (int i = 0; i < W * H; i++) {
    const float *p = r.rgb + 3 * i;
    worst = fmax(worst, p[0]);
    differ += p[1] != p[2];
    lo = fmin(lo, p[1]), hi = fmax(hi, p[1]);
  }
  printf("gather against four clamped fetches over %d pixels: largest difference %g, means that differ %d; "
         "the fetched means span %.4f .. %.4f\n",
         W * H, worst, differ, lo, hi);
  assert_true(worst == 0 && differ == 0);
  assert_true(lo > 0 && hi - lo > 0.5); /* the atlas was read: its values vary */
  gl_result_free(&r);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(one_gather_reads_the_four_clamped_texels),
  };
  return cmocka_run_group_tests(tests, setup, gl_test_teardown);
}
