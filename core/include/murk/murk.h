/* murk/murk.h — libmurk's embedding API: load a scene, render it, write the images.
 * Plugin authors do not need this header (see murk/plugin.h). */
#ifndef MURK_MURK_H
#define MURK_MURK_H

#include <stddef.h>
#include <stdint.h>

typedef struct murk_scene murk_scene;

typedef struct murk_render_opts {
    int spp;            /* samples per pixel; 0 = the scene's */
    int threads;        /* 0 = all cores */
    double time_limit;  /* seconds; > 0 stops after the last whole pass that fits (spp is then a cap) */
    int progress;       /* draw a progress bar on stderr */
} murk_render_opts;

typedef struct murk_render_result {
    int width, height, spp; /* spp actually rendered */
    float *rgb;             /* 3*width*height linear floats, row 0 at the top; free() it */
    double seconds;
    uint64_t samples, rays, nonfinite;
} murk_render_result;

/* `sets` are "KEY.PATH=VALUE" overrides. NULL with a one-line "file:line:col: message" in err. */
murk_scene *murk_scene_load(const char *path, const char *const *sets, size_t nsets, char *err, size_t errlen);
void murk_scene_free(murk_scene *scene);
int murk_render(const murk_scene *scene, const murk_render_opts *opts, murk_render_result *out);
/* The `murk` command line (render / plugins / compare / grid); returns the exit status. */
int murk_cli_main(int argc, char **argv);

#endif
