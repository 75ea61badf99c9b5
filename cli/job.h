/* Capture jobs (cli/job.c) as `limn capture --job`, `limn reference` and
 * `limn report` share them: the job file read, its views enumerated, its
 * pipeline set up, the progress line. */
#ifndef LIMN_JOB_H
#define LIMN_JOB_H

#include "camera_path.h"
#include "capture_render.h"
#include "scene/sky.h"

#define MAX_LIST 64
#define MAX_PATH_KEYS 256
#define MAX_FRAMES 100000
#define MAX_VIEWS 200000 /* a job's views, frames counted (about 1 KB each) */

typedef struct job_scene {
  char path[1024], cameras[1024], name[LM_NAME_MAX];
  bool cameras_given; /* named in the job; else the list beside the scene, or the file's own cameras */
  lm_scene *scene;
  int first_camera, camera_count;
  uint64_t hash;
  int animation;      /* the job's `animation` in this scene (LM_ANIM_ALL by default) */
  int path_camera;    /* the camera a `path` or `turntable` moves (-1: none) */
  float centre[3], radius; /* of the scene's bounds as loaded: the orbit, near and far */
  float orbit;        /* a turntable's distance from the centre */
} job_scene;

/* The job's `references` table (limn reference, report, manifest merge): the command line's
 * --sky, --materials and --approximate win over it when given. */
typedef struct job_references {
  bool has_sky;
  lm_sky sky;
  int pbr_materials; /* 1 pbr, 0 phong, -1 not given */
  int approximate;   /* 1 or 0, -1 not given */
} job_references;

typedef struct job {
  char path[1024], dir[1024], script[1024], output[1024], manifest[1024];
  char renderer[16]; /* the references' renderer: "pov", "cycles" or "" (not given; cli/reference.h) */
  job_references references;
  job_scene scenes[MAX_LIST];
  int scene_count;
  char techniques[MAX_LIST][64];
  int technique_count;
  int sizes[MAX_LIST][2];
  int size_count;
  char set_names[MAX_LIST][128], set_values[MAX_LIST][256];
  int set_count;
  int events[MAX_LIST], event_count; /* frames where a light, door or object changes: limn report's lags */
  int frames;
  uint64_t hash;
  /* `time`: timed false leaves the scenes as loaded. A sequence has
   * frame_count frames at time_start + k / fps; a still (fps 0) one. */
  bool timed;
  double time_start, time_stop, fps;
  int frame_count;
  char animation[LM_NAME_MAX];
  /* `path` (keys) or `turntable`: each scene's one view is a camera they move. */
  camera_key keys[MAX_PATH_KEYS];
  int key_count;
  bool turntable;
  double turns, elevation, distance; /* degrees; distance 0: auto (the scene framed) */
} job;

typedef struct job_view {
  int scene, camera, size, technique;
  /* A sequence's frame (a job's `time = { start, stop, fps }`): frame 0 ..
   * frames - 1 at `time` seconds; a still job's views are frame 0 at its
   * one time. Views of one place (scene, size, technique, camera) differing
   * only in frame are one sequence, listed in frame order. */
  int frame;
  double time;
  char output[1024];
} job_view;


/* Reads and checks the job file (Lua data); false with a message naming it. */
bool job_read(job *j, const char *path, lm_error *err);
/* Loads every scene and camera list (once; a path or turntable adds its
 * camera instead) and lists the views in the job's order: scene, size,
 * technique, camera, frame, with their outputs. Without
 * all_techniques, the places only (technique 0, no output): what does not
 * depend on the technique, as a reference render. *out is malloc'd. */
bool job_views(job *j, bool all_techniques, job_view **out, int *count, lm_error *err);
void job_free_scenes(job *j);
/* The job's script with its `set` options and then `sets` (NAME=VALUE);
 * with check_techniques its techniques must exist (an empty list becomes
 * the script's first). NULL after logging what is wrong. */
lm_pipeline *job_pipeline(job *j, const char *const *sets, int set_count, bool check_techniques);
/* Poses view v's scene at the view's time (lm_scene_set_time, when the job
 * is timed) and moves the path's or turntable's camera there. The caller
 * uploads deformed meshes where there is a GL context. */
void job_pose(const job *j, const job_view *v);
/* The shard (of `shards`) that renders view i of `count`: i % shards for
 * stills; for sequences contiguous runs of views, so that a shard renders
 * consecutive frames and temporal histories carry from frame to frame. */
int job_shard_of(const job *j, int i, int count, int shards);
/* Creates the folders above `file`. */
bool job_make_parent(const char *file, lm_error *err);
/* A progress bar on a terminal (tty), else one line per item. */
void job_progress(bool quiet, bool tty, int done, int total, const char *what);

/* The manifest of a capture job (a shard's when shards > 1:
 * <manifest stem>.shard-I-of-N.json). */
void job_manifest_path(const job *j, int shard, int shards, char *out, size_t cap);
/* The job hash a manifest records: the job file's, then the --set flags. */
uint64_t job_hash_with(const job *j, const char *const *sets, int set_count);

/* A manifest as capture writes it: the header's JSON text (everything
 * before "images"), then one line of JSON per view (NULL: not rendered). */
typedef struct job_manifest {
  char *header;
  char **entries; /* one per view */
  int run;        /* the run that last wrote it (0: none) */
} job_manifest;

/* Reads the file's header and its entries, each put at the view whose
 * output it names; false when there is no such file (m stays empty).
 * m->entries must hold `count` pointers. */
bool job_manifest_load(const char *path, const job_view *views, int count, job_manifest *m);
/* Writes the header and the entries whole (a temporary file renamed). */
bool job_manifest_write(const char *path, const job_manifest *m, int count, lm_error *err);
/* A string or number field of the header ("job_hash"), unquoted, into out;
 * false when it is not there. */
bool job_manifest_field(const job_manifest *m, const char *key, char *out, size_t cap);

typedef struct capture_job_args {
  const char *path;
  const char *const *sets; /* extra NAME=VALUE options, after the job's own */
  int set_count;
  int shard, shards;       /* render views v with v % shards == shard */
  bool force, quiet, verbose;
  const char *egl;
  lm_clock clock;
} capture_job_args;
/* `limn capture --job FILE`: the exit code. */
int capture_job_run(const capture_job_args *a);

#endif
