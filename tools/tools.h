/* The `limn` command's subcommands. Each returns the process exit code:
 * 0 done, 1 failed, 2 bad usage. */
#ifndef LIMN_TOOLS_H
#define LIMN_TOOLS_H

int limn_capture(int argc, char **argv);
int limn_view(int argc, char **argv);

#endif
