/* The `limn` command's subcommands. Each returns the process exit code:
 * 0 done, 1 failed, 2 bad usage. */
#ifndef LIMN_TOOLS_H
#define LIMN_TOOLS_H

#include <stdbool.h>

int limn_capture(int argc, char **argv);
int limn_view(int argc, char **argv);
int limn_export_pov(int argc, char **argv);
int limn_compare(int argc, char **argv);
int limn_bench(int argc, char **argv);

/* Flag values (tools/args.c): false when `s` is not one. */
bool limn_parse_int(const char *s, int lo, int hi, int *out);
bool limn_parse_double(const char *s, double *out); /* finite */
bool limn_parse_size(const char *s, int *w, int *h); /* WxH, each 1..65536 */
bool limn_parse_on_off(const char *s, bool *out);
/* Prints s as a JSON string (quotes, backslashes and control characters escaped). */
void limn_json_string(const char *s);

#endif
