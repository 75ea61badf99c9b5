/* References of a capture job's views (`limn reference`), which `limn
 * report`, `limn manifest merge` and `limn farm` also use, from one of two
 * renderers behind one interface: name a view's file, write the renderer's
 * input beside it, start the renderer, rename its output into place.
 * - POV-Ray (radiosity; the default): each view exported (engine/scene/pov.h)
 *   into REFS/<scene>/<camera>_<WxH>-<hash>.exr, the hash being lm_hash of
 *   the exported text and the command line's settings.
 * - Cycles, Blender's path tracer (cli/reference_cycles.c): each view a
 *   spec (JSON) for cli/cycles_render.py, run by `blender -b`, into
 *   REFS/<scene>/<camera>_<WxH>-cycles-<hash>.exr, the hash covering the
 *   scene file's bytes, the spec's settings, the script and Blender's version.
 *   A scene's missing views go to one Blender run (its start costs seconds).
 * An unchanged view is never rendered twice and a changed one gets a new file;
 * a failed or killed render leaves no reference. */
#ifndef LIMN_REFERENCE_H
#define LIMN_REFERENCE_H

#include <getopt.h>
#include <sys/types.h>

#include "job.h"
#include "scene/pov.h"

typedef enum reference_renderer { REFERENCE_POV, REFERENCE_CYCLES } reference_renderer;

typedef struct reference_cycles {
  const char *blender; /* the program (default blender) */
  const char *script;  /* the Blender script (default <root>/cli/cycles_render.py) */
  int samples;         /* a pixel (default REFERENCE_CYCLES_SAMPLES) */
  int bounces;         /* diffuse bounces (default 8); 0: direct light only */
  int seed;            /* Cycles' seed (default 0) */
  char version[128];   /* `blender --version`'s first line (reference_prepare) */
  uint64_t script_hash;
} reference_cycles;

/* The default samples a pixel: the reference's noise (two seeds' mean
 * error) must stay below a tenth of dl+esm's error against it. On the
 * reference set's room (window view, 160x120, 8 bounces) dl+esm's error is
 * 0.064; two seeds differ by 0.0108 (17%) at 256 samples and 0.0052 (8.2%)
 * at 1024, as one over the root of the samples says. */
#define REFERENCE_CYCLES_SAMPLES 1024

typedef struct reference_args {
  const char *refs;   /* folder of the references (default out/reference) */
  reference_renderer renderer;
  bool renderer_given; /* --renderer on the command line: it wins over the job's `renderer` */
  bool sky_given, materials_given, approximate_given; /* and these over the job's `references` */
  const char *povray; /* POV-Ray's program (default povray) */
  lm_pov_desc pov;    /* POV-Ray's export settings (camera and size are the view's); Cycles takes
                         its materials and sky */
  reference_cycles cycles;
  int jobs;           /* renders at once; 0: POV-Ray's the core count, Cycles' 1 (it uses every core) */
  int shard, shards;  /* places p with job_shard_of(p) == shard (default 0 of 1) */
  bool force, quiet;
} reference_args;

void reference_defaults(reference_args *a);
/* "POV-Ray" or "Cycles". */
const char *reference_renderer_name(reference_renderer r);
/* One line saying what a reference is: "Cycles (1024 samples, 8 bounces, seed 0)". */
void reference_describe(const reference_args *a, char *out, size_t cap);

/* The flags that choose and set the renderer (--renderer, --samples,
 * --bounces, --seed, --blender, --cycles-script), shared by reference,
 * report, manifest merge and farm: reference_options ends with a zero entry
 * (REFERENCE_OPTION_COUNT entries in all). reference_flag takes these and
 * export-pov's (limn_pov_options, into a->pov, noting which were given):
 * 0 when it took getopt's c, 1 when c is neither, 2 after printing a usage
 * error for `limn CMD`. */
extern const struct option reference_options[];
#define REFERENCE_OPTION_COUNT 7
#define REFERENCE_OPTIONS_HELP                                                                           \
  "  --renderer pov|cycles  POV-Ray radiosity (default) or Blender's Cycles; the job's\n"                \
  "                       `renderer` field when not given\n"                                             \
  "  --samples N          Cycles: samples a pixel (default 1024)\n"                                      \
  "  --bounces N          Cycles: diffuse bounces (default 8; 0: direct light only)\n"                   \
  "  --seed N             Cycles: the noise pattern's seed (default 0)\n"                                \
  "  --blender PROGRAM    Cycles: the Blender program (default blender)\n"                               \
  "  --cycles-script FILE Cycles: the script Blender runs (default cli/cycles_render.py)\n"
int reference_flag(const char *cmd, int c, const char *arg, reference_args *a);

/* Before any view, once a run: takes the job's `renderer` and `references`
 * unless the command line gave them, refuses a job whose views are lit by
 * the sky (set sky.enabled) against references without one, checks the
 * settings fit the renderer, and for Cycles reads
 * Blender's version and the script. False with a message naming the
 * program and the Debian package that installs it when it cannot run. */
bool reference_prepare(reference_args *a, const job *j, lm_error *err);
/* The direct-only counterpart of a (POV-Ray without radiosity, Cycles with
 * 0 bounces) into *direct, and how its command line says it (flags); false
 * when a is direct-only already. */
bool reference_direct(const reference_args *a, reference_args *direct, const char **flags);

/* Writes the renderer's input for place v into `input` (POV-Ray's scene
 * text, Cycles' spec) and names its reference file (into path). */
bool reference_export(const reference_args *a, const job *j, const job_view *v, lm_buf *input, char *path,
                      size_t cap, lm_error *err);
/* Renders every place of the shard whose reference is missing (all with
 * force): at most a->jobs renderer processes at once, POV-Ray one view
 * each, Blender the views of one scene each (split to keep every job busy).
 * A view's reference appears when it is complete, whatever happens to the
 * others of its run; each view's progress line gives its wall time (a
 * Blender run's first includes Blender's start). paths (may be NULL)
 * gets each place's file. The exit code: 0, 1 when an export or a render
 * failed (each named by view, with the renderer's error lines). SIGINT and
 * SIGTERM stop the renders and remove their partial files first. */
int reference_run(const reference_args *a, const job *j, const job_view *places, int n, char (*paths)[1024]);

/* ---- the renderers' own parts ------------------------------------------ */

/* Cycles (cli/reference_cycles.c). */
bool reference_cycles_prepare(reference_cycles *c, lm_error *err);
/* Place v's spec into `spec` and its hash (everything that decides the image). */
bool reference_cycles_spec(const reference_args *a, const job *j, const job_view *v, lm_buf *spec, uint64_t *hash,
                           lm_error *err);
/* Blender's command line up to its "--" (REFERENCE_CYCLES_ARGS entries),
 * with `threads` threads (a number as text); reference.c appends a SPEC OUT
 * pair for each view of the run and the closing NULL, and runs it. */
#define REFERENCE_CYCLES_ARGS 11
void reference_cycles_argv(const reference_cycles *c, const char *threads, const char *argv[REFERENCE_CYCLES_ARGS]);
/* The name the spec gives view v ("scene/camera WxH", with " frame F" in a
 * sequence), which cycles_render.py's error lines quote. */
void reference_cycles_view_name(const job *j, const job_view *v, char *out, size_t cap);

#endif
