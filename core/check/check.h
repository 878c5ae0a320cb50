/* check.h — `murk check PLUGIN`: the statistical tests murk runs on its own plugins, for any plugin.
 * Part of libmurk (the murk command calls murk_check_main; tests may call the parts). */
#ifndef MURK_CHECK_H
#define MURK_CHECK_H

#include "util/util.h"

/* `murk check [--seed S] [--quick] PLUGIN...` (argv[0] is "check"). PLUGIN is a name found on the
 * plugin search path or a path to NAME.so (its folder is then searched first). Prints one line per
 * figure and a verdict per plugin; returns 0 when every check passed, 1 when one failed, 2 on usage. */
MURK_API int murk_check_main(int argc, char **argv);

#endif
