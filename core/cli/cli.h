/* cli.h — the murk command line, part of the murk executable only (not of libmurk). */
#ifndef MURK_CLI_H
#define MURK_CLI_H

#include <stddef.h>

/* Runs `murk render | plugins | compare | grid | --version | --help`; returns the exit status. */
int murk_cli_main(int argc, char **argv);
/* `murk info SCENE.yaml [--set ...]` (info.c). */
int murk_cli_info(int argc, char **argv);
/* A scene as the murk command loads it (info.c): murk_scene_load plus the command's rule that every
 * medium and material is used (murk_scene_check_unused). NULL after printing the one-line error. */
struct murk_scene *murk_cli_load(const char *path, const char *const *sets, size_t nsets);

#endif
