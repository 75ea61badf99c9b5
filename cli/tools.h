/* The `limn` command's subcommands. Each returns the process exit code:
 * 0 done, 1 failed, 2 bad usage. */
#ifndef LIMN_TOOLS_H
#define LIMN_TOOLS_H

#include <stdbool.h>
#include <getopt.h>
#include <stddef.h>

#include "core/core.h"

int limn_capture(int argc, char **argv);
int limn_view(int argc, char **argv);
int limn_graph(int argc, char **argv);
int limn_export_pov(int argc, char **argv);
int limn_export_gltf(int argc, char **argv);
int limn_compare(int argc, char **argv);
int limn_bench(int argc, char **argv);
int limn_reference(int argc, char **argv);
int limn_report(int argc, char **argv);
int limn_manifest(int argc, char **argv);
int limn_farm(int argc, char **argv);

/* Flag values (cli/args.c): false when `s` is not one. */
bool limn_parse_int(const char *s, int lo, int hi, int *out);
/* Prints "limn CMD: " then fmt with arg, and where to read more, to stderr;
 * returns 2 (bad usage). */
int limn_usage_error(const char *cmd, const char *fmt, const char *arg);
bool limn_parse_double(const char *s, double *out); /* finite */
/* --time: SECONDS (start = stop) or START:STOP, finite; the order is the caller's to check. */
bool limn_parse_time(const char *s, double *start, double *stop);
bool limn_parse_size(const char *s, int *w, int *h); /* WxH, each 1..65536 */
/* A time in seconds as messages, the viewer and file names ({time}) print it:
 * `places` decimals (1.250), but %g from 1e6 s on, where fixed decimals
 * would print a 300-digit number for 1e300. Returns out. */
#define LIMN_TIME_TEXT 32
const char *limn_time_text(double seconds, int places, char out[LIMN_TIME_TEXT]);
bool limn_parse_on_off(const char *s, bool *out);
/* A command of one subcommand (limn farm slurm, limn manifest merge): -1
 * when argv[1] is `sub`; else the exit status, 0 after printing `usage` for
 * --help or -h, 2 after printing `why` and `usage` to stderr. */
int limn_subcommand(int argc, char **argv, const char *sub, const char *usage, const char *why);
/* --shard I/N, auto or auto/N. `auto` takes the index from the scheduler:
 * Slurm's SLURM_ARRAY_TASK_ID less SLURM_ARRAY_TASK_MIN, of
 * SLURM_ARRAY_TASK_COUNT (or MAX - MIN + 1) shards; `auto/N` takes
 * SLURM_ARRAY_TASK_ID as it is, or a Kubernetes Indexed Job's
 * JOB_COMPLETION_INDEX, of N shards. msg gets where the shard came from
 * ("" for I/N), or on false what is wrong. */
bool limn_parse_shard(const char *s, int *shard, int *shards, char *msg, size_t cap);
/* --camera: an index, or "auto" (LIMN_CAMERA_AUTO): a camera framing the
 * scene's bounds at the output's aspect, added by limn_camera_resolve. */
#define LIMN_CAMERA_AUTO (-1)
bool limn_parse_camera(const char *s, int *out);
struct lm_scene;
int limn_camera_resolve(struct lm_scene *s, int camera, int width, int height);
/* Each command keeps its own getopt table and loop (its flags as its
 * --help and docs/commands.md list them) and frees what it made at its end,
 * so commands read alike; what they share is parsed here and in
 * limn_pov_flag.
 * The flags capture, view, bench and graph share: --scene, --script, --tech,
 * --set NAME=VALUE (at most LIMN_MAX_SETS), --size WxH, --camera N (or
 * "auto" where camera_auto). Each command lists those it takes in its own
 * option table with these getopt values: 's', 'p', 't', 'D', 'z', 'c', and
 * hands limn_common_flag every getopt_long result its own cases do not take
 * (optarg and optind as getopt_long left them): 0 when it took c, else 2
 * after printing the usage error for `limn CMD` (a bad value, a flag
 * without its value, an unknown flag). */
enum { LIMN_MAX_SETS = 64 };
typedef struct limn_common_args {
  const char *scene, *script, *tech;
  const char *sets[LIMN_MAX_SETS]; /* NAME=VALUE, as given */
  int set_count, width, height, camera;
  bool camera_auto; /* the command resolves --camera auto */
} limn_common_args;
int limn_common_flag(const char *cmd, int c, char **argv, limn_common_args *a);
/* Prints s as a JSON string (quotes, backslashes and control characters escaped). */
void limn_json_string(const char *s);          /* a quoted, escaped JSON string to stdout */
void limn_json_append(lm_buf *b, const char *s); /* the same, appended to b */

/* export-pov's flags (cli/export_pov.c), shared by reference and report:
 * limn_pov_options ends with a zero entry (12 entries in all);
 * limn_pov_flag returns 0 when it took getopt's c, 1 when c is not one of
 * them, 2 after printing a usage error for `limn CMD`. */
struct lm_pov_desc;
extern const struct option limn_pov_options[];
#define LIMN_POV_OPTION_COUNT 12
enum { LIMN_POV_SKY_FLAG = 0x100 }; /* --sky's getopt value, beyond any one-letter flag */
void limn_pov_defaults(struct lm_pov_desc *d);
int limn_pov_flag(const char *cmd, int c, const char *arg, struct lm_pov_desc *d);
/* --sky's ZENITH:HORIZON[:INTENSITY] (colours r,g,b or one grey number, each in
 * 0 .. 1e6), as scripts/sky.lua's options; also a job's references.sky. */
struct lm_sky;
bool limn_parse_sky(const char *s, struct lm_sky *sky);
/* Writes the file under a temporary name and renames it: whole or not at all. */
typedef struct lm_error lm_error;
bool limn_write_whole(const char *path, const char *data, size_t len, lm_error *err);

#endif
