/* policy_progress.c — the progress bar on stderr (a murk_progress_fn, session.h): share done, seconds
 * since the passes began and the time left at the rate so far, redrawn in place; a newline after the
 * last. */
#include "render/session.h"

#include <stdio.h>

void murk_progress_bar(void *user, double fraction, double seconds, int last)
{
    (void)user;
    int width = 40, fill = (int)(fraction * width + 0.5);
    char bar[64];
    for (int i = 0; i < width; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[width] = 0;
    double eta = fraction > 0.001 ? seconds * (1.0 - fraction) / fraction : 0.0;
    fprintf(stderr, "\r[%s] %5.1f%%  %6.1fs  ETA %6.1fs ", bar, 100.0 * fraction, seconds, eta);
    if (last)
        fputc('\n', stderr);
    fflush(stderr);
}
