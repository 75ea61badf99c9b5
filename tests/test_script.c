/* Pipeline scripts: errors with script:line, options, the sandbox, the
 * instruction budget, and what a script records (no GL needed).
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "script/script.h"

static char dir[256];

static const char *write_script(const char *name, const char *text) {
  static char path[512];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
  return path;
}

static int setup(void **state) {
  (void)state;
  snprintf(dir, sizeof dir, "/tmp/limn-script-XXXXXX");
  return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state) {
  (void)state;
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  return system(cmd);
}

static lm_pipeline *load(const char *name, const char *text, lm_error *err) {
  return lm_pipeline_load(&(lm_pipeline_desc){.path = write_script(name, text),
                                             .instruction_budget = 2000000}, err);
}

/* Records and compiles one frame; returns false with the message in err. */
static bool frame(lm_pipeline *p, lm_graph *g, lm_error *err) {
  lm_graph_begin(g, 64, 48);
  int presented;
  if (!lm_pipeline_record(p, g, &presented, err)) return false;
  lm_graph_mark_output(g, presented);
  return lm_graph_compile(g, err);
}

static void first_line(const lm_error *err, char *out, size_t cap) {
  snprintf(out, cap, "%.*s", (int)strcspn(err->msg, "\n"), err->msg);
}

static void syntax_errors_name_script_and_line(void **state) {
  (void)state;
  lm_error err;
  assert_null(load("syntax.lua", "Techniques = { 'dl' }\nfunction OnRender(tech)\n  local x = = 1\nend\n", &err));
  assert_non_null(strstr(err.msg, "syntax.lua:3:"));
}

static void runtime_errors_carry_a_traceback(void **state) {
  (void)state;
  lm_error err;
  lm_pipeline *p = load("runtime.lua",
                        "Techniques = { 'dl' }\n"
                        "local function helper() return nil + 1 end\n"
                        "function OnRender(tech)\n"
                        "  helper()\n"
                        "end\n", &err);
  assert_non_null(p);
  lm_graph *g = lm_graph_create();
  assert_false(frame(p, g, &err));
  char line[512];
  first_line(&err, line, sizeof line);
  assert_non_null(strstr(line, "runtime.lua:2: attempt to perform arithmetic on a nil value"));
  assert_non_null(strstr(err.msg, "stack traceback"));
  assert_non_null(strstr(err.msg, "runtime.lua:4:"));
  lm_graph_destroy(g);
  lm_pipeline_destroy(p);
}

static const char *good_script =
    "Techniques = { 'dl', 'other' }\n"
    "Options = { ambient = 0.1, bloom = false, dof = { focus = 3.5, mode = 'lens' } }\n"
    "Seen = nil\n"
    "function OnCreate() History = target{ 'history', format = 'r32f', size = { 1, 1 } } end\n"
    "function OnRender(tech)\n"
    "  Seen = tech\n"
    "  local a = target{ 'a', format = 'rgba16f', scale = 0.5 }\n"
    "  local depth = target{ 'depth', format = 'depth32f', scale = 0.5 }\n"
    "  scene{ 'geometry', out = a, depth = depth, clear = { 0, 0, 0, 1 } }\n"
    "  local unused = pass{ 'unused', shader = 'x.frag', inputs = { src = a },\n"
    "                       out = target{ 'u', format = 'rgba8' } }\n"
    "  local b = pass{ 'light', shader = 'x.frag', inputs = { src = a, hist = History },\n"
    "                  params = { k = tech.ambient, v = { 1, 2, 3 }, on = tech.bloom },\n"
    "                  defines = { B = 2, A = true, C = false }, out = target{ 'b', format = 'rgba8' } }\n"
    "  present(b)\n"
    "end\n";

static void a_script_records_a_frame(void **state) {
  (void)state;
  lm_error err;
  lm_pipeline *p = load("good.lua", good_script, &err);
  assert_non_null(p);
  assert_string_equal(lm_pipeline_technique(p), "dl");
  lm_graph *g = lm_graph_create();
  assert_true(frame(p, g, &err));
  assert_int_equal(lm_graph_pass_count(g), 3);
  assert_string_equal(lm_graph_pass(g, 0).name, "geometry");
  assert_true(lm_graph_pass(g, 0).kind == LM_PASS_SCENE);
  assert_string_equal(lm_graph_pass(g, 0).shader, "std");
  assert_true(lm_graph_pass(g, 1).culled); /* 'unused' reaches nothing presented */
  assert_false(lm_graph_pass(g, 2).culled);
  assert_non_null(strstr(lm_graph_pass(g, 2).where, "good.lua:12"));
  int a = lm_graph_find_target(g, "a");
  assert_int_equal(lm_graph_target(g, a).width, 32);
  assert_true(lm_graph_target(g, lm_graph_find_target(g, "history")).persistent);
  /* A second frame runs OnRender only; OnCreate's target is still there. */
  assert_true(frame(p, g, &err));
  assert_int_equal(lm_graph_find_target(g, "history"), 0);
  lm_graph_destroy(g);
  lm_pipeline_destroy(p);
}

/* camera_view() gives the frame's camera (eye, unit axes from the inverse
 * view, near, far, tan(fov_y / 2), aspect), nil in OnCreate and without one;
 * the script reports what it got through an error message. */
static void camera_view_gives_the_frames_camera(void **state) {
  (void)state;
  lm_error err;
  lm_pipeline *p = load("camera.lua",
                        "Techniques = { 'dl' }\n"
                        "function OnCreate() assert(camera_view() == nil) end\n"
                        "function OnRender(tech)\n"
                        "  local c = camera_view()\n"
                        "  if c then\n"
                        "    local function v(t) return string.format('%g %g %g', t[1], t[2], t[3]) end\n"
                        "    error(string.format('camera %s | %s | %s | %s | %g %g %g %g', v(c.eye), v(c.forward),\n"
                        "                        v(c.up), v(c.right), c.near, c.far, c.tan_y, c.aspect), 0)\n"
                        "  end\n"
                        "  present(pass{ 'copy', shader = 'x.frag', out = target{ 'a', format = 'rgba8' } })\n"
                        "end\n", &err);
  assert_non_null(p);
  lm_graph *g = lm_graph_create();
  if (!frame(p, g, &err)) fail_msg("%s", err.msg); /* no camera given: nil */
  /* A camera at (1, 2, 3) turned 90 degrees about y: it looks along -x, its right is -z. */
  lm_frame_data f = {.camera_pos = {1, 2, 3, 1}, .clip = {0.1f, 50, 0.02f, 0.5f}, .output_size = {64, 48}};
  const float inv_view[16] = {0, 0, -1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 2, 3, 1};
  memcpy(f.inv_view, inv_view, sizeof inv_view);
  lm_pipeline_set_scene(p, NULL, &f, NULL, (lm_still_frames){0});
  assert_false(frame(p, g, &err));
  assert_non_null(strstr(err.msg, "camera 1 2 3 | -1 -0 -0 | 0 1 0 | 0 0 -1 | 0.1 50 0.5 1.33333"));
  lm_graph_destroy(g);
  lm_pipeline_destroy(p);
}

static void options_are_typed_and_listed(void **state) {
  (void)state;
  lm_error err;
  lm_pipeline *p = load("options.lua", good_script, &err);
  assert_non_null(p);
  assert_true(lm_pipeline_set_option(p, "ambient", "0.25", &err));
  assert_true(lm_pipeline_set_option(p, "bloom", "true", &err));
  assert_true(lm_pipeline_set_option(p, "dof.focus", "7", &err));
  assert_true(lm_pipeline_set_option(p, "dof.mode", "range", &err));
  assert_false(lm_pipeline_set_option(p, "bloom", "maybe", &err));
  assert_non_null(strstr(err.msg, "not a boolean"));
  assert_false(lm_pipeline_set_option(p, "ambient", "nan", &err));
  assert_non_null(strstr(err.msg, "not a finite number"));
  assert_false(lm_pipeline_set_option(p, "ambeint", "1", &err));
  assert_non_null(strstr(err.msg, "unknown option 'ambeint'"));
  assert_non_null(strstr(err.msg, "ambient=0.25, bloom=true, dof.focus=7, dof.mode=range"));
  assert_false(lm_pipeline_set_option(p, "dof", "1", &err));
  assert_false(lm_pipeline_set_option(p, "dof.focus.x", "1", &err));
  assert_false(lm_pipeline_set_technique(p, "isr", &err));
  assert_non_null(strstr(err.msg, "unknown technique 'isr'"));
  assert_non_null(strstr(err.msg, "known: dl, other"));
  assert_true(lm_pipeline_set_technique(p, "other", &err));
  /* What the viewer reads before it flips an option. */
  char v[64];
  assert_true(lm_pipeline_get_option(p, "bloom", v, sizeof v));
  assert_string_equal(v, "true");
  assert_true(lm_pipeline_get_option(p, "dof", v, sizeof v));
  assert_string_equal(v, "table");
  assert_true(lm_pipeline_get_option(p, "dof.focus", v, sizeof v));
  assert_string_equal(v, "7");
  assert_false(lm_pipeline_get_option(p, "dof.nope", v, sizeof v));
  assert_false(lm_pipeline_get_option(p, "bloom.enabled", v, sizeof v));
  assert_false(lm_pipeline_get_option(p, "nope", v, sizeof v));
  lm_pipeline_destroy(p);
}

static void script_errors_name_the_field(void **state) {
  (void)state;
  static const struct {
    const char *body, *expect;
  } cases[] = {
      {"pass{ 'p', shader = 'x.frag', inptus = {}, out = target{ 't', format = 'rgba8' } }",
       "bad.lua:3: pass 'p': unknown field 'inptus' (known: shader, inputs, params, out, defines, fetches, fold_output)"},
      {"target{ 't', format = 'rgb9' }", "bad.lua:3: target 't': unknown format 'rgb9'"},
      {"target{ 't', format = 'rgba8', scale = -1 }", "bad.lua:3: target 't': scale must be"},
      {"pass{ shader = 'x.frag' }", "bad.lua:3: pass: give the pass a name first"},
      /* Found by fuzz_pipeline: a number as the name was freed while in use. */
      {"target{ 16, format = 'rgba8' }", "bad.lua:3: target: the name (first entry) must be a string, not a number"},
      {"scene{ 16, out = target{ 't', format = 'rgba8' } }", "bad.lua:3: scene: the name (first entry) must be a string"},
      {"pass{ 'p', out = target{ 't', format = 'rgba8' } }", "bad.lua:3: pass 'p': field 'shader' is missing"},
      {"pass{ 'p', shader = 'x.frag', out = 5 }", "bad.lua:3: pass 'p': field 'out' must be a target"},
      {"pass{ 'p', shader = 'x.frag', params = { k = 'a' }, out = target{ 't', format = 'rgba8' } }",
       "bad.lua:3: pass 'p': parameter 'k': a number, boolean or list of numbers, not a string"},
      {"pass{ 'p', shader = 'x.frag', params = { k = 0/0 }, out = target{ 't', format = 'rgba8' } }",
       "bad.lua:3: pass 'p': parameter 'k' is not finite"},
      {"present(3)", "bad.lua:3: present: expected a target"},
      {"meter('lit')", "bad.lua:3: meter: expected a target"},
      {"scene{ 's', out = target{ 't', format = 'rgba8' }, fit = target{ 'r', format = 'rg32f' } }",
       "bad.lua:3: pass 's': fit is for a pass with views (a shadow plan)"},
      {"local t = target{ 't', format = 'rgba8' }\n"
       "pass{ 'light', shader = 'x.frag', inputs = { src = target{ 'never', format = 'rgba8' } }, out = t }\n"
       "present(t)", "bad.lua:4: pass 'light' reads target 'never' that no pass writes before it"},
      {"if not Old then Old = target{ 't', format = 'rgba8' }; pass{ 'p', shader = 'x.frag', out = Old } end\n"
       "present(Old)", "bad.lua:4: present: target 't' belongs to an earlier frame"},
      {"", "OnRender presented nothing"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    char text[2048];
    snprintf(text, sizeof text, "Techniques = { 'dl' }\nfunction OnRender(tech)\n%s\nend\n", cases[i].body);
    lm_error err;
    lm_pipeline *p = load("bad.lua", text, &err);
    assert_non_null(p);
    lm_graph *g = lm_graph_create();
    bool ok = frame(p, g, &err) && frame(p, g, &err); /* some errors show on the second frame */
    if (ok || !strstr(err.msg, cases[i].expect)) fail_msg("case %zu: got '%s'", i, ok ? "success" : err.msg);
    lm_graph_destroy(g);
    lm_pipeline_destroy(p);
  }
}

static void the_sandbox_holds(void **state) {
  (void)state;
  lm_error err;
  lm_pipeline *p = load("sandbox.lua",
                        "Techniques = { 'dl' }\n"
                        "assert(io == nil and package == nil and debug == nil)\n"
                        "assert(dofile == nil and loadfile == nil and load == nil)\n"
                        "assert(os.execute == nil and os.remove == nil and os.getenv == nil and os.exit == nil)\n"
                        "assert(string.dump == nil and type(os.clock()) == 'number')\n"
                        "function OnRender() end\n", &err);
  if (!p) fail_msg("%s", err.msg);
  lm_pipeline_destroy(p);
  static const struct {
    const char *code, *expect;
  } escapes[] = {
      {"require 'socket.core'", "require 'socket.core': no socket/core.lua"},
      {"require '../../etc/passwd'", "module names are letters"},
      {"require '/etc/passwd'", "module names are letters"},
      {"io.open('/tmp/x', 'w')", "attempt to index a nil value (global 'io')"},
      {"os.execute('true')", "attempt to call a nil value (field 'execute')"},
  };
  for (size_t i = 0; i < sizeof escapes / sizeof *escapes; i++) {
    char text[512];
    snprintf(text, sizeof text, "Techniques = { 'dl' }\n%s\nfunction OnRender() end\n", escapes[i].code);
    p = load("escape.lua", text, &err);
    assert_null(p);
    if (!strstr(err.msg, escapes[i].expect)) fail_msg("case %zu: '%s'", i, err.msg);
  }
}

static void modules_load_from_the_script_folder(void **state) {
  (void)state;
  write_script("helper.lua", "local M = {}\nfunction M.answer() return 42 end\nreturn M\n");
  lm_error err;
  lm_pipeline *p = load("uses_helper.lua",
                        "local h = require 'helper'\nassert(require 'helper' == h)\n"
                        "assert(h.answer() == 42)\nlocal g = require 'gbuffer'\n"
                        "assert(type(g.targets) == 'function')\n"
                        "Techniques = { 'dl' }\nfunction OnRender() end\n", &err);
  if (!p) fail_msg("%s", err.msg);
  lm_pipeline_destroy(p);
}

static void endless_loops_hit_the_budget(void **state) {
  (void)state;
  lm_error err;
  lm_pipeline *p = load("loop.lua", "Techniques = { 'dl' }\nfunction OnRender(tech)\n  while true do end\nend\n", &err);
  assert_non_null(p);
  lm_graph *g = lm_graph_create();
  assert_false(frame(p, g, &err));
  if (!strstr(err.msg, "loop.lua:3: instruction budget of 2000000 exceeded")) fail_msg("%s", err.msg);
  lm_graph_destroy(g);
  lm_pipeline_destroy(p);
}

static void scripts_need_techniques_and_on_render(void **state) {
  (void)state;
  lm_error err;
  assert_null(load("none.lua", "Techniques = { 'dl' }\n", &err));
  assert_non_null(strstr(err.msg, "defines no function OnRender"));
  assert_null(load("notech.lua", "function OnRender() end\n", &err));
  assert_non_null(strstr(err.msg, "Techniques must list"));
  assert_null(lm_pipeline_load(&(lm_pipeline_desc){.path = "/nonexistent.lua"}, &err));
  assert_non_null(strstr(err.msg, "/nonexistent.lua: cannot open"));
}

int main(void) {
  lm_log_set_level(LM_LOG_WARN);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(syntax_errors_name_script_and_line),
      cmocka_unit_test(runtime_errors_carry_a_traceback),
      cmocka_unit_test(a_script_records_a_frame),
      cmocka_unit_test(camera_view_gives_the_frames_camera),
      cmocka_unit_test(options_are_typed_and_listed),
      cmocka_unit_test(script_errors_name_the_field),
      cmocka_unit_test(the_sandbox_holds),
      cmocka_unit_test(modules_load_from_the_script_folder),
      cmocka_unit_test(endless_loops_hit_the_budget),
      cmocka_unit_test(scripts_need_techniques_and_on_render),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
