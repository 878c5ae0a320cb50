/* commit.c — the git commit and version murk was built from, for the files it writes (the PNG text keys
 * murk:commit and murk:version, the EXR attributes of the same names) and for `murk --version`. */
#include "util/util.h"

#include "util/murk_commit.h"

MURK_API const char *murk_build_commit(void) { return MURK_COMMIT; }

MURK_API const char *murk_build_version(void) { return MURK_VERSION; }
