/* POV-Ray references of a capture job's views (`limn reference`), which
 * `limn report` also uses: each view exported (engine/scene/pov.h) and
 * rendered by POV-Ray into REFS/<scene>/<camera>_<WxH>-<hash>.exr, the hash
 * being lm_hash of the exported text, so an unchanged view is never
 * rendered twice and a changed one gets a new file. */
#ifndef LIMN_REFERENCE_H
#define LIMN_REFERENCE_H

#include "job.h"
#include "scene/pov.h"

typedef struct reference_args {
  const char *refs;   /* folder of the references (default out/reference) */
  const char *povray; /* the program (default povray) */
  lm_pov_desc pov;    /* export settings; camera and size are the view's */
  int jobs;           /* POV-Ray runs at once (default: the core count) */
  int shard, shards;  /* places p with p % shards == shard (default 0 of 1) */
  bool force, quiet;
} reference_args;

void reference_defaults(reference_args *a);
/* Exports place v into sdl and names its reference file (into path). */
bool reference_export(const reference_args *a, const job *j, const job_view *v, lm_buf *sdl, char *path,
                      size_t cap, lm_error *err);
/* Renders every place of the shard whose reference is missing (all with force): at most
 * a->jobs POV-Ray processes at once. paths (may be NULL) gets each place's
 * file. The exit code: 0, 1 when an export or a POV-Ray run failed (each
 * named by view, with POV-Ray's error lines). */
int reference_run(const reference_args *a, const job *j, const job_view *places, int n, char (*paths)[1024]);

#endif
