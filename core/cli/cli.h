/* cli.h — the murk command line, part of the murk executable only (not of libmurk). */
#ifndef MURK_CLI_H
#define MURK_CLI_H

#include <stddef.h>

#include "cmd/cmd.h"

/* Runs `murk render | info | plugins | compare | bench | merge | check | grid | help | --version | --help`;
 * returns the exit status. */
int murk_cli_main(int argc, char **argv);
/* `murk info SCENE.yaml [--set ...]` (info.c). */
int murk_cli_info(int argc, char **argv);
/* A scene as the murk command loads it (info.c): murk_scene_load plus the command's rule that every
 * medium and material is used (murk_scene_check_unused). NULL after printing the one-line error. */
struct murk_scene *murk_cli_load(const char *path, const char *const *sets, size_t nsets);

int murk_cli_plugins(int argc, char **argv); /* plugins.c */

#include <stdio.h>
/* What the scene holds in memory (info.c): every grid, mesh, texture and Embree's scene with its bytes when
 * detail, else one line of totals per kind; then the process's peak resident memory. */
void murk_cli_memory_print(FILE *f, const struct murk_scene *s, int detail);

/* `murk merge OUT.exr PART...` (merge.c): the parts of a --part I/N render into the whole image. */
int murk_cli_merge(int argc, char **argv);

#endif
