/* libFuzzer target: the Lua pipeline API. Input bytes pick a random sequence
 * of API calls with random arguments; each becomes a line of a pipeline
 * script that is loaded, recorded for two frames and compiled (no GL). */
#include "fuzz_files.h"
#include "script/script.h"

typedef struct bytes {
  const unsigned char *p;
  size_t n;
} bytes;

static unsigned next(bytes *b) {
  if (!b->n) return 0;
  b->n--;
  return *b->p++;
}

static const char *pick(bytes *b, const char *const *list, int count) { return list[next(b) % count]; }

static void value(bytes *b, lm_buf *out, int depth) {
  static const char *const atoms[] = {"0", "1", "-1", "0.5", "1e300", "-1e300", "0/0", "1/0", "true", "false",
                                      "nil", "'rgba8'", "'depth32f'", "'x.frag'", "'direct.frag'", "'std'",
                                      "'esm'", "'a'", "''", "16", "65536", "3.7", "T[1]", "T[2]", "T[3]", "P"};
  unsigned k = next(b) % 30;
  if (k < 26 || depth > 2) {
    lm_buf_append(out, atoms[k % 26], -1);
    return;
  }
  lm_buf_append(out, "{", 1);
  for (unsigned i = next(b) % 4; i > 0; i--) {
    value(b, out, depth + 1);
    lm_buf_append(out, ", ", 2);
  }
  lm_buf_append(out, "}", 1);
}

static void table(bytes *b, lm_buf *out) {
  static const char *const keys[] = {"name", "format", "scale", "size", "mips", "shader", "inputs", "params",
                                     "out", "defines", "technique", "depth", "clear", "views", "c", "blur",
                                     "cascades", "resolution", "stabilize", "src", "bogus"};
  lm_buf_append(out, "{ ", 2);
  if (next(b) % 2) {
    value(b, out, 0);
    lm_buf_append(out, ", ", 2);
  }
  for (unsigned i = next(b) % 5; i > 0; i--) {
    lm_buf_printf(out, "%s = ", pick(b, keys, 21));
    value(b, out, 0);
    lm_buf_append(out, ", ", 2);
  }
  lm_buf_append(out, "}", 1);
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  static lm_scene *scene;
  if (!scene) {
    lm_log_set_level(LM_LOG_QUIET);
    lm_error err;
    scene = lm_scene_builtin("cornell", &err);
  }
  static const char *const calls[] = {"T[#T + 1] = target", "T[#T + 1] = pass", "scene", "present",
                                      "P = shadow_plan", "present", "output_size"};
  bytes b = {data, size};
  lm_buf src = {0};
  lm_buf_append(&src, "Techniques = { 'x' }\nT = {}\nfunction OnRender(tech)\n", -1);
  for (int line = 0; b.n && line < 24; line++) {
    const char *call = pick(&b, calls, 7);
    lm_buf_printf(&src, "  pcall(function() %s", call);
    if (!strcmp(call, "present")) {
      lm_buf_append(&src, "(", 1);
      value(&b, &src, 0);
      lm_buf_append(&src, ")", 1);
    } else if (!strcmp(call, "output_size")) {
      lm_buf_append(&src, "()", 2);
    } else {
      table(&b, &src);
    }
    lm_buf_append(&src, " end)\n", -1);
  }
  lm_buf_append(&src, "  present(T[#T] or target{ 'last', format = 'rgba8' })\nend\n", -1);
  const char *path = fuzz_write(fuzz_dir("lua"), "fuzz.lua", src.data, (size_t)src.len);
  lm_buf_free(&src);
  lm_error err;
  lm_pipeline *p = lm_pipeline_load(&(lm_pipeline_desc){.path = path, .instruction_budget = 1000000}, &err);
  if (!p) return 0;
  lm_graph *g = lm_graph_create();
  lm_shadow_plan plan = {0};
  lm_frame_data camera;
  lm_scene_frame_data(scene, 0, 64, 48, &camera);
  lm_pipeline_set_scene(p, scene, &camera, &plan, (lm_still_frames){0});
  for (int frame = 0; frame < 2; frame++) {
    lm_graph_begin(g, 64, 48);
    int presented;
    if (!lm_pipeline_record(p, g, &presented, &err)) break;
    lm_graph_mark_output(g, presented);
    lm_graph_compile(g, &err);
  }
  lm_shadow_plan_free(&plan);
  lm_graph_destroy(g);
  lm_pipeline_destroy(p);
  return 0;
}
