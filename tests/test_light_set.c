/* Light-set variants (light_set(), shaders/lighting.glsl's LIGHT_SET): the
 * lighting passes compiled for the scene's lights, each evaluated unrolled
 * for its kind, render what the general loop renders, for one light and for
 * eight of every kind, falloff and shadow kind, with Phong and with the pbr
 * materials, and so does the RSM's gather of the combined technique (each light
 * of its RSM views unrolled, shaders/rsm.glsl); a light added at run time compiles one new variant, and a scene
 * with more lights than pp.lua's light_variants takes the general loop; a light whose shadow tiles hold no
 * back face compiles out the offset step and renders the same image.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <cglm/cglm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"

enum { W = 96, H = 72 };

/* A light at p aimed at `at` (spots), added to s. */
static void add_light(lm_scene *s, lm_light l, vec3 p, vec3 at) {
  mat4 m;
  glm_lookat(p, at, fabsf(at[0] - p[0]) + fabsf(at[2] - p[2]) > 1e-3f ? (vec3){0, 1, 0} : (vec3){1, 0, 0}, m);
  glm_mat4_inv(m, m); /* lookat gives the view; the node holds its inverse */
  l.node = lm_scene_add_node(s, l.name, -1, (float *)m, -1, -1);
  lm_scene_add_light(s, &l);
}

/* The box with its point light, sun and spot (cornell_pov: a cube, cascades
 * and a spot tile of shadows), and five more lights of every falloff, two of
 * them casting shadows: eight. */
static lm_scene *box_with_eight_lights(void) {
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_pov", &err);
  assert_non_null(s);
  assert_int_equal(s->light_count, 3);
  add_light(s, (lm_light){.name = "window", .type = LM_LIGHT_POINT, .color = {1, 0.4f, 0.2f}, .power = 0.8f,
                          .radius = 1.5f, .falloff = LM_FALLOFF_WINDOW, .casts_shadows = true},
            (vec3){-0.6f, 1.5f, 0.3f}, (vec3){0, 0, 0});
  add_light(s, (lm_light){.name = "none", .type = LM_LIGHT_POINT, .color = {0.1f, 0.2f, 0.1f}, .power = 1,
                          .falloff = LM_FALLOFF_NONE},
            (vec3){0.5f, 0.4f, 0.6f}, (vec3){0, 0, 0});
  add_light(s, (lm_light){.name = "range", .type = LM_LIGHT_POINT, .color = {0.2f, 0.3f, 1}, .power = 0.6f,
                          .radius = 1.2f, .falloff = LM_FALLOFF_RANGE},
            (vec3){0.6f, 1.6f, -0.6f}, (vec3){0, 0, 0});
  add_light(s, (lm_light){.name = "spot_range", .type = LM_LIGHT_SPOT, .color = {0.3f, 1, 0.3f}, .power = 2,
                          .radius = 3, .inner_cone = 0.2f, .outer_cone = 0.4f, .falloff = LM_FALLOFF_RANGE,
                          .casts_shadows = true},
            (vec3){-0.8f, 1.8f, 0.8f}, (vec3){0.35f, 0.3f, 0.3f});
  add_light(s, (lm_light){.name = "spot_square", .type = LM_LIGHT_SPOT, .color = {1, 1, 0.5f}, .power = 0.4f,
                          .inner_cone = 0.3f, .outer_cone = 0.5f, .falloff = LM_FALLOFF_INVERSE_SQUARE},
            (vec3){0.8f, 0.3f, 0.8f}, (vec3){-1, 1, -1});
  assert_int_equal(s->light_count, 8);
  lm_scene_update(s);
  return s;
}

/* Renders s with the technique and options `sets` plus light_variants=16 (a
 * variant) and =0 (the general loop); returns the largest difference of the
 * linear output relative to max(value, 0.05), and its radiance in *sum. */
static double variant_against_loop(lm_scene *s, const char *tech, const char *extra, double *sum) {
  const char *on[] = {"ambient=0.02", extra, "light_variants=16", "light_cull=false", NULL};
  const char *off[] = {"ambient=0.02", extra, "light_variants=0", NULL};
  double ms;
  int before = lm_programs_stats("LIGHT_SET", &ms);
  gl_result a = gl_render_ok(&(gl_run){.scene = s, .tech = tech, .sets = on, .width = W, .height = H});
  int variants = lm_programs_stats("LIGHT_SET", &ms);
  gl_result b = gl_render_ok(&(gl_run){.scene = s, .tech = tech, .sets = off, .width = W, .height = H});
  assert_true(variants > before); /* the first frame compiled a variant ... */
  assert_int_equal(lm_programs_stats("LIGHT_SET", &ms), variants); /* ... the general loop none */
  double worst = 0;
  *sum = 0;
  for (int i = 0; i < 3 * W * H; i++) {
    /* The lit target is half float: sums in another order differ in its last bits. */
    worst = fmax(worst, fabs(a.rgb[i] - b.rgb[i]) / fmax(b.rgb[i], 0.05));
    *sum += b.rgb[i];
  }
  printf("%d lights, %s %s: variant against the general loop: largest relative difference %.2e, radiance %.2f\n",
         s->light_count, tech, extra, worst, *sum);
  gl_result_free(&a);
  gl_result_free(&b);
  return worst;
}

/* With light_cull (pp.lua's default) a scene of several lights one of which
 * the grid can cull (a spot's cone, a finite reach) keeps the grid's loop:
 * the eight lights' box compiles no variant, its loop reads the uniform
 * blocks and renders what the loop over storage blocks renders, exactly; the
 * Cornell box's one light compiles a variant. */
static void lights_the_grid_culls_keep_its_loop(void **state) {
  (void)state;
  lm_error err;
  lm_scene *one = lm_scene_builtin("cornell", &err), *eight = box_with_eight_lights();
  /* A filter no other test here compiles: a variant of it is new. */
  const char *sets[] = {"light_variants=16", "shadow.technique=poisson", NULL};
  double ms;
  int before = lm_programs_stats("LIGHT_SET", &ms);
  int blocks = lm_programs_stats("LIGHT_BLOCKS", &ms);
  gl_result r = gl_render_ok(&(gl_run){.scene = eight, .tech = "dl+esm", .sets = sets, .width = W, .height = H});
  assert_int_equal(lm_programs_stats("LIGHT_SET", &ms), before);
  /* ... reading the lights from uniform blocks: the image of the loop reading storage blocks */
  assert_true(lm_programs_stats("LIGHT_BLOCKS", &ms) > blocks);
  const char *storage[] = {"light_variants=0", "shadow.technique=poisson", NULL};
  gl_result u = gl_render_ok(&(gl_run){.scene = eight, .tech = "dl+esm", .sets = storage, .width = W, .height = H});
  double worst = 0;
  for (int i = 0; i < 3 * W * H; i++) worst = fmax(worst, fabs(r.rgb[i] - u.rgb[i]));
  printf("eight lights, the grid's loop over uniform blocks against storage blocks: largest difference %.2e\n", worst);
  assert_true(worst == 0);
  gl_result_free(&u);
  gl_result_free(&r);
  r = gl_render_ok(&(gl_run){.scene = one, .tech = "dl+esm", .sets = sets, .width = W, .height = H});
  assert_true(lm_programs_stats("LIGHT_SET", &ms) > before);
  gl_result_free(&r);
  lm_scene_destroy(one);
  lm_scene_destroy(eight);
}

static void variants_render_as_the_general_loop(void **state) {
  (void)state;
  lm_error err;
  lm_scene *one = lm_scene_builtin("cornell", &err), *eight = box_with_eight_lights();
  assert_non_null(one);
  assert_int_equal(one->light_count, 1);
  double sum_one, sum_eight, sum;
  /* One light, its cube of shadows, with two shadow filters; eight lights
   * with shadows of every kind, Phong and GGX. */
  assert_true(variant_against_loop(one, "dl+esm", "shadow.technique=esm", &sum_one) < 4e-3);
  assert_true(variant_against_loop(one, "dl+esm", "shadow.technique=pcf", &sum) < 4e-3);
  assert_true(variant_against_loop(eight, "dl+esm", "shadow.technique=hard", &sum_eight) < 4e-3);
  assert_true(variant_against_loop(eight, "dl+esm", "materials=pbr", &sum) < 4e-3);
  assert_true(variant_against_loop(eight, "dl", "shadow.technique=esm", &sum) < 4e-3);
  assert_true(sum_eight > 1.3 * sum_one); /* the seven more lights do light the box */
  /* The RSM gather inside ISR's march (its direct pass checked above), every kind of sender's light. */
  assert_true(variant_against_loop(eight, "isr+rsm+esm", "rsm.k=4", &sum) < 4e-3);
  lm_scene_destroy(one);
  lm_scene_destroy(eight);
}

/* A light added while the pipeline runs (a viewer's reload, a script) makes
 * the next frame compile the new set's variant, once; past light_variants
 * the general loop takes over and no variant is compiled. */
static void adding_a_light_compiles_a_new_variant(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  assert_non_null(s);
  const char *sets[] = {"ambient=0", "light_variants=2", "light_cull=false", NULL};
  double ms;
  lm_programs_clear(); /* none cached from the test before */
  gl_result r = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = sets, .width = W, .height = H});
  int first = lm_programs_stats("LIGHT_SET", &ms);
  assert_int_equal(first, 1);
  assert_true(gl_render_again(&r)); /* the same set: cached */
  assert_int_equal(lm_programs_stats("LIGHT_SET", &ms), first);
  float box[3], lit[3];
  gl_region(&r, 0, 0, W - 1, H - 1, box);
  add_light(s, (lm_light){.name = "added", .type = LM_LIGHT_POINT, .color = {1, 1, 1}, .power = 1, .radius = 3,
                          .casts_shadows = true},
            (vec3){0.5f, 1.5f, 0.5f}, (vec3){0, 0, 0});
  lm_scene_update(s);
  assert_true(gl_render_again(&r));
  assert_int_equal(lm_programs_stats("LIGHT_SET", &ms), first + 1);
  gl_region(&r, 0, 0, W - 1, H - 1, lit);
  printf("added light: luminance %.4f -> %.4f; light-set variants %d, compiled in %.1f ms\n", gl_luminance(box),
         gl_luminance(lit), first + 1, ms);
  assert_true(gl_luminance(lit) > 1.1f * gl_luminance(box));
  assert_true(gl_render_again(&r));
  assert_int_equal(lm_programs_stats("LIGHT_SET", &ms), first + 1);
  /* A third light: more than light_variants = 2, the general loop. */
  add_light(s, (lm_light){.name = "third", .type = LM_LIGHT_POINT, .color = {1, 1, 1}, .power = 1, .radius = 3},
            (vec3){-0.5f, 1.5f, 0.5f}, (vec3){0, 0, 0});
  lm_scene_update(s);
  assert_true(gl_render_again(&r));
  assert_int_equal(lm_programs_stats("LIGHT_SET", &ms), first + 1);
  gl_result_free(&r);
  lm_scene_destroy(s);
}

/* Where a light's shadow tiles hold no face it sees from behind
 * (lm_shadow_front_lit: the Cornell box's lamp), its variant compiles out the
 * shadow lookup's offset step (LIGHT_FRONT_LIT) and renders the image of the
 * variant that keeps it (front_lit=false) to the bit, with ESM and PCF. */
static void front_lit_lights_render_as_with_the_offset_step(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  assert_non_null(s);
  static const char *const filters[] = {"shadow.technique=esm", "shadow.technique=pcf"};
  lm_programs_clear(); /* none cached from the tests before */
  for (int f = 0; f < 2; f++) {
    const char *on[] = {"light_variants=16", filters[f], NULL};
    const char *off[] = {"light_variants=16", filters[f], "front_lit=false", NULL};
    double ms;
    int before = lm_programs_stats("LIGHT_FRONT_LIT", &ms);
    gl_result a = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = on, .width = W, .height = H});
    assert_true(lm_programs_stats("LIGHT_FRONT_LIT", &ms) > before);
    gl_result b = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = off, .width = W, .height = H});
    int differ = 0;
    for (int i = 0; i < 3 * W * H; i++) differ += memcmp(&a.rgb[i], &b.rgb[i], sizeof *a.rgb) != 0;
    printf("%s: without the offset step against with it: %d of %d values differ\n", filters[f], differ, 3 * W * H);
    assert_int_equal(differ, 0);
    gl_result_free(&a);
    gl_result_free(&b);
  }
  lm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(variants_render_as_the_general_loop),
      cmocka_unit_test(lights_the_grid_culls_keep_its_loop),
      cmocka_unit_test(adding_a_light_compiles_a_new_variant),
      cmocka_unit_test(front_lit_lights_render_as_with_the_offset_step),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
